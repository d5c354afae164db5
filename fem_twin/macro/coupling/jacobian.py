"""The linear algebra of one Newton step of the monolithic coupling (:mod:`.newton`).

The Jacobian is exact: the ``h0``-derivatives of the flow factors by central differences of
their interpolation, the Poiseuille operator's coefficient derivatives by probing it with
nine colourings of the grid.  Each step is solved by right-preconditioned GMRES with the
exact Jacobian action (the half-space operator ``E`` by FFT); the preconditioner is the
Jacobian with the elastic coupling kept, as a dense block, on the set ``S`` of nodes where
it outweighs the pressure flow (the loaded zone of the contact), and dropped elsewhere;
``S`` is eliminated by a Schur complement on a sparse LU of the rest (in the grid's
nested-dissection order), which needs that LU's inverse only between ``S``'s neighbours:
memory of the LU and the dense block alone (a pin point at 1024^2: 3.6 GiB, where the
dense ``J_OO^-1`` columns of every neighbour took more than 16 GiB).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ...errors import SolverError
from ...numerics.ordering import subgrid_order
from ..film.cavitation import cavitation_model
from ..film.contact_load import contact_load
from ..laws.kinematics import rotate_tensor, rotate_vector
from .evaluation import NewtonEvaluation
from .problem import MAX_COEFFICIENT_PRESSURE, Problem

#: a node joins the dense elastic block when its elastic coupling exceeds this fraction of
#: its pressure-flow coupling (the fastest on the ball's points: ``benchmarks/run.py
#: ball-newton``)
DENSE_THRESHOLD = 1.0


#: most nodes in the dense block (a 4000^2 LU takes about 2 s here)
MAX_DENSE = 4000
#: the most entries of the right-hand sides solved at once for the Schur complement
#: (16M: 128 MB)
SOLVE_BLOCK = 1 << 24


def _probe(P: Problem, coefficients, p) -> sp.csr_matrix:
    """The matrix ``M`` with ``M[:, k] = K(*coefficients(e_k)) p``, where ``K`` (the
    Poiseuille operator, bilinear in its nodal coefficient fields) takes the fields that
    ``coefficients(mask)`` returns for a node mask: probed with nine colourings of the grid
    (the 3 x 3 stencil of a node's coefficient never overlaps its colour mates)."""
    ny, nx = P.shape
    i, j = np.divmod(np.arange(ny * nx), nx)
    rows, cols, vals = [], [], []
    for ci in range(3):
        for cj in range(3):
            colour = ((i % 3 == ci) & (j % 3 == cj)).astype(float).reshape(ny, nx)
            v = P.poiseuille(*coefficients(colour)) @ p
            # the node of this colour in each row's 3 x 3 neighbourhood
            ni = i + (ci - i) % 3 - np.where((ci - i) % 3 == 2, 3, 0)
            nj = j + (cj - j) % 3 - np.where((cj - j) % 3 == 2, 3, 0)
            ok = (ni >= 0) & (ni < ny) & (nj >= 0) & (nj < nx) & (v != 0)
            rows.append(np.flatnonzero(ok))
            cols.append((ni * nx + nj)[ok])
            vals.append(v[ok])
    n = ny * nx
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(n, n))


def jacobian(P: Problem, ev: NewtonEvaluation) -> dict:
    """The sparse blocks of the Jacobian: ``J_pp = dR/dphi`` (interior x interior),
    ``J_ph = dR/dh0`` (interior x all, through h_m, A and b), ``pos`` (dp/dphi) and
    ``dpc = dp_con/dh0`` (per node; with the ``"gauss"`` contact quadrature the row sums of
    ``Dpc``, the sparse ``dp_con,i/dh0_j`` that the exact action uses)."""
    lub, I = P.point.lubricant, P.interior
    pos, dtheta = cavitation_model(P.point.settings.complementarity).derivatives(
        ev.phi.ravel(), P.point.settings.p_ref)
    p_coef = np.minimum(ev.p, MAX_COEFFICIENT_PRESSURE)
    unclipped = ev.p < MAX_COEFFICIENT_PRESSURE
    dlnrho = lub.density_log_slope(p_coef) * unclipped
    dlnmu = lub.viscosity_log_slope(p_coef) * unclipped
    d = P.factors.slopes(ev.h0)
    if P.turn is not None:                              # into the grid frame, as loc's
        c, s, _ = P.turn
        d["A"], d["b"] = rotate_tensor(d["A"], c, s), rotate_vector(d["b"], c, s)
    free = ~ev.touching
    g, q, loc, p = ev.g, ev.q, ev.loc, ev.p.ravel()
    Kg = _probe(P, lambda c: (c, loc.A), p)
    KA = _probe(P, lambda c: (g, c[..., None, None] * d["A"] * free[..., None, None]), p)
    Q1, Q2 = ev.couette.q_derivatives(1 - ev.theta.ravel())
    b1, b2 = loc.b[..., 0].ravel(), loc.b[..., 1].ravel()
    Bq = Q1 @ sp.diags(b1) + Q2 @ sp.diags(b2)
    Bb = (Q1 @ sp.diags(q.ravel() * d["b"][..., 0].ravel())
          + Q2 @ sp.diags(q.ravel() * d["b"][..., 1].ravel()))
    dg_dp, dq_dp = (g * (dlnrho - dlnmu)).ravel(), (q * dlnrho).ravel()
    dhm = d["h_m"] * free
    dg_dh, dq_dh = (3 * g * dhm / loc.h_m).ravel(), (q * dhm / loc.h_m).ravel()
    J_p = (ev.K @ sp.diags(pos) + ev.B @ sp.diags(dtheta)
           + (Kg @ sp.diags(dg_dp) + Bq @ sp.diags(dq_dp)) @ sp.diags(pos))
    J_h = Kg @ sp.diags(dg_dh) + Bq @ sp.diags(dq_dh) + KA + Bb @ sp.diags(free.ravel() * 1.0)
    J_p, J_h = J_p.tocsr()[I], J_h.tocsr()[I]
    out = dict(J_pp=J_p[:, I].tocsc(), J_ph=J_h.tocsr(), pos=pos,
               dpc=(d["p_con"] * free).ravel(), Dpc=None)
    if P.point.settings.contact_quadrature != "nodal":        # p_con_i depends on its neighbours
        out["Dpc"] = contact_load(P.shape, P.mesh).derivative(P.factors, ev.h0, free)
        out["dpc"] = np.asarray(out["Dpc"].sum(axis=1)).ravel()    # lumped: preconditioner
    return out


@dataclass(frozen=True, eq=False)
class ElasticBlock:
    """The dense elastic block of a :class:`Preconditioner` on its node set ``S``:
    ``E = E_SS`` [m/Pa], the LU of ``I - E_SS p_con'`` (None without contact stiffness on
    ``S``) and ``ME = M E_SS`` with ``M`` that matrix's inverse, in single precision (a
    preconditioner's accuracy: GMRES runs on the exact action).  The cubic part of a
    build, kept by the rebuilds whose set it covers."""

    S: np.ndarray
    E: np.ndarray
    lu: tuple | None
    ME: np.ndarray

    @classmethod
    def build(cls, P: Problem, S: np.ndarray, dpc: np.ndarray) -> ElasticBlock:
        """The block on the flat nodes ``S`` with contact stiffness ``dpc = dp_con/dh0``
        [Pa/m] there."""
        E = P.dense_elastic(S).astype(np.float32)
        if not np.any(dpc):
            return cls(S, E, None, E)
        lu = la.lu_factor(np.eye(S.size, dtype=np.float32) - E * dpc.astype(np.float32),
                          overwrite_a=True, check_finite=False)
        return cls(S, E, lu, la.lu_solve(lu, E, check_finite=False))

    def M(self, r, transpose=False):
        """``M r`` (``M^T r``) in double."""
        if self.lu is None:
            return r
        return la.lu_solve(self.lu, r.astype(np.float32), trans=int(transpose),
                           check_finite=False).astype(float)


class Preconditioner:
    """Approximate inverse of the Newton matrix: the Jacobian with ``E`` kept on ``S x S``.

    Outside ``S`` the deformation update is the elastic residual alone; on ``S`` it is
    eliminated exactly (``dw_S = M_S (r_G + E_SS (D dphi + p_con' dh))``,
    ``M_S = (I - E_SS p_con')^-1``), which leaves the pressure system ``J_pp + J_ph[:, S] W``
    bordered by the load row; that is solved with a sparse LU outside ``S`` and a dense LU of
    the Schur complement on ``S``.
    """

    def __init__(self, P: Problem, jac: dict, elastic: ElasticBlock | None = None):
        I, n = P.interior, P.point.gap.size
        J_pp, J_ph, pos, dpc = jac["J_pp"], jac["J_ph"], jac["pos"], jac["dpc"]
        sI = dense_set(P, jac)
        if elastic is not None and np.isin(I[sI], elastic.S).all():
            sI = np.searchsorted(I, elastic.S)            # a set that covers this step's
        else:
            elastic = ElasticBlock.build(P, I[sI], dpc[I[sI]])
        S = I[sI]
        self.P, self.jac, self.sI, self.S, self.elastic = P, jac, sI, S, elastic
        E, self.ME = elastic.E, elastic.ME
        W = self.ME * pos[S]                              # M_S E_SS D_S
        self.JphS = J_ph[:, S].tocsr()
        a = P.area.ravel()
        self.v = self.elastic.M(a[S] * dpc[S], transpose=True)
        l = a[I] * pos[I]
        l[sI] += pos[S] * _mv(E.T, self.v)
        self.l = l
        self.delta = float(a @ dpc + self.v @ _mv(E, dpc[S]))
        self._factor(J_pp, W)
        c = J_ph @ np.ones(n) + self.JphS @ _mv(self.ME, dpc[S])
        self.y2 = self.solve_pressure(c)

    def _factor(self, J_pp, W):
        """The sparse LU of ``J_pp`` outside ``S`` (:func:`_grid_lu`) and the dense LU of
        the Schur complement on ``S``, which needs ``J_OO^-1`` only between the nodes beside
        ``S`` (solved in blocks of columns: no dense ``O x ring`` array)."""
        sI, P = self.sI, self.P
        O = np.setdiff1d(np.arange(J_pp.shape[0]), sI)
        self.O = O
        J = J_pp.tocsr()
        JO = J[O]
        self.lu = _grid_lu(JO[:, O], P.shape, P.interior[O])
        if sI.size == 0:
            return
        JOS, CsO, JS = JO[:, sI], self.JphS[O], J[sI]
        self.ring = np.flatnonzero(np.asarray(abs(JOS).sum(axis=1)).ravel()
                                   + np.asarray(abs(CsO).sum(axis=1)).ravel())
        self.B_ring = JOS[self.ring].toarray() + CsO[self.ring] @ W
        C = JS[:, O].tocsc()
        self.C = C.tocsr()
        cols = np.flatnonzero(np.diff(C.indptr))          # the nodes of O that C reads
        inverse = self._inverse_block(cols, self.ring)    # J_OO^-1 [cols, ring]
        D = JS[:, sI].toarray() + self.JphS[sI] @ W
        self.schur = la.lu_factor((D - (C[:, cols] @ inverse) @ self.B_ring)
                                  .astype(np.float32), overwrite_a=True, check_finite=False)

    def _inverse_block(self, rows, cols):
        """``J_OO^-1[rows, cols]``, from solves of at most ``SOLVE_BLOCK`` entries at once."""
        n = self.O.size
        step = max(1, SOLVE_BLOCK // max(n, 1))
        out = np.empty((rows.size, cols.size))
        for k in range(0, cols.size, step):
            unit = np.zeros((n, min(step, cols.size - k)))
            unit[cols[k:k + step], np.arange(unit.shape[1])] = 1.0
            out[:, k:k + step] = self.lu.solve(unit)[rows]
        return out

    def solve_pressure(self, r):
        """``(J_pp + J_ph[:, S] W)^-1 r`` by the block elimination (two sparse solves)."""
        x = np.empty_like(r)
        yO = self.lu.solve(r[self.O])
        if self.sI.size == 0:
            x[self.O] = yO
            return x
        xS = la.lu_solve(self.schur, (r[self.sI] - self.C @ yO).astype(np.float32))
        rO = r[self.O].copy()
        rO[self.ring] -= self.B_ring @ xS
        x[self.O] = self.lu.solve(rO)
        x[self.sI] = xS
        return x

    def __call__(self, r_R, r_G, r_L):
        S, sI = self.S, self.sI
        dpc = self.jac["dpc"]
        a = self.P.area.ravel()
        r_GO = r_G.copy()
        r_GO[S] = 0.0
        MrS = self.elastic.M(r_G[S])
        r_t = r_R - self.jac["J_ph"] @ r_GO - self.JphS @ MrS
        r_tL = r_L - float(np.sum(a * dpc * r_GO)) - float(self.v @ r_G[S])
        y1 = self.solve_pressure(r_t)
        dhd = (r_tL - self.l @ y1) / (self.delta - self.l @ self.y2)
        dphi = y1 - self.y2 * dhd
        dw = r_GO
        dw[S] = MrS + _mv(self.ME, self.jac["pos"][S] * dphi[sI] + dpc[S] * dhd)
        return dphi, dw, dhd


def _mv(matrix, vector):
    """``matrix @ vector`` in the matrix's precision (no upcast copy of a single-precision
    block), returned in double."""
    return (matrix @ vector.astype(matrix.dtype)).astype(float)


def _grid_lu(A, shape, nodes):
    """SuperLU of the sparse ``A`` whose unknowns are the grid ``shape``'s flat ``nodes``,
    eliminated in the grid's nested-dissection order
    (:func:`~fem_twin.numerics.ordering.subgrid_order`) with diagonal pivots preferred (faster and
    leaner than SuperLU's own COLAMD order); ``solve(rhs)`` in ``A``'s numbering.  PARDISO's LU as
    :class:`~fem_twin.numerics.linalg.SPDSolver` runs it (no matching, no scaling) misses these
    matrices by O(1): not used."""
    position = np.full(int(np.prod(shape)), -1)
    position[nodes] = np.arange(nodes.size)
    order = subgrid_order(shape, position)
    try:
        lu = spla.splu(A[order][:, order].tocsc(), permc_spec="NATURAL",
                       diag_pivot_thresh=0.1, options={"SymmetricMode": True})
    except RuntimeError as err:                   # SuperLU: "Factor is exactly singular"
        raise SolverError(f"the Newton matrix of the pressures is singular: {err}") from err
    return _Permuted(lu, order)


class _Permuted:
    """``solve(rhs)`` of a factorisation of ``A[order][:, order]``, in ``A``'s numbering."""

    def __init__(self, lu, order):
        self.lu, self.order = lu, order

    def solve(self, rhs):
        x = np.empty_like(rhs, dtype=float)
        x[self.order] = self.lu.solve(rhs[self.order])
        return x


def dense_set(P: Problem, jac: dict) -> np.ndarray:
    """Interior positions where the elastic coupling of a node's own deformation outweighs
    ``DENSE_THRESHOLD`` of its pressure coupling (or of its contact stiffness), grown by two
    nodes; at most ``MAX_DENSE``, the strongest first."""
    from scipy.ndimage import maximum_filter
    e0 = float(P.kernel()[0, 0])
    I = P.interior
    diag = np.abs(jac["J_pp"].diagonal())
    row = np.asarray(abs(jac["J_ph"]).sum(axis=1)).ravel()
    score = np.zeros(P.point.gap.size)
    e0 = e0 * np.sqrt(P.cells)           # a node's own compliance grows with its side
    score[I] = e0[I] * row / np.maximum(diag, 1e-300 + 1e-12 * diag.max())
    score = np.maximum(score, e0 * np.abs(jac["dpc"]))
    score = maximum_filter(score.reshape(P.shape), size=5, mode="constant").ravel()[I]
    chosen = np.flatnonzero(score > DENSE_THRESHOLD)
    if chosen.size > MAX_DENSE:
        chosen = np.sort(chosen[np.argsort(score[chosen])[-MAX_DENSE:]])
    return chosen


def apply_jacobian(P: Problem, jac: dict, dphi, dw, dhd):
    """The exact Jacobian action (``E`` by FFT) on an update ``(dphi, dw, dhd)``."""
    dp = np.zeros(P.point.gap.size)
    dp[P.interior] = jac["pos"][P.interior] * dphi
    dh = dw + dhd
    dpt = dp + (jac["dpc"] * dh if jac["Dpc"] is None else jac["Dpc"] @ dh)
    return (jac["J_pp"] @ dphi + jac["J_ph"] @ dh,
            dw - P.elastic(dpt.reshape(P.shape)).ravel(), float(P.area.ravel() @ dpt))


def newton_step(P: Problem, ev: NewtonEvaluation, load: float, rtol: float, pre=None,
                elastic: ElasticBlock | None = None, jac: dict | None = None, residual=None):
    """The Newton update ``(dphi, dw, dhd)``, the GMRES iteration count and the
    preconditioner (built from this step's Jacobian, with the ``elastic`` block where its
    set is this step's, unless ``pre`` is given).  GMRES runs on the system scaled by the
    residuals' natural sizes (:func:`scales`) to ``rtol``.  ``jac`` (default: the
    Jacobian at ``ev``) and ``residual`` (default: ``ev``'s ``(R, G, L)``) are for a
    linear response (:mod:`.linearised`): the step that cancels another residual."""
    s = P.point.settings
    jac = jacobian(P, ev) if jac is None else jac
    pre = Preconditioner(P, jac, elastic) if pre is None else pre
    nI, n = P.interior.size, P.point.gap.size
    size, h_s, _ = scales(ev, s, load)
    row = np.r_[1 / size, np.full(n, 1 / h_s), 1 / load]                 # residual scales

    def split(v):
        return v[:nI], v[nI:nI + n], v[-1]

    def precondition(y):
        r = y / row
        dphi, dw, dhd = pre(*split(r))
        return np.r_[dphi, dw, dhd]

    def matvec(y):
        return _stack(apply_jacobian(P, jac, *split(precondition(y)))) * row

    b = -_stack((ev.R, ev.G.ravel(), ev.L) if residual is None else residual) * row
    op = spla.LinearOperator((b.size, b.size), matvec=matvec)
    count = [0]
    y, info = spla.gmres(op, b, rtol=rtol, atol=0.0, restart=60, maxiter=4,
                         callback=lambda _: count.__setitem__(0, count[0] + 1),
                         callback_type="pr_norm")
    return split(precondition(y)), count[0], pre


def _stack(parts):
    return np.concatenate([np.atleast_1d(np.asarray(v, float)).ravel() for v in parts])


def scales(ev: NewtonEvaluation, s, load: float) -> tuple:
    """Natural sizes of the residuals ``(R, G, L)``: each node's flux magnitude, the
    thinnest loaded film (at most h_ref) and the load."""
    loaded = ev.p > 0
    film = float(ev.h0[loaded].min()) if loaded.any() else s.h_ref
    return ev.size, min(s.h_ref, max(film, 10 * s.gap_floor)), load
