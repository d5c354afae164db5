"""Reynolds equation with mass-conserving (JFO) cavitation on the macro grid (eqs 17-18).

    0 = div( G grad p - q (1 - theta) ),   p theta = 0,  p >= 0,  theta >= 0,

with ``p = p_hd - p_cav``, ``G = rho h^3 A / (12 mu)`` and ``q = rho h u_m b`` (smooth, rigid:
``A = I``, ``b = e1``).  Nodes are pixels, ``p = p_amb - p_cav`` and ``theta = 0`` on the
four edges (flooded inlet).

Discretisation.  The Poiseuille term is the Q1 finite-element stiffness of ``G`` (scikit-fem
form, 2 x 2 Gauss) for ``method="fe"``, or the paper's 5-point central finite volumes for
``method="fvm"``.  The Couette term is in both a flux through the faces of the node's dual
cell with the liquid fraction ``1 - theta`` from the upstream node
(:mod:`fem_twin.macro.couette`): the face-centred, second-order ``"central"`` scheme by
default, the paper's first-order ``"upwind"`` one as an option.  A Galerkin Couette term is
unstable here: in a cavitated zone the equation is pure transport of ``(1 - theta) h`` with
no pressure diffusion at all (infinite Peclet number), so only an upwind liquid fraction
keeps theta monotone, and the face fluxes conserve mass exactly (each leaves one dual cell
and enters the next).

Complementarity.  One unknown per node, ``phi``: ``p = max(phi, 0)``, ``theta =
max(-phi, 0) / s`` (the p-theta switch), which makes ``p theta = 0`` exact.  The residual
is piecewise linear in ``phi``; semismooth Newton (primal-dual active set) solves it and
stops when the active set no longer changes and the mass residual is below ``tol``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import skfem
from skfem.helpers import dot, grad

from ..errors import InputError, ReynoldsNotConverged
from ..assembly import FixedPattern, element_entries, unit_element
from ..io.mesh import grid_mesh
from ..linalg import SPDSolver, default_backend
from ..ordering import nested_dissection
from .couette import SCHEMES, couette_matrix
from .fbns import solve_complementarity_fb
from .lubricant import Lubricant
from .reynolds_fv import fvm_poiseuille


#: relative mass residual at which Newton steps can no longer improve the solution
ROUND_OFF = 1e3 * np.finfo(float).eps


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
def poiseuille_form(u, v, w):
    """Pressure flow of eq 17 with a scalar coefficient ``g = rho h^3 / (12 mu)`` [m^3/(Pa s)]."""
    return w.g * dot(grad(u), grad(v))


@skfem.BilinearForm
def homogenised_poiseuille_form(u, v, w):
    """Pressure flow of eq 17, ``g (A grad p) . grad v`` with the flow factor tensor ``A``."""
    du, dv = grad(u), grad(v)
    return w.g * (w.a11 * du[0] * dv[0] + w.a12 * du[1] * dv[0]
                  + w.a21 * du[0] * dv[1] + w.a22 * du[1] * dv[1])


def solve_reynolds(gap, spacing, speed, viscosity, *, ambient_pressure: float = 0.0,
                   cavitation_pressure: float = 0.0, method: str = "fe", tol: float = 1e-10,
                   max_iter: int = 200, complementarity: str = "switch",
                   couette: str = "central") -> ReynoldsResult:
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
        Couette flux of :mod:`fem_twin.macro.couette`
    """
    h = np.asarray(gap, dtype=float)
    if h.ndim != 2 or min(h.shape) < 3:
        raise InputError(f"gap must be a 2D field of at least 3 x 3 nodes, got shape {h.shape}")
    if not np.all(np.isfinite(h)) or h.min() <= 0:
        raise InputError("gap must be finite and positive everywhere [m]")
    lubricant = viscosity if isinstance(viscosity, Lubricant) else None
    mu0 = lubricant.viscosity if lubricant is not None else viscosity
    if not mu0 > 0:
        raise InputError(f"viscosity must be positive [Pa s], got {viscosity}")
    if ambient_pressure < cavitation_pressure:
        raise InputError("ambient pressure must not be below the cavitation pressure [Pa]")
    if method not in ("fe", "fvm"):
        raise InputError(f"method must be 'fe' or 'fvm', got {method!r}")
    if couette not in SCHEMES:
        raise InputError(f"couette must be one of {SCHEMES}, got {couette!r}")
    dx = tuple(float(s) for s in np.broadcast_to(np.asarray(spacing, float), (2,)))
    boundary = np.zeros(h.shape, bool)
    boundary[[0, -1], :] = boundary[:, [0, -1]] = True
    scale = 12 * mu0 * max(abs(speed), 1e-30) / 2 * float(np.mean(dx)) / np.mean(h) ** 2
    solver = complementarity_solver(complementarity)
    assemble = fe_poiseuille if method == "fe" else fvm_poiseuille
    mu, rho, phi, p_old, outer = mu0, 1.0, None, None, []
    for _ in range(max_iter if lubricant is not None else 1):
        g = rho * h ** 3 / (12 * mu)
        q1 = rho * h * speed / 2
        B = couette_matrix(q1, np.zeros_like(q1), dx, couette)
        phi, its, history = solver(assemble(g, dx), B, boundary,
                                   ambient_pressure - cavitation_pressure, scale, phi0=phi,
                                   tol=tol, max_iter=max_iter)
        p = np.maximum(phi, 0).reshape(h.shape)
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
    theta = (np.maximum(-phi, 0) / scale).reshape(h.shape)
    p_hd = p + cavitation_pressure
    load = float(np.sum(trapezoid_weights(h.shape, dx) * (p_hd - ambient_pressure)))
    return ReynoldsResult(p_hd, theta, load, its, tuple(history))


def trapezoid_weights(shape, dx) -> np.ndarray:
    """Nodal weights [m^2] of the trapezoidal rule on the node grid (half at the edges)."""
    w1 = np.full(shape[1], dx[0])
    w1[[0, -1]] /= 2
    w2 = np.full(shape[0], dx[1])
    w2[[0, -1]] /= 2
    return w2[:, None] * w1[None, :]


def fe_poiseuille(g, spacing, A=None) -> sp.csr_matrix:
    """Q1 stiffness of ``-div(g A grad p)`` on the node grid (nodes = pixels), non-periodic.

    ``g`` is ``(ny, nx)``; ``A`` is ``(ny, nx, 2, 2)`` (identity if None).  Nodal fields
    are interpolated to the 2 x 2 Gauss points.  The matrix is
    ``homogenised_poiseuille_form`` assembled by scikit-fem, re-assembled from element
    tensors computed once per grid (see :class:`PoiseuilleAssembly`).
    """
    g = np.asarray(g, dtype=float)
    return _assembly(g.shape, tuple(float(v) for v in spacing)).matrix(g, A)


class PoiseuilleAssembly:
    """Fast re-assembly of ``homogenised_poiseuille_form`` on one grid.

    Every element is the same rectangle, so the element matrix is
    ``sum_q g_q A_kl,q T[q, k, l]`` with 16 x 16 reference tensors ``T`` that scikit-fem
    assembles once on a single element (unit coefficient at one quadrature point and one
    tensor entry).  A new matrix is then one ``einsum`` and one ``bincount`` onto a CSR
    pattern fixed in advance: about 10x faster than ``BilinearForm.assemble`` with five
    interpolated coefficient fields (``benchmarks/run.py macro``).
    """

    def __init__(self, shape, spacing):
        gm = grid_mesh(shape, spacing)
        self.shape = tuple(shape)
        self._pix = gm.node_pixel[gm.mesh.t]                   # (4, nelems)
        b = unit_element(spacing)
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
        self._pattern = FixedPattern.from_entries(*element_entries(self._pix),
                                                  shape[0] * shape[1])

    def at_quadrature(self, field) -> np.ndarray:
        """Nodal field ``(ny, nx, ...)`` -> values at the Gauss points ``(nelems, nq, ...)``."""
        f = np.asarray(field, float).reshape(self.shape[0] * self.shape[1], -1)[self._pix]
        return np.einsum("iec,iq->eqc", f, self._phi)

    def matrix(self, g, A=None) -> sp.csr_matrix:
        if np.shape(g) != self.shape:
            raise InputError(f"coefficient shape {np.shape(g)} does not match the grid "
                             f"{self.shape}")
        if A is not None and np.shape(A) != (*self.shape, 2, 2):
            raise InputError(f"flow factor field shape {np.shape(A)} is not {(*self.shape, 2, 2)}")
        gq = self.at_quadrature(g)                               # (nelems, nq, 1)
        if A is None:
            data = gq[..., 0] @ (self._T[:, 0, 0] + self._T[:, 1, 1])
        else:
            coef = gq * self.at_quadrature(np.asarray(A, float).reshape(*self.shape, 4))
            data = coef.reshape(coef.shape[0], -1) @ self._T.reshape(-1, 16)
        return self._pattern.csr(data)


@lru_cache(maxsize=8)
def _assembly(shape, spacing) -> PoiseuilleAssembly:
    return PoiseuilleAssembly(shape, spacing)


def complementarity_solver(name: str):
    """``"switch"`` -> :func:`solve_complementarity`, ``"fb"`` -> the FBNS solver."""
    if name == "switch":
        return solve_complementarity
    if name == "fb":
        return solve_complementarity_fb
    raise InputError(f"complementarity must be 'switch' or 'fb', got {name!r}")


def solve_complementarity(K, B, dirichlet, p_boundary, scale, *, phi0=None, tol=1e-10,
                          max_iter=200, inexact=False):
    """Semismooth Newton on ``K p + B (1 - theta) = 0`` with the p-theta switch ``phi``.

    Dirichlet nodes keep ``p = p_boundary``, ``theta = 0``.  ``phi0`` warm-starts the
    interior; ``inexact`` returns the iterate after ``max_iter`` steps instead of raising (a
    truncated inner solve of a fixed point that ends on an exact one).
    Returns ``phi``, the number of iterations and the residual history (scaled by
    the size of each node's fluxes, ``|K| p + |B| 1``).  Each Newton matrix is factorised by SuperLU in a
    nested-dissection order of the grid (computed once per grid).
    """
    n = K.shape[0]
    interior = np.flatnonzero(~dirichlet)
    phi = np.full(n, float(p_boundary))
    if phi0 is not None:
        phi[interior] = np.asarray(phi0, float).ravel()[interior]
    ones = np.ones(n)
    absK, absB = abs(K[interior]), abs(B[interior])
    couette_size = absB @ ones
    floor = 1e-300 + 1e-12 * float(couette_size.max())
    order = _interior_order(tuple(dirichlet.shape) if dirichlet.ndim == 2 else None,
                            dirichlet.ravel(), interior)
    KI, BI = K[interior], B[interior]

    def residual(phi):
        pos = phi >= 0
        p = np.where(pos, phi, 0.0)
        r = KI @ p + BI @ (ones - np.where(pos, 0.0, -phi / scale))
        # each node's mass residual relative to the size of its own fluxes
        res = float(np.max(np.abs(r) / (absK @ p + couette_size + floor)))
        return r, pos, res

    newton = _newton_solver(tuple(dirichlet.shape) if dirichlet.ndim == 2 else None,
                            dirichlet.ravel(), interior, K, B)
    history, active_old = [], None
    r, pos, res = residual(phi)
    for it in range(1, max_iter + 1):
        history.append(res)
        # converged: the active set is settled, or the residual is at round-off (nodes with
        # p = 0 exactly, e.g. a pocket at p_cav, can flip sign from one step to the next)
        if res < tol and active_old is not None and (np.array_equal(pos, active_old)
                                                     or res < ROUND_OFF):
            return phi, it, history
        active_old = pos
        dtheta = np.where(pos, 0.0, 1.0 / scale)       # d(1 - theta)/dphi = +1/scale
        step = None if newton is None else newton(pos[interior], dtheta[interior], -r)
        if step is not None:
            phi[interior] += step
            r, pos, res = residual(phi)
            continue
        J = (KI @ sp.diags(pos.astype(float)) + BI @ sp.diags(dtheta))[:, interior]
        step = np.empty(interior.size)
        try:
            lu = spla.splu(J[order][:, order].tocsc(), permc_spec="NATURAL",
                           diag_pivot_thresh=0.1, options={"SymmetricMode": True})
            step[order] = lu.solve(-r[order])
        except RuntimeError as err:               # exactly singular
            raise ReynoldsNotConverged(f"singular Newton matrix in the cavitation loop: {err}",
                                       history) from err
        if not np.all(np.isfinite(step)):
            raise ReynoldsNotConverged("singular Newton matrix in the cavitation loop", history)
        phi[interior] += step
        r, pos, res = residual(phi)
    if inexact:
        return phi, max_iter + 1, history
    raise ReynoldsNotConverged(f"no convergence in {max_iter} Newton steps (tol {tol})", history)


def _newton_solver(shape, dirichlet, interior, K, B):
    """``step(pos, dtheta, rhs)`` solving the Newton system ``(K diag(pos) + B diag(dtheta))
    step = rhs`` on the interior with PARDISO, whose ordering and symbolic factorisation
    are kept per grid (the pattern: the 3x3 stencil, which holds K and every upwind B);
    None without PARDISO.  A step returns None (the caller then uses SuperLU) when pivots
    were perturbed or the step does not solve the system to 1e-8."""
    if shape is None or default_backend() != "pardiso":
        return None
    key = (shape, dirichlet.tobytes())
    if _NEWTON_CACHE.get("key") != key:
        _NEWTON_CACHE.update(key=key, pattern=_stencil_pattern(shape, interior))
    indptr, indices, keys, solver = _NEWTON_CACHE["pattern"]
    n = interior.size
    parts = []
    for M in (K, B):
        M = M[interior][:, interior].tocoo()
        entries = M.row.astype(np.int64) * n + M.col
        at = np.searchsorted(keys, entries)
        if not np.array_equal(keys[np.minimum(at, keys.size - 1)], entries):
            return None                           # not a stencil matrix: the general path
        parts.append((at, M.data, M.col))

    def step(pos, dtheta, rhs):
        values = sum(np.bincount(at, data * w[col], minlength=keys.size)
                     for (at, data, col), w in zip(parts, (pos.astype(float), dtheta)))
        size = float(np.abs(values).max())            # PARDISO's pivot threshold is absolute
        x = solver.factor(values / size).solve(rhs / size)
        J = sp.csr_matrix((values, indices, indptr), shape=(n, n))
        if solver.perturbed or not np.all(np.isfinite(x)) or (
                np.linalg.norm(J @ x - rhs) > 1e-8 * np.linalg.norm(rhs)):
            return None
        return x
    return step


def _stencil_pattern(shape, interior):
    """CSR pattern of the 3x3 stencil on the interior nodes, its sorted keys row * n + col,
    and a PARDISO LU solver on it (analysis once)."""
    ny, nx = shape
    position = np.full(ny * nx, -1)
    position[interior] = np.arange(interior.size)
    idx = np.arange(ny * nx).reshape(ny, nx)
    rows, cols = [], []
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            a = idx[max(0, -di):ny - max(0, di), max(0, -dj):nx - max(0, dj)]
            b = idx[max(0, di):ny - max(0, -di), max(0, dj):nx - max(0, -dj)]
            rows.append(position[a.ravel()])
            cols.append(position[b.ravel()])
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    keep = (rows >= 0) & (cols >= 0)
    n = interior.size
    P = sp.csr_matrix((np.ones(keep.sum()), (rows[keep], cols[keep])), shape=(n, n))
    P.sort_indices()
    keys = np.repeat(np.arange(n, dtype=np.int64), np.diff(P.indptr)) * n + P.indices
    return P.indptr, P.indices, keys, SPDSolver(P.indptr, P.indices, "pardiso",
                                                symmetric=False)


_NEWTON_CACHE: dict = {}


def _interior_order(shape, dirichlet, interior):
    """Nested-dissection order of the interior unknowns (COLAMD-like fallback: identity)."""
    if shape is None:
        return np.arange(interior.size)
    key = (shape, dirichlet.tobytes())
    if _ORDER_CACHE.get("key") != key:
        full = nested_dissection(shape)
        position = np.full(dirichlet.size, -1)
        position[interior] = np.arange(interior.size)
        _ORDER_CACHE.update(key=key, order=position[full][position[full] >= 0])
    return _ORDER_CACHE["order"]


_ORDER_CACHE: dict = {}
