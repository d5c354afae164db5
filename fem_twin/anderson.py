"""Anderson mixing for fixed-point problems (the macro coupling's accelerator).

Type II Anderson acceleration (Walker and Ni 2011) of ``x = x + f(x)``: each step mixes the
last ``depth`` differences of iterates and residuals by least squares.  On a linear map it
is equivalent to GMRES, so with ``depth`` at least the dimension it reaches the fixed point
in at most dimension + 1 steps (tested).
"""

from __future__ import annotations

import numpy as np


class Anderson:
    """Anderson mixing with memory ``depth``: ``x_next = step(x, f(x))``."""

    def __init__(self, depth: int):
        self.depth = depth
        self.dx, self.df = [], []
        self.x_old = self.f_old = None

    def step(self, x, f):
        """The next iterate from the current one ``x`` and its residual ``f = g(x) - x``."""
        if self.x_old is not None:
            self.dx.append(x - self.x_old)
            self.df.append(f - self.f_old)
            if len(self.dx) > self.depth:
                self.dx.pop(0)
                self.df.pop(0)
        self.x_old, self.f_old = x.copy(), f.copy()
        if not self.dx:
            return x + f
        DF = np.array(self.df).T
        DX = np.array(self.dx).T
        gamma = np.linalg.lstsq(DF, f, rcond=1e-10)[0]
        return x + f - (DX + DF) @ gamma
