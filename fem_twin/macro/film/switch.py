"""The p-theta switch solver of the JFO complementarity problem (eqs 17-18).

One unknown per node, ``phi``: ``p = max(phi, 0)``, ``theta = max(-phi, 0) / s`` (the p-theta
switch), which makes ``p theta = 0`` exact.  The residual is piecewise linear in ``phi``;
semismooth Newton (primal-dual active set) solves it and stops when the active set no
longer changes and the mass residual is below ``tol``.  Each Newton step is solved by
PARDISO on the fixed 3x3-stencil pattern of the grid (:mod:`.stencil_solver`) or, without
MKL, by SuperLU in a nested-dissection order.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ...errors import ReynoldsNotConverged
from ...numerics.ordering import subgrid_order
from .stencil_solver import newton_solver

#: relative mass residual at which Newton steps can no longer improve the solution
ROUND_OFF = 1e3 * np.finfo(float).eps


def solve_complementarity(K, B, dirichlet, p_boundary, scale, *, phi0=None, tol=1e-10,
                          max_iter=200, inexact=False, settle=0.0, source=None):
    """Semismooth Newton on ``K p + B (1 - theta) = f`` with the p-theta switch ``phi``
    (``source`` f, each node's inflow [m^3/s]; default 0: a time step's earlier film
    content, :mod:`fem_twin.macro.reference.time_resolved`).

    Dirichlet nodes keep ``p = p_boundary``, ``theta = 0``.  ``phi0`` warm-starts the
    interior; ``inexact`` returns the iterate after ``max_iter`` steps instead of raising (a
    truncated inner solve of a fixed point that ends on an exact one).  ``settle`` > 0
    also returns, after two steps or more, the iterate of the first step that switches at
    most ``settle`` times as many nodes between film and cavity as the first step did (the
    active set has settled; the tail of one- and two-node steps at a degenerate free
    boundary is left to the fixed point's next solves).
    Returns ``phi``, the number of iterations and the residual history (scaled by the size
    of each node's fluxes, ``|K| p + |B| 1``).  Each Newton step is solved by
    :func:`.stencil_solver.newton_solver`, else by SuperLU in a nested-dissection order of
    the grid (computed once per grid).
    """
    n = K.shape[0]
    interior = np.flatnonzero(~dirichlet)
    phi = np.full(n, float(p_boundary))
    if phi0 is not None:
        phi[interior] = np.asarray(phi0, float).ravel()[interior]
    K, B = K.tocsr(), B.tocsr()
    couette_size = _absolute(B) @ np.ones(n)
    f = None if source is None else np.asarray(source, float).ravel()[interior]
    if f is not None:
        couette_size[interior] += np.abs(f)
    floor = 1e-300 + 1e-12 * float(couette_size.max())

    def residual(phi):
        # full products, then the interior rows: no copy of K's and B's rows kept alive
        pos = phi >= 0
        p = np.where(pos, phi, 0.0)
        r = (K @ p + B @ np.where(pos, 1.0, 1.0 + phi / scale))[interior]
        if f is not None:
            r -= f
        # each node's mass residual relative to the size of its own fluxes
        size = (_absolute(K) @ p)[interior] + couette_size[interior] + floor
        return r, pos, float(np.max(np.abs(r) / size))

    newton = newton_solver(tuple(dirichlet.shape) if dirichlet.ndim == 2 else None,
                            dirichlet.ravel(), interior, K, B)
    try:
        return _newton_loop(K, B, dirichlet, interior, scale, phi, residual, newton, tol,
                            max_iter, inexact, settle)
    finally:
        if newton is not None:
            newton.release()


def _newton_loop(K, B, dirichlet, interior, scale, phi, residual, newton, tol, max_iter,
                 inexact, settle):
    """The semismooth Newton iteration of :func:`solve_complementarity` from ``phi``."""
    history, active_old, first = [], None, None
    r, pos, res = residual(phi)
    for it in range(1, max_iter + 1):
        history.append(res)
        # converged: the active set is settled, or the residual is at round-off (nodes with
        # p = 0 exactly, e.g. a pocket at p_cav, can flip sign from one step to the next)
        if res < tol and active_old is not None and (np.array_equal(pos, active_old)
                                                     or res < ROUND_OFF):
            return phi, it, history
        if settle and active_old is not None:
            switched = np.count_nonzero(pos != active_old)
            first = switched if first is None else first
            if it > 2 and switched <= settle * first:
                return phi, it, history
        active_old = pos
        dtheta = np.where(pos, 0.0, 1.0 / scale)       # d(1 - theta)/dphi = +1/scale
        step = None if newton is None else newton(pos[interior], dtheta[interior], -r)
        if step is not None:
            phi[interior] += step
            r, pos, res = residual(phi)
            continue
        J = (K @ sp.diags(pos.astype(float)) + B @ sp.diags(dtheta))[interior][:, interior]
        order = _interior_order(tuple(dirichlet.shape) if dirichlet.ndim == 2 else None,
                                dirichlet.ravel(), interior)
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


def _absolute(M):
    """``|M|`` entrywise, sharing ``M``'s index arrays (CSR)."""
    return sp.csr_matrix((np.abs(M.data), M.indices, M.indptr), shape=M.shape, copy=False)


def _interior_order(shape, dirichlet, interior):
    """Nested-dissection order of the interior unknowns (COLAMD-like fallback: identity)."""
    if shape is None:
        return np.arange(interior.size)
    key = (shape, dirichlet.tobytes())
    if _ORDER_CACHE.get("key") != key:
        position = np.full(dirichlet.size, -1)
        position[interior] = np.arange(interior.size)
        _ORDER_CACHE.update(key=key, order=subgrid_order(shape, position))
    return _ORDER_CACHE["order"]


_ORDER_CACHE: dict = {}
