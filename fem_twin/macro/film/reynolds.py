"""Reynolds equation with mass-conserving (JFO) cavitation on the macro grid (eqs 17-18).

    0 = div( G grad p - q (1 - theta) ),   p theta = 0,  p >= 0,  theta >= 0,

with ``p = p_hd - p_cav``, ``G = rho h^3 A / (12 mu)`` and ``q = rho h u_m b``.  Nodes are
pixels; ``p = p_amb - p_cav`` and ``theta = 0`` on the four edges (flooded inlet) and
wherever the gap opens beyond ``OPEN_GAP`` (the oil bath).  The Poiseuille term is the Q1
finite-element stiffness of ``G`` (scikit-fem form, 2 x 2 Gauss; ``method="fe"``) or the
paper's 5-point finite volumes (``"fvm"``).  The Couette term is in both a flux through
the faces of each node's dual cell with the liquid fraction from the upstream node
(:mod:`fem_twin.macro.film.couette`): a Galerkin Couette term is unstable here, as a cavitated
zone is pure transport of ``(1 - theta) h`` (infinite Peclet number), and the face fluxes
conserve mass exactly.  One unknown per node, ``phi``, carries ``p`` and ``theta`` as the
cavitation model says (:mod:`fem_twin.macro.film.cavitation`)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.sparse as sp
import skfem
from skfem.helpers import grad

from ...checks import arguments, as_field, as_pair
from ...errors import InputError, ReynoldsNotConverged
from ...numerics.assembly import at_points, grid_stencil, unit_element
from ...numerics.graded_mesh import Mesh
from ..laws.lubricant import Lubricant
from .cavitation import cavitation_model
from .couette import SCHEMES, couette_matrix
from .reynolds_fv import fvm_poiseuille

#: Nodes whose gap exceeds this [m] are at ambient pressure (Dirichlet): the oil bath around
#: a pin face, over the holder 1 mm below it.  Half a millimetre carries no hydrodynamic
#: pressure: its ``h^3`` is at least 1e6 times that of any film (< 5 um) that does, and
#: with the bath in the problem the Newton matrices span a contrast of 1e9, which costs the
#: direct solver its pivots (perturbed, then a SuperLU fallback: 45 % of a 1024^2 point)
#: and defeats multigrid.  Measured: C_f changed by 1.5e-7 C_f,b (sample pin, 512^2).
OPEN_GAP = 5e-4


@dataclass(frozen=True, eq=False)
class ReynoldsResult:
    """Solution of the Reynolds problem on the grid (SI units).

    pressure : absolute hydrodynamic pressure p_hd [Pa]
    cavity_fraction : theta [-]
    load : integral of ``p_hd - p_amb`` over the domain [N] (trapezoidal rule on the nodes)
    iterations, history : Newton steps and scaled residual per step
    """

    pressure: np.ndarray
    cavity_fraction: np.ndarray
    load: float
    iterations: int
    history: tuple


@skfem.BilinearForm
def homogenised_poiseuille_form(u, v, w):
    """Pressure flow of eq 17, ``g (A grad p) . grad v`` with the flow factor tensor ``A``."""
    du, dv = grad(u), grad(v)
    return w.g * (w.a11 * du[0] * dv[0] + w.a12 * du[1] * dv[0]
                  + w.a21 * du[0] * dv[1] + w.a22 * du[1] * dv[1])


def check_closed(gap: np.ndarray) -> None:
    """Refuse a gap [m] open (above :data:`OPEN_GAP`, the oil bath) at every interior node:
    nothing would carry load, most likely a gap not in metres."""
    if not np.any(gap[1:-1, 1:-1] <= OPEN_GAP):
        raise InputError(f"the gap is open everywhere inside the grid (above {OPEN_GAP:g} m, "
                         "the oil bath): nothing carries load; give the gap in metres")


def _inputs(gap, spacing, viscosity, method, couette):
    """:func:`solve_reynolds`'s checked inputs: ``(h, dx, lubricant or None, mu_0)``."""
    h = as_field("gap [m]", gap, 3)
    if h.min() <= 0:
        raise InputError("gap must be positive everywhere [m]")
    check_closed(h)
    lubricant = viscosity if isinstance(viscosity, Lubricant) else None
    mu0 = lubricant.viscosity if lubricant is not None else viscosity
    if not mu0 > 0:
        raise InputError(f"viscosity must be positive [Pa s], got {viscosity}")
    if method not in ("fe", "fvm"):
        raise InputError(f"method must be 'fe' or 'fvm', got {method!r}")
    if couette not in SCHEMES:
        raise InputError(f"couette must be one of {SCHEMES}, got {couette!r}")
    dx = as_pair("spacing [m]", spacing)
    if not all(np.isfinite(dx)) or min(dx) <= 0:
        raise InputError(f"spacing must be positive and finite [m], got {dx}")
    return h, dx, lubricant, mu0


@arguments(speed="number")
def solve_reynolds(gap, spacing, speed, viscosity, *, ambient_pressure: float = 0.0,
                   cavitation_pressure: float = 0.0, method: str = "fe", tol: float = 1e-10,
                   max_iter: int = 200, complementarity: str = "switch",
                   couette: str = "central", velocity=None) -> ReynoldsResult:
    """Smooth rigid-gap Reynolds with JFO cavitation, one surface sliding at ``speed``.

    Parameters
    ----------
    gap : (ny, nx) film thickness h [m], x1 (sliding) along the columns
    spacing : (dx1, dx2) [m]
    speed : sliding speed U [m/s] of one surface along +x1 (u_m = U / 2); may be negative
    viscosity : mu [Pa s], or a :class:`~fem_twin.macro.Lubricant` for a piezoviscous
        (eq 23 or Barus) and compressible (eq 24) film: its coefficients are then iterated
        with the pressure (Picard, warm-started) until the pressure changes by less than
        ``tol`` of its maximum
    ambient_pressure, cavitation_pressure : p_amb on the four edges and p_cav [Pa]
    method : ``"fe"`` (Q1 Poiseuille) or ``"fvm"`` (5-point Poiseuille)
    complementarity : ``"switch"`` (p-theta semismooth Newton) or ``"fb"`` (the paper's
        Fischer-Burmeister-Newton-Schur, :mod:`fem_twin.fvm.fbns`; slower, same solution)
    couette : ``"central"`` (second order) or ``"upwind"`` (the paper's first order), the
        Couette flux of :mod:`fem_twin.macro.film.couette`
    velocity : (ny, nx, 2) the sliding surface's velocity over ``speed`` [-] (a rotating
        disk's, :func:`~fem_twin.macro.laws.kinematics.disk_velocity`); None: +x1
    """
    h, dx, lubricant, mu0 = _inputs(gap, spacing, viscosity, method, couette)
    velocity = _velocity(velocity, h.shape)
    if ambient_pressure < cavitation_pressure:
        raise InputError("ambient pressure must not be below the cavitation pressure [Pa]")
    boundary = h > OPEN_GAP
    boundary[[0, -1], :] = boundary[:, [0, -1]] = True
    scale = 12 * mu0 * max(abs(speed), 1e-30) / 2 * float(np.mean(dx)) / np.mean(h) ** 2
    model = cavitation_model(complementarity)
    assemble = fe_poiseuille if method == "fe" else fvm_poiseuille
    mu, rho, phi, p_old, outer = mu0, 1.0, None, None, []
    for _ in range(max_iter if lubricant is not None else 1):
        g = rho * h ** 3 / (12 * mu)
        q1 = rho * h * speed / 2
        q2 = np.zeros_like(q1) if velocity is None else q1 * velocity[..., 1]
        q1 = q1 if velocity is None else q1 * velocity[..., 0]
        B = couette_matrix(q1, q2, dx, couette)
        phi, its, history = model.solve(assemble(g, dx), B, boundary,
                                        ambient_pressure - cavitation_pressure, scale,
                                        phi0=phi, tol=tol, max_iter=max_iter)
        p = model.split(phi, scale)[0].reshape(h.shape)
        if lubricant is None:
            break
        change = np.inf if p_old is None else float(np.abs(p - p_old).max())
        outer.append(change / max(float(p.max()), 1e-300))
        if outer[-1] < tol:
            break
        p_old = p
        mu, rho = lubricant.viscosity_at(p), lubricant.density_ratio(p)
    else:
        raise ReynoldsNotConverged("piezoviscous Reynolds: the coefficient iteration did not "
                                   f"settle in {max_iter} solves", outer)
    theta = model.split(phi, scale)[1].reshape(h.shape)
    p_hd = p + cavitation_pressure
    load = float(np.sum(trapezoid_weights(h.shape, dx) * (p_hd - ambient_pressure)))
    return ReynoldsResult(p_hd, theta, load, its, tuple(history))


def _velocity(velocity, shape):
    """A velocity field checked against the gap's ``shape`` (None stays None)."""
    if velocity is None:
        return None
    velocity = np.asarray(velocity, float)
    if velocity.shape != tuple(shape) + (2,) or not np.all(np.isfinite(velocity)):
        raise InputError(f"velocity must be finite, shaped like the gap plus (2,): "
                         f"{tuple(shape) + (2,)}, got {velocity.shape}")
    return velocity


def trapezoid_weights(shape, dx) -> np.ndarray:
    """Nodal weights [m^2] of the trapezoidal rule on the node grid (half at the edges), or
    on a graded ``Mesh`` ``dx``."""
    if isinstance(dx, Mesh):
        return dx.area
    w1 = np.full(shape[1], dx[0])
    w1[[0, -1]] /= 2
    w2 = np.full(shape[0], dx[1])
    w2[[0, -1]] /= 2
    return w2[:, None] * w1[None, :]


def fe_poiseuille(g, spacing, A=None) -> sp.csr_matrix:
    """Q1 stiffness of ``-div(g A grad p)`` on the node grid (nodes = pixels), non-periodic.

    ``g`` is ``(ny, nx)``; ``A`` is ``(ny, nx, 2, 2)`` (identity if None).  Nodal fields
    are interpolated to the 2 x 2 Gauss points.  ``spacing`` (dx1, dx2) [m], or a graded
    :class:`~fem_twin.numerics.graded_mesh.Mesh`.  The matrix is
    ``homogenised_poiseuille_form`` assembled by scikit-fem, re-assembled from element
    tensors computed once per grid (see :class:`PoiseuilleAssembly`).
    """
    g = np.asarray(g, dtype=float)
    if isinstance(spacing, Mesh):
        return graded_assembly(spacing).matrix(g, A)
    return _assembly(g.shape, tuple(float(v) for v in spacing)).matrix(g, A)


#: elements assembled at a time: bounds the transients (coefficients at the Gauss points,
#: element matrices: 260 B an element) to a block of the grid
BLOCK = 1 << 16


class PoiseuilleAssembly:
    """Fast re-assembly of ``homogenised_poiseuille_form`` on one grid.

    Every element is the same rectangle, so the element matrix is
    ``sum_q g_q A_kl,q T[q, k, l]`` with 16 x 16 reference tensors ``T`` that scikit-fem
    assembles once on a single element (unit coefficient at one quadrature point and one
    tensor entry).  A new matrix is then one matrix product per block of element rows,
    added into the grid's 3 x 3 stencil (:class:`fem_twin.numerics.assembly.GridStencil`): about
    10x faster than ``BilinearForm.assemble`` with five interpolated coefficient fields
    (``benchmarks/run.py macro``), with nothing kept per element.
    """

    def __init__(self, shape, spacing, sizes=None):
        self.shape = tuple(shape)
        b = unit_element((1.0, 1.0) if sizes is not None else spacing)
        # a graded mesh: the unit square's tensors scaled per element (h2/h1, 1, 1, h1/h2)
        self._scale = None if sizes is None else _element_scales(*sizes)
        nq = b.X.shape[1]
        T = np.zeros((nq, 2, 2, 16))
        names = (("a11", "a12"), ("a21", "a22"))
        for q in range(nq):
            unit = np.zeros((1, nq))
            unit[0, q] = 1.0
            for k in range(2):
                for m in range(2):
                    coef = {names[i][j]: unit * (i == k and j == m)
                            for i in range(2) for j in range(2)}
                    T[q, k, m] = homogenised_poiseuille_form.assemble(
                        b, g=np.ones((1, nq)), **coef).toarray().ravel()
        self._T = T
        self._phi = np.array([np.asarray(b.basis[i][0])[0] for i in range(4)])   # (4, nq)
        self._stencil = grid_stencil(self.shape)

    def at_quadrature(self, field, r0: int = 0, r1: int | None = None) -> np.ndarray:
        """Nodal field ``(..., ny, nx)`` -> values at the Gauss points of the elements whose
        first node is in rows ``r0 .. r1 - 1``: ``(nq, ..., r1 - r0, nx - 1)``."""
        return at_points(self._phi, field, r0, self.shape[0] - 1 if r1 is None else r1)

    def matrix(self, g, A=None) -> sp.csr_matrix:
        if np.shape(g) != self.shape:
            raise InputError(f"coefficient shape {np.shape(g)} does not match the grid "
                             f"{self.shape}")
        if A is not None and np.shape(A) != (*self.shape, 2, 2):
            raise InputError(f"flow factor field shape {np.shape(A)} is not {(*self.shape, 2, 2)}")
        ny, nx = self.shape
        A4 = None if A is None else np.asarray(A, float).reshape(ny, nx, 4).transpose(2, 0, 1)
        S = np.zeros((ny, nx, 3, 3))
        rows = max(1, BLOCK // (nx - 1))
        for r0 in range(0, ny - 1, rows):
            r1 = min(r0 + rows, ny - 1)
            gq = self.at_quadrature(g, r0, r1)                       # (nq, rows, nx - 1)
            if self._scale is not None:
                Aq = (np.eye(2).reshape(1, 2, 2, 1, 1) if A4 is None else
                      self.at_quadrature(A4, r0, r1).reshape(-1, 2, 2, r1 - r0, nx - 1))
                coef, T = gq[:, None, None] * Aq * self._scale[:, :, r0:r1], self._T
            elif A4 is None:
                coef, T = gq, self._T[:, 0, 0] + self._T[:, 1, 1]
            else:
                coef, T = gq[:, None] * self.at_quadrature(A4, r0, r1), self._T
            # (16, elements): each entry of the element matrices contiguous
            local = T.reshape(-1, 16).T @ coef.reshape(-1, (r1 - r0) * (nx - 1))
            self._stencil.add_elements(S, local.reshape(4, 4, r1 - r0, nx - 1), r0)
        return self._stencil.csr(S)


@lru_cache(maxsize=8)
def _assembly(shape, spacing) -> PoiseuilleAssembly:
    return PoiseuilleAssembly(shape, spacing)


@lru_cache(maxsize=8)
def graded_assembly(mesh: Mesh) -> PoiseuilleAssembly:
    """The (cached) :class:`PoiseuilleAssembly` of a graded ``Mesh``."""
    return PoiseuilleAssembly(mesh.shape, mesh.pitch, sizes=mesh.sizes)


def _element_scales(h1, h2) -> np.ndarray:
    """``(2, 2, ny - 1, nx - 1)``: the factors of a ``h1 x h2`` element's ``d_k phi d_m phi``
    integrals over the unit square's (Q1: ``h2/h1``, ``1``, ``1``, ``h1/h2``)."""
    r = h2[:, None] / h1[None, :]
    return np.array([[r, np.ones_like(r)], [np.ones_like(r), 1 / r]])


