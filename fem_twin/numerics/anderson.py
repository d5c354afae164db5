"""Anderson mixing for fixed-point problems (the macro coupling's accelerator).

Type II Anderson acceleration (Walker and Ni 2011) of ``x = x + f(x)``: each step mixes the
last ``depth`` differences of iterates and residuals by least squares.  On a linear map it
is equivalent to GMRES, so with ``depth`` at least the dimension it reaches the fixed point
in at most dimension + 1 steps (tested).
"""

from __future__ import annotations

import numpy as np


class Anderson:
    """Anderson mixing with memory ``depth`` and damping ``beta`` (the share of the mixed
    residual added, ``x_next = x_mix + beta f_mix``; 1: undamped): ``x_next = step(x, f(x))``.

    The differences live in two ``(depth, n)`` ring buffers written in place, so a step
    allocates one ``(n, depth)`` copy (the least-squares solver's) besides its result: at
    2048^2 with depth 8 stacking the history anew held 0.8 GB more during each step."""

    def __init__(self, depth: int, beta: float = 1.0):
        self.depth, self.beta = depth, beta
        self.dx = self.df = None                  # (depth, n) ring buffers
        self.count = 0                            # differences stored so far
        self.x_old = self.f_old = None

    def step(self, x, f):
        """The next iterate from the current one ``x`` and its residual ``f = g(x) - x``."""
        if self.depth == 0:
            return x + self.beta * f              # the plain (relaxed) iteration
        if self.x_old is not None:
            if self.dx is None:
                self.dx, self.df = np.empty((2, self.depth, x.size))
            slot = self.count % self.depth
            np.subtract(x, self.x_old, out=self.dx[slot])
            np.subtract(f, self.f_old, out=self.df[slot])
            self.count += 1
            self.x_old[...], self.f_old[...] = x, f
        else:
            self.x_old, self.f_old = x.copy(), f.copy()
        k = min(self.count, self.depth)
        if k == 0:
            return x + self.beta * f
        gamma = np.linalg.lstsq(self.df[:k].T, f, rcond=1e-10)[0]
        return x + self.beta * f - gamma @ self.dx[:k] - self.beta * (gamma @ self.df[:k])

    def pairs(self, k: int):
        """The last ``min(k, stored)`` differences ``(dx, df)``, oldest first, as copies
        ``(m, n)``."""
        m = min(k, self.count, self.depth)
        if m == 0:
            return np.empty((0, 0)), np.empty((0, 0))
        slots = [(self.count - m + j) % self.depth for j in range(m)]
        return self.dx[slots].copy(), self.df[slots].copy()

    def seed(self, dx, df):
        """Start the history from the differences ``(dx, df)`` (``(m, n)``, oldest first,
        ``m <= depth``) of a related problem: the first step already mixes them out of the
        residual (a coarser grid's pairs carry its slow, smooth modes)."""
        m = min(len(dx), self.depth)
        if m == 0 or self.depth == 0:
            return
        self.dx, self.df = np.empty((2, self.depth, dx.shape[1]))
        self.dx[:m], self.df[:m] = dx[-m:], df[-m:]
        self.count = m
