"""Finite-volume cell problems (paper eqs 8-10, its own discretisation).

Cell-centred finite volumes on the periodic pixel grid: one control volume per pixel and
second-order central fluxes, ``c_f ((chi_2[i+1] - chi_2[i]) / dx1 + 1)`` through an x1
face, with the face conductance ``c_f`` for ``h^3`` and the arithmetic mean ``h_f`` for the
Couette flux of eq 8, whose time term sits at the cell centre.  The averages (eqs 13-16)
are face averages of the fluxes, ``A[i, j] = <c_f (delta_ij + D_i chi_{j+2})>``, which keeps
``A`` exactly symmetric.  One pixel is pinned (chi = 0).

Face conductance (``face=``): ``"bilinear"`` (default) integrates ``h^3`` exactly along the
face for the bilinear gap through the pixel centres (the FE path's gap; the mean cube of a
linear function from ``a`` to ``b`` is ``(a + b)(a^2 + b^2) / 4``); ``"arithmetic"`` is the
two-point mean ``(h_P^3 + h_E^3) / 2``, which leaks flow where contact spots meet open
pixels (docs/accuracy.md, "Design choices, measured")."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..checks import arguments
from ..errors import InputError
from ..numerics.assembly import FixedPattern, periodic_unknowns
from ..numerics.linalg import SPDSolver
from .cell import CellSolution
from .film import shear_spread
from .pockets import fluid_regions
from .pockets import sealed as seal


def _cube_mean(a, b):
    """Mean of ``f^3`` for ``f`` linear from ``a`` to ``b``."""
    return (a + b) * (a * a + b * b) / 4


def _bilinear_face(h, axis):
    """Face mean of ``h^3`` over the faces between each pixel and its ``+axis`` neighbour."""
    other = 1 - axis
    m0 = (h + np.roll(h, -1, axis=axis)) / 2                 # face centre
    return sum(_cube_mean(m0, (m0 + np.roll(m0, s, axis=other)) / 2) for s in (-1, 1)) / 2


#: face conductance of h^3, per axis (1: x1 faces, 0: x2 faces), for the gap ``h`` [m]
FACE_RULES = {"bilinear": _bilinear_face,
              "arithmetic": lambda h, axis: (h ** 3 + np.roll(h ** 3, -1, axis=axis)) / 2}


class CellSolverFV:
    """Periodic 5-point FVM cell problems on a ``(ny, nx)`` grid of pitch ``spacing`` [m].

    ``backend``: the sparse direct solver (see :mod:`fem_twin.numerics.linalg`).
    """

    @arguments(shape="shape", spacing="pair")
    def __init__(self, shape, spacing, *, pinned: int = 0, face: str = "bilinear",
                 backend: str | None = None):
        if face not in FACE_RULES:
            raise InputError(f"face must be one of {sorted(FACE_RULES)}, got {face!r}")
        self.face = face
        self.shape = (int(shape[0]), int(shape[1]))
        self.spacing = tuple(float(s) for s in np.broadcast_to(np.asarray(spacing, float), (2,)))
        ny, nx = self.shape
        n = ny * nx
        if min(self.shape) < 3:
            raise InputError(f"the FVM cell needs at least 3 x 3 pixels, got {self.shape}")
        if not 0 <= pinned < n:
            raise InputError(f"pinned pixel {pinned} outside the {self.shape} grid")
        self.pinned = int(pinned)
        idx = np.arange(n).reshape(ny, nx)
        east, north = np.roll(idx, -1, axis=1).ravel(), np.roll(idx, -1, axis=0).ravel()
        me = idx.ravel()
        # face list: x1 faces (me, east) then x2 faces (me, north); each adds w (e_i - e_j)^2
        self._fi = np.r_[me, me]
        self._fj = np.r_[east, north]
        self._free, renum = periodic_unknowns(self.shape, self.pinned)
        rows = np.r_[self._fi, self._fj, self._fi, self._fj]
        cols = np.r_[self._fi, self._fj, self._fj, self._fi]
        self._keep = (rows != self.pinned) & (cols != self.pinned)
        self._pattern = FixedPattern.from_entries(renum[rows[self._keep]],
                                                  renum[cols[self._keep]], n - 1)
        self._factor = SPDSolver(self._pattern.indptr, self._pattern.indices, backend)

    @property
    def unknowns(self) -> np.ndarray:
        """Pixel index of each unknown of the reduced system."""
        return self._free

    def face_values(self, field):
        """Arithmetic means on the x1 faces (east) and the x2 faces (north), ``(2, ny, nx)``."""
        f = np.asarray(field, float)
        return np.stack([(f + np.roll(f, -1, axis=1)) / 2, (f + np.roll(f, -1, axis=0)) / 2])

    def face_conductance(self, gap):
        """Conductance ``c_f`` of the x1 faces and the x2 faces [m^3], ``(2, ny, nx)``."""
        h = np.asarray(gap, float)
        rule = FACE_RULES[self.face]
        return np.stack([rule(h, 1), rule(h, 0)])

    def operator(self, c_faces) -> sp.csr_matrix:
        """Reduced operator for the face conductances ``c_f`` (x1 faces, x2 faces)."""
        dx1, dx2 = self.spacing
        w = np.r_[c_faces[0].ravel() * (dx2 / dx1), c_faces[1].ravel() * (dx1 / dx2)]
        return self._pattern.csr(np.r_[w, w, -w, -w][self._keep])

    def _divergence(self, flux):
        """Net outflow of face fluxes ``(2, ny, nx)`` [per unit length] times face length."""
        dx1, dx2 = self.spacing
        out = (flux[0] - np.roll(flux[0], 1, axis=1)) * dx2
        out += (flux[1] - np.roll(flux[1], 1, axis=0)) * dx1
        return out

    def solve(self, gap, squeeze=None, couette: bool = True, film=(0.0,),
              sealed: bool = False, shear_weight: float | None = None) -> CellSolution:
        """Cell solutions for the gap ``h`` [m] and the squeeze term ``tau`` [-] (or steady);
        ``couette=False``: eq 8 without its Couette term (the mean-speed frame); ``film``
        ``sealed`` and ``shear_weight``: as in :meth:`CellSolver.solve` (the regions joined
        through faces; the local shear per pixel, its dissipation on its two upper faces)."""
        h = np.asarray(gap, float)
        if h.shape != self.shape:
            raise InputError(f"gap shape {h.shape} does not match the cell {self.shape}")
        if not np.all(np.isfinite(h)) or h.min() <= 0:
            raise InputError("the gap must be finite and positive (truncate it first) [m]")
        dx1, dx2 = self.spacing
        hf = self.face_values(h)
        cf = self.face_conductance(h)
        zero = np.zeros_like(h)
        f1 = -self._divergence(np.stack([hf[0], zero])) if couette else zero.copy()
        if squeeze is not None:                   # mean removed: see the FE CellSolver
            tau = np.asarray(squeeze, float)
            f1 = f1 - (tau - tau.mean()) * dx1 * dx2
        f1 = ([seal(f1, fluid_regions(h, w, connectivity=4)) for w in film] if sealed
              else [f1])
        f2 = self._divergence(np.stack([cf[0], zero]))
        f3 = self._divergence(np.stack([zero, cf[1]]))
        F = np.column_stack([f.ravel()[self._free] for f in (*f1, f2, f3)])
        K = self.operator(cf)
        scale = cf.mean()
        X = self._factor.factor(K.data / scale).solve(F / scale)
        fields = np.zeros((X.shape[1], h.size))
        fields[:, self._free] = X.T
        fields = fields.reshape(-1, *self.shape)
        chi = fields[[0, -2, -1]]
        return CellSolution(chi, self.moments(h, hf, cf, chi, film, fields[:-2], shear_weight))

    def moments(self, h, hf, cf, chi, film=(0.0,), chi_1=None,
                shear_weight: float | None = None) -> dict:
        """Cell averages of one step as face averages of the fluxes (same keys as FE; the
        dissipation over the faces whose mean gap exceeds each value of ``film``, of the
        matching one of ``chi_1`` if given)."""
        dx = self.spacing

        def grad(f):                              # D_i f on the faces normal to x_i
            return np.stack([(np.roll(f, -1, axis=1) - f) / dx[0],
                             (np.roll(f, -1, axis=0) - f) / dx[1]])

        g1 = grad(chi[0])
        if chi_1 is None or len(chi_1) == 1:                   # one chi_1 for every film
            faces = [cf * g1 * g1] * len(film)                  # dissipation on the faces
        else:
            faces = [cf * g * g for g in (grad(c) for c in chi_1)]
        G = np.stack([grad(chi[1]), grad(chi[2])], axis=1)      # (i, j, ny, nx): D_i chi_{j+2}
        eye = np.eye(2)[:, :, None, None]
        out = {} if shear_weight is None else shear_spread(
            h.ravel(), [d.sum(axis=0).ravel() for d in faces], film, shear_weight)
        return {**out, "h": float(h.mean()),
                "h3_grad": (cf[:, None] * (eye + G)).mean(axis=(2, 3)),
                "h3_g1": (cf * g1).mean(axis=(1, 2)),
                "h_grad": (hf[:, None] * (eye + G)).mean(axis=(2, 3)),
                "h_g1": (hf * g1).mean(axis=(1, 2)),
                "h3_g1g1": np.array([np.where(hf > cut, d, 0.0).mean(axis=(1, 2)).sum()
                                     for cut, d in zip(film, faces)])}
