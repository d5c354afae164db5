"""Newton steps of the p-theta switch (:mod:`.switch`) on the grid's 3x3 stencil.

The Newton matrix ``J = K diag(pos) + B diag(dtheta)`` lives on a pattern fixed per grid:
PARDISO's symbolic factorisation is computed once per grid in its nested-dissection order
(:func:`fem_twin.numerics.ordering.subgrid_order`), so a step costs one numeric
factorisation and a solve.  Above ``SINGLE_UNKNOWNS`` unknowns the factors are single
precision, refined with the double-precision residual.  The factors of a step serve the
next steps of the same inner solve: a matrix that differs in the ``m`` columns of nodes
switched since is solved with them updated by the Woodbury identity (Hager 1989) as the
refinement's preconditioner, when that takes at most :meth:`_Grid.budget` solves.  A step
is returned only when it solves ``J x = rhs`` to ``STEP_RTOL``; the factors are freed when
the inner solve ends (``step.release()``).  Measured by ``python benchmarks/run.py scale``
and ``amg``."""

from __future__ import annotations

import hashlib
from collections import OrderedDict

import numpy as np
import scipy.sparse as sp

from ...numerics.assembly import grid_stencil
from ...numerics.linalg import SPDSolver, default_backend
from ...numerics.ordering import subgrid_order

#: relative residual ``|J x - rhs| / |rhs|`` a step must reach
STEP_RTOL = 1e-8
#: iterative refinement steps (residual in double precision) with the single-precision
#: factors; each gains about five digits
REFINEMENTS = 4
#: the largest entry of the equilibrated matrix a factorisation takes
#: (float32 overflows at 3.4e38; beyond this the step goes to SuperLU in double precision)
SINGLE_MAX = 1e30
#: the most switched columns the kept factors are updated for (``W``: 16 vectors of the
#: grid in the factors' precision, 0.22 GB at 2048^2), and the most solves a step may
#: spend with them ...
REUSE_SOLVES = 16
#: ... which is at most half a factorisation's time: a step takes one solve per node newly
#: switched, plus about two refinement passes.  A factorisation costs about
#: ``1.44 n^0.2`` solves of the grid's ``n`` unknowns (PARDISO, one thread), a rule of the
#: size rather than of measured times so that a run repeats to the last bit
REUSE_SHARE = 0.5 * 1.44
#: grids of more unknowns factorise in single precision (from about 181^2 nodes: faster
#: from there on, C_f the same to 1e-13)
SINGLE_UNKNOWNS = 1 << 15
#: grids whose patterns and PARDISO analyses are kept (a sweep with error estimates
#: alternates between the grid and its coarsening) ...
GRIDS = 3
#: ... while the unknowns of those smaller than the current one add up to at most this: at
#: 2048^2 the 1024^2 grid's analysis (0.4 GiB) is not kept beside the 2048^2 one, and is
#: redone (0.8 s) at each point's coarse solve
KEPT_UNKNOWNS = 1 << 19


def newton_solver(shape, dirichlet, interior, K, B):
    """``step(pos, dtheta, rhs)`` solving ``(K diag(pos) + B diag(dtheta)) x = rhs`` on the
    interior with PARDISO, or None without PARDISO or when ``K`` or ``B`` leave the 3x3
    stencil.  A step returns None (the caller then uses SuperLU) when pivots were perturbed
    or it does not reach ``STEP_RTOL``.  The factors of a step serve the next ones (see the
    module docstring) until ``step.release()``, which the caller calls when its solve
    ends."""
    if shape is None or default_backend() != "pardiso":
        return None
    grid = _grid(shape, dirichlet, interior)
    K, B = K.tocsr(), B.tocsr()
    maps = [grid.locate(M) for M in (K, B)]
    if any(found is None for found in maps):
        return None

    kept = {}                                 # the switch of the kept factorisation

    def step(pos, dtheta, rhs):
        def values():
            v = grid.entries(K, maps[0], pos)
            v += grid.entries(B, maps[1], dtheta)
            return v

        def product(x):
            """``J x`` from ``K`` and ``B`` themselves (no copy of ``J`` in double)."""
            u, v = np.zeros(K.shape[0]), np.zeros(K.shape[0])
            u[interior], v[interior] = pos * x, dtheta * x
            return (K @ u + B @ v)[interior]

        def difference(columns):
            """``(J - J_0)[:, columns]`` (dense, interior rows), ``J_0`` the kept one's."""
            nodes, at = interior[columns], np.arange(columns.size)
            dpos = sp.csc_matrix((pos[columns] - kept["pos"][columns].astype(float),
                                  (nodes, at)), shape=(K.shape[0], columns.size))
            dtht = sp.csc_matrix((dtheta[columns] - kept["dtheta"][columns], (nodes, at)),
                                 shape=dpos.shape)
            return (K @ dpos + B @ dtht).toarray()[interior]
        if kept:
            switched = np.flatnonzero((pos != kept["pos"]) | (dtheta != kept["dtheta"]))
            x = grid.solve_kept(switched, np.c_[pos[switched], dtheta[switched]],
                                difference, product, rhs)
            if x is not None:
                return x
        kept.clear()
        x = grid.factor_and_solve(values(), product, rhs)
        if x is not None:
            kept.update(pos=pos.copy(), dtheta=dtheta.copy())
        return x
    step.release = grid.release
    return step


class _Grid:
    """One grid's stencil pattern, its PARDISO solver and the maps of ``K`` and ``B``."""

    def __init__(self, shape, interior):
        self.shape = tuple(shape)
        self.position = np.full(shape[0] * shape[1], -1)
        self.position[interior] = np.arange(interior.size)
        self.n = interior.size
        self.indptr, self.indices = _stencil_pattern(shape, self.position, self.n)
        self.counts = np.diff(self.indptr)                       # entries per row
        self.diagonal = np.flatnonzero(np.repeat(np.arange(self.n), self.counts)
                                       == self.indices)
        self.solver = SPDSolver(self.indptr, self.indices, "pardiso", symmetric=False,
                                single=self.n > SINGLE_UNKNOWNS,
                                order=subgrid_order(shape, self.position))
        self._maps = []                       # [(digest, at, keep)]
        self.scale = None                     # the equilibration of the kept factors
        self.columns = {}                     # node: (its state, its column of W)

    def locate(self, M):
        """``(at, keep)``: the position ``at`` in the pattern of each interior entry ``keep``
        of the CSR matrix ``M``, or None if ``M`` leaves the stencil.  Kept per sparsity
        pattern of ``M``, known by a digest of it (at 2048^2 a copy of the pattern would
        hold 40 B a node), or as the grid's own 3 x 3 stencil
        (:func:`fem_twin.numerics.assembly.grid_stencil`, on which ``K`` and ``B`` are assembled:
        compared in 0.03 s at 2048^2, where the digest takes 0.13 s)."""
        stencil = grid_stencil(self.shape)
        own = (M.shape == (stencil.indptr.size - 1,) * 2
               and np.array_equal(M.indptr, stencil.indptr)
               and np.array_equal(M.indices, stencil.indices))
        digest = b"grid stencil" if own else _digest(M)
        found = next((m for m in self._maps if m[0] == digest), None) or self._map(M, digest)
        return None if found is None else found[1:]

    def entries(self, M, found, weight):
        """The interior entries of ``M diag(weight)`` in the pattern's order (zeros where
        ``M`` has none), ``found`` from :meth:`locate` (computed per step, so no copy of
        ``M`` is alive during the factorisation)."""
        at, keep = found
        if at is None:                        # M's interior entries are the pattern
            return M.data[keep] * weight[self.indices]
        return np.bincount(at, M.data[keep] * weight[self.indices[at]],
                           minlength=self.indices.size)

    def _map(self, M, digest):
        """``(digest, at, keep)`` for a new sparsity pattern of ``M``: the position in the
        pattern of each of its interior entries ``keep``; None if one lies outside."""
        rows = self.position[np.repeat(np.arange(M.shape[0]), np.diff(M.indptr))]
        cols = self.position[M.indices]
        keep = (rows >= 0) & (cols >= 0)
        entries = rows[keep].astype(np.int64) * self.n + cols[keep]
        keys = np.repeat(np.arange(self.n) * self.n, self.counts) + self.indices  # sorted
        at = np.searchsorted(keys, entries)
        if not np.array_equal(keys[np.minimum(at, keys.size - 1)], entries):
            return None
        # ``at`` only feeds bincount, as fast from int32; None where it is every position
        # of the pattern in order (``M`` on the grid's stencil, as K and B are)
        at = None if np.array_equal(at, np.arange(keys.size)) else at.astype(np.int32)
        self._maps = [*self._maps[-1:], (digest, at, keep)]
        return self._maps[-1]

    def factor_and_solve(self, data, product, rhs):
        """Factorise ``J`` (its CSR data in the pattern's order: ``data``, which this takes
        over) and solve, refined with ``product(x) = J x`` in double precision; None if
        pivots were perturbed or the step falls short of ``STEP_RTOL``.  The matrix is
        equilibrated first, ``S J S`` with ``S`` the inverse square root of its diagonal:
        PARDISO's pivot threshold is absolute, and the film's ``h^3`` spans 1e9 over a pin
        face (a 20 nm film beside the 40 um edge).  It is scaled straight into the factors'
        precision, and ``data`` is freed before the factorisation (0.25 GB at 2048^2)."""
        self.release()                        # the kept factors go before new ones come
        d = np.abs(data[self.diagonal])
        scale = 1 / np.sqrt(np.where(d > 0, d, max(float(d.max()), 1e-300)))
        own = scale.astype(self.solver.dtype)
        with np.errstate(over="ignore", invalid="ignore"):
            scaled = np.repeat(own, self.counts)          # the factors' precision: no
            scaled *= data                                # second double copy alive
            scaled *= own[self.indices]
        del data
        if not np.abs(scaled).max() < SINGLE_MAX:         # inf or nan too
            return None                       # beyond single precision: the general path
        self.solver.factor(scaled)
        del scaled
        self.scale = scale
        x = None if self.solver.perturbed else self._refined(product, rhs)
        if x is None:
            self.release()
        return x

    def solve_kept(self, switched, states, difference, product, rhs):
        """``x`` solving ``J x = rhs`` (``product(x) = J x``) to ``STEP_RTOL`` with the kept
        factors of ``J_0`` updated for the columns ``switched`` (Woodbury, see the module
        docstring), refined in double precision; ``states`` (a row per switched column)
        tell whether a kept ``W`` column still holds, ``difference(columns)`` gives the new
        ones' ``(J - J_0)[:, columns]``.  None (and the factors freed) when the step would
        take more than :meth:`budget` solves or falls short of ``STEP_RTOL``."""
        if switched.size > REUSE_SOLVES:
            self.release()
            return None
        kept = {k: self.columns[k] for k, state in zip(switched, states)
                if k in self.columns and np.array_equal(self.columns[k][0], state)}
        new = np.array([k for k in switched if k not in kept], int)
        if new.size + 2 > self.budget():
            self.release()
            return None
        self.columns = kept                   # columns switched back are dropped
        for k, state, u in zip(new, states[np.isin(switched, new)], difference(new).T):
            # kept in the factors' precision: computed with them, W is no more accurate
            self.columns[k] = (state, self._precondition(u).astype(self.solver.dtype))
        W = [self.columns[k][1] for k in switched]                # no (n, m) copy
        small = np.zeros((switched.size,) * 2)                    # V^T W
        for k, w in enumerate(W):
            small[:, k] = w[switched]
        try:
            capacitance = np.linalg.inv(np.eye(switched.size) + small)
        except np.linalg.LinAlgError:
            capacitance = np.full((switched.size,) * 2, np.nan)

        def updated(r):
            z = self._precondition(r)
            for w, c in zip(W, capacitance @ z[switched]):
                z -= c * w
            return z
        x = self._refined(product, rhs, updated)
        if x is None:
            self.release()
        return x

    def budget(self) -> int:
        """Solves with the kept factors a step may take: half a factorisation's cost, at
        most ``REUSE_SOLVES`` (0 without kept factors)."""
        if self.scale is None:
            return 0
        return int(min(REUSE_SOLVES, REUSE_SHARE * self.n ** 0.2))

    def release(self):
        """Free the kept factors and their update's columns (the analysis stays)."""
        self.solver.release()
        self.scale, self.columns = None, {}

    def _precondition(self, r):
        """The kept factors' solution of ``J x = r`` (the solve sees ``r`` over its size:
        no overflow in single precision)."""
        b = self.scale * r
        size = np.abs(b).max()
        if not 0 < size < np.inf:
            return np.full_like(r, np.nan)
        return self.scale * self.solver.solve(b / size) * size

    def _refined(self, product, rhs, inverse=None):
        """``x`` solving ``J x = rhs`` (``product(x) = J x``) to ``STEP_RTOL`` by refinement
        with ``inverse(r)``, an approximate ``J^-1 r`` (default: the factors of the
        equilibrated ``J``), or None."""
        inverse = inverse or self._precondition
        x, residual = np.zeros_like(rhs), rhs
        target = STEP_RTOL * np.linalg.norm(rhs)
        for _ in range(1 + REFINEMENTS):
            if np.linalg.norm(residual) <= target:
                return x
            x = x + inverse(residual)
            if not np.all(np.isfinite(x)):
                return None
            residual = rhs - product(x)
        return x if np.linalg.norm(residual) <= target else None


def _grid(shape, dirichlet, interior) -> _Grid:
    key = (tuple(shape), dirichlet.tobytes())
    grid = _GRIDS.pop(key, None) or _Grid(shape, interior)
    while _GRIDS and (len(_GRIDS) >= GRIDS or sum(
            g.n for g in _GRIDS.values() if g.n < grid.n) > KEPT_UNKNOWNS):
        # the least recently used of the smaller grids first (the finest grid sets the
        # peak), the finest one last (a nested point's levels run coarse to fine)
        finest = max(_GRIDS, key=lambda k: _GRIDS[k].n)
        victims = ([k for k, g in _GRIDS.items() if g.n < grid.n]
                   or [k for k in _GRIDS if k != finest] or [finest])
        del _GRIDS[victims[0]]
    _GRIDS[key] = grid
    return grid


def _stencil_pattern(shape, position, n):
    """CSR pattern (``indptr``, ``indices``) of the 3x3 stencil on the ``n`` interior nodes
    (``position``: each node's interior number, -1 elsewhere)."""
    ny, nx = shape
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
    P = sp.csr_matrix((np.ones(keep.sum()), (rows[keep], cols[keep])), shape=(n, n))
    P.sort_indices()
    return P.indptr, P.indices


def _digest(M) -> bytes:
    """A digest of the sparsity pattern of the CSR matrix ``M``."""
    h = hashlib.blake2b(digest_size=16)
    for a in (np.asarray(M.shape), M.indptr, M.indices):
        h.update(np.ascontiguousarray(a))
    return h.digest()


_GRIDS: OrderedDict = OrderedDict()
