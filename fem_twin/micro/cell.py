"""FE cell problems of the roughness scale (paper eqs 8-10) on a periodic pixel mesh.

Bilinear quadrilaterals, one per pixel square, nodes = pixels, 2 x 2 Gauss quadrature.  With
``a = h^3`` at the quadrature points the weak forms are, for all periodic test functions v,

    (a grad chi_1, grad v) = (h, dv/dx1) - (tau, v)        eq 8, tau = (1/u_m) dh/dt
    (a grad chi_2, grad v) = -(a, dv/dx1)                  eq 9
    (a grad chi_3, grad v) = -(a, dv/dx2)                  eq 10

(the derivatives of h and h^3 moved onto v by parts, which is exact on a periodic cell).
All pixel squares are the same rectangle, so the element matrix of the flow form is a sum
over quadrature points ``q`` of ``a_q k_q`` with four 4 x 4 tensors ``k_q`` computed once by
scikit-fem on one element.  Re-assembling the operator for a new gap is then one small dense
product and one ``bincount`` onto a sparsity pattern fixed in advance (about 10 x faster
than ``BilinearForm.assemble``).  One node is pinned (chi = 0) to remove the constant.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import skfem
from skfem.helpers import dot, grad

from ..checks import arguments
from ..errors import InputError
from ..io.mesh import GridMesh, grid_mesh
from ..numerics.assembly import FixedPattern, element_entries, periodic_unknowns, unit_element
from ..numerics.linalg import SPDSolver
from .film import shear_spread
from .pockets import fluid_regions
from .pockets import sealed as seal


@skfem.BilinearForm
def flow_form(u, v, w):
    """Poiseuille operator of eqs 8-10: ``a grad u . grad v`` with ``a = h^3`` [m^3]."""
    return w.a * dot(grad(u), grad(v))


@skfem.LinearForm
def pressure_form_1(v, w):
    """Right-hand side of eq 9: ``-h^3 dv/dx1``."""
    return -w.a * v.grad[0]


@skfem.LinearForm
def pressure_form_2(v, w):
    """Right-hand side of eq 10: ``-h^3 dv/dx2``."""
    return -w.a * v.grad[1]


@skfem.LinearForm
def squeeze_form(v, w):
    """Time term of eq 8 moved to the right: ``-tau v``, ``tau = (1/u_m) dh/dt`` [-]."""
    return -w.tau * v


@dataclass(frozen=True, eq=False)
class CellSolution:
    """The three cell solutions at one time step, as grid fields ``(ny, nx)``.

    Attributes
    ----------
    chi
        (3, ny, nx); chi_1 [1/m], chi_2 and chi_3 [m]; zero at the pinned pixel
    moments
        dict of the cell averages that eqs 11-16 need at this step (see
        :meth:`CellSolver.moments`)
    """

    chi: np.ndarray
    moments: dict


class CellSolver:
    """Periodic Q1 cell problems on a ``(ny, nx)`` grid of pitch ``spacing`` [m].

    Everything that does not depend on the gap is built once: the mesh, the per-quadrature-
    point element tensors, the sparsity pattern with the pinned node removed, the scatter
    maps of the right-hand sides, and the symbolic factorisation (``backend``: see
    :mod:`fem_twin.numerics.linalg`).
    """

    @arguments(shape="shape", spacing="pair")
    def __init__(self, shape, spacing, *, pinned: int = 0, backend: str | None = None):
        self.shape = (int(shape[0]), int(shape[1]))
        self.spacing = tuple(float(s) for s in np.broadcast_to(np.asarray(spacing, float), (2,)))
        self.grid: GridMesh = grid_mesh(self.shape, self.spacing, periodic=True)
        n = self.shape[0] * self.shape[1]
        if not 0 <= pinned < n:
            raise InputError(f"pinned pixel {pinned} outside the {self.shape} grid")
        self.pinned = int(pinned)
        self.basis = skfem.Basis(self.grid.mesh, skfem.ElementQuad1(), intorder=2)
        ref = self._reference_element()
        self._k = ref["k"]                       # (nq, 16) flow tensors per quadrature point
        self._g = ref["g"]                       # (2, nq, 4) w_q dphi_i/dx_d
        self._m = ref["m"]                       # (nq, 4) w_q phi_i
        self._phi = ref["phi"]                   # (4, nq) phi_i at the quadrature points
        self._dphi = ref["dphi"]                 # (2, 4, nq) dphi_i/dx_d
        pix = self.grid.node_pixel[self.grid.mesh.t]          # (4, nelems) pixel of each dof
        self._pix = pix
        rows, cols = element_entries(pix)
        keep = (rows != self.pinned) & (cols != self.pinned)
        self._free, renum = periodic_unknowns(self.shape, self.pinned)   # pixel of each unknown
        self._keep = keep
        self._pattern = FixedPattern.from_entries(renum[rows[keep]], renum[cols[keep]], n - 1)
        self._factor = SPDSolver(self._pattern.indptr, self._pattern.indices, backend)

    # -- reference element --------------------------------------------------------------
    def _reference_element(self) -> dict:
        """Element tensors of the forms per quadrature point, computed by scikit-fem."""
        b = unit_element(self.spacing)
        nq = b.X.shape[1]
        k, g, m = [], [], []
        for q in range(nq):
            unit = np.zeros((1, nq))
            unit[0, q] = 1.0
            k.append(flow_form.assemble(b, a=unit).toarray().ravel())
            g.append([-pressure_form_1.assemble(b, a=unit), -pressure_form_2.assemble(b, a=unit)])
            m.append(-squeeze_form.assemble(b, tau=unit))
        phi = np.array([np.asarray(b.basis[i][0])[0] for i in range(4)])
        dphi = np.array([[b.basis[i][0].grad[d][0] for i in range(4)] for d in range(2)])
        return {"k": np.array(k), "g": np.transpose(np.array(g), (1, 0, 2)), "m": np.array(m),
                "phi": phi, "dphi": dphi}

    # -- fields at quadrature points -----------------------------------------------------
    def at_quadrature(self, field: np.ndarray) -> np.ndarray:
        """Grid field ``(ny, nx)`` -> values at the quadrature points ``(nelems, nq)``."""
        return np.asarray(field, float).ravel()[self._pix].T @ self._phi

    def gradient(self, field: np.ndarray) -> np.ndarray:
        """Gradient of a grid field at the quadrature points, ``(2, nelems, nq)``."""
        f = np.asarray(field, float).ravel()[self._pix].T
        return np.stack([f @ self._dphi[0], f @ self._dphi[1]])

    # -- assembly ------------------------------------------------------------------------
    def operator(self, a_q: np.ndarray) -> sp.csr_matrix:
        """Reduced flow operator for ``a = h^3`` at the quadrature points.

        Pinned node removed, unknowns in the order of ``self.unknowns`` (pixel indices).
        """
        return self._pattern.csr((a_q @ self._k).ravel()[self._keep])

    @property
    def unknowns(self) -> np.ndarray:
        """Pixel index of each unknown of the reduced system."""
        return self._free

    def _scatter(self, local: np.ndarray, regions=None) -> np.ndarray:
        """Element vectors ``(nelems, 4)`` -> reduced global vector (``regions``: each
        sealed region's net load removed, :func:`.pockets.sealed`)."""
        n = self.shape[0] * self.shape[1]
        full = np.bincount(self._pix.T.ravel(), weights=local.ravel(), minlength=n)
        if regions is not None:
            full = seal(full.reshape(self.shape), regions).ravel()
        return full[self._free]

    def right_hand_sides(self, h_q: np.ndarray, a_q: np.ndarray, tau_q=None,
                         couette: bool = True, regions=(None,)) -> np.ndarray:
        """Load vectors of eqs 8, 9, 10 as columns ``(n - 1, 2 + len(regions))``: eq 8's
        sealed in each of ``regions`` (None: not sealed; :mod:`.pockets`), then eqs 9 and
        10 (``couette=False``: eq 8 without its Couette term, the mean-speed frame)."""
        f1 = h_q @ self._g[0] if couette else np.zeros_like(h_q @ self._m)
        if tau_q is not None:
            f1 = f1 - tau_q @ self._m
        f2 = -(a_q @ self._g[0])
        f3 = -(a_q @ self._g[1])
        return np.column_stack([self._scatter(f1, r) for r in regions]
                               + [self._scatter(f2), self._scatter(f3)])

    # -- solve ---------------------------------------------------------------------------
    def solve(self, gap: np.ndarray, squeeze: np.ndarray | None = None,
              couette: bool = True, film=(0.0,), sealed: bool = False,
              shear_weight: float | None = None) -> CellSolution:
        """Cell solutions for the gap ``h`` [m] and the squeeze term ``tau`` [-] (or steady).

        ``squeeze`` is ``(1/u_m) dh/dt`` on the grid, already discretised in time; its cell
        mean (non-zero only where the truncation at the gap floor changes the mean gap) is
        removed, as the periodic problem requires.  ``couette=False``: eq 8 without its
        Couette term (the mean-speed frame, :mod:`fem_twin.micro.sliding`).  ``film``: the
        thinnest film [m] whose dissipation of chi_1 counts, one moment per value.
        ``sealed``: each value of ``film`` also walls in the regions of its own chi_1
        (:mod:`.pockets`; the first is the solution's), one more right-hand side each;
        False: the paper's source, which leaks through the contact spots.
        ``shear_weight``: adds the moments of the local shear's spread (see :meth:`moments`).
        """
        h = np.asarray(gap, float)
        if h.shape != self.shape:
            raise InputError(f"gap shape {h.shape} does not match the cell {self.shape}")
        if not np.all(np.isfinite(h)) or h.min() <= 0:
            raise InputError("the gap must be finite and positive (truncate it first) [m]")
        h_q = self.at_quadrature(h)
        a_q = h_q ** 3
        tau_q = None
        if squeeze is not None:
            # the mean squeeze of the cell is macro-scale (d h_m / dt); the periodic problem
            # is solvable only without it, and keeping it would make chi depend on the pin
            tau_q = self.at_quadrature(squeeze)
            tau_q = tau_q - tau_q.mean()
        K = self.operator(a_q)
        regions = [fluid_regions(h, w, connectivity=8) for w in film] if sealed else [None]
        F = self.right_hand_sides(h_q, a_q, tau_q, couette, regions)
        scale = a_q.mean()
        X = self._factor.factor(K.data / scale).solve(F / scale)
        n = self.shape[0] * self.shape[1]
        fields = np.zeros((X.shape[1], n))
        fields[:, self._free] = X.T
        fields = fields.reshape(-1, *self.shape)
        chi = fields[[0, -2, -1]]
        return CellSolution(chi, self.moments(h_q, chi, film, fields[:-2], shear_weight))

    def moments(self, h_q: np.ndarray, chi: np.ndarray, film=(0.0,), chi_1=None,
                shear_weight: float | None = None) -> dict:
        """Cell averages of one time step, unnormalised (eqs 12-16 divide by h_m later).

        h : <h> [m];  h3_grad : <h^3 (I + G)> [m^3], G[i, j] = d chi_{j+2} / dx_i;
        h3_g1 : <h^3 grad chi_1> [m];  h_grad : <h (I + G)> [m];  h_g1 : <h grad chi_1> [1/m];
        h3_g1g1 : ``<h^3 |grad chi_1|^2>`` where ``h`` exceeds each value of ``film`` [1/m]
        (the dissipation of the sliding flow in the film, :func:`.sliding.film_moments`),
        of the matching one of ``chi_1`` (sealed at each value) if given;
        with ``shear_weight`` ``w``, per value of ``film``: film_area, the fraction of the
        cell above it [-], and log_shear, ``<ln s>`` over it (zero elsewhere) of the local
        dissipation ``s = 1/h + w h^3 |grad chi_1|^2`` [1/m] at the quadrature points
        """
        a_q = h_q ** 3
        n = a_q.size
        weights = np.stack([a_q.ravel(), h_q.ravel()])          # (2, n): h^3 and h
        g1 = self.gradient(chi[0]).reshape(2, n)
        g_mean = np.stack([weights @ self.gradient(chi[j]).reshape(2, n).T / n
                           for j in (1, 2)], axis=2)            # <w G[i, j]>: (w, i, j)
        w_mean = weights.mean(axis=1)
        eye = np.eye(2)
        if chi_1 is None or len(chi_1) == 1:                   # one chi_1 for every film
            density = [weights[0] * (g1 * g1).sum(axis=0)] * len(film)
        else:
            density = [weights[0] * (g * g).sum(axis=0)
                       for g in (self.gradient(c).reshape(2, n) for c in chi_1)]
        out = ({} if shear_weight is None
               else shear_spread(weights[1], density, film, shear_weight))
        return {**out, "h": float(w_mean[1]),
                "h3_grad": w_mean[0] * eye + g_mean[0],
                "h3_g1": g1 @ weights[0] / n,
                "h_grad": w_mean[1] * eye + g_mean[1],
                "h_g1": g1 @ weights[1] / n,
                "h3_g1g1": np.array([np.mean(np.where(weights[1] > cut, d, 0.0))
                                     for cut, d in zip(film, density)])}

