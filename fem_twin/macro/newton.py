"""Monolithic Newton coupling of the macro problem, for elastically dominated contacts.

When the elastic deformation is much larger than the film (a ball on a disk: ~1.5 um of
deformation over a 0.2 um film) no fixed point on ``h_el`` converges; the paper's EHL-FBNS
puts the elastic operator into its Newton system, and so does this module.  The unknowns
are ``phi`` (the p-theta switch of :mod:`.reynolds`, interior nodes), the elastic
deformation ``w = h_el`` (all nodes) and ``h_d``; the equations, all fully implicit:

* ``R = K(g) p + B(q) (1 - theta) = 0`` on the interior (eqs 17-18), with
  ``g = rho h_m^3 / (12 mu)`` and ``q = rho h_m u_m`` at ``p`` and
  ``h0 = h_d + h_g + w`` (eq 19), Roelands (23) and Dowson-Higginson (24);
* ``G = w - E (p + p_cav + p_con(h0) - p_amb) = 0`` (eqs 20-22, ``E`` the FFT half-space);
* ``L = sum(a (p + p_cav + p_con - p_amb)) - F_N,imp = 0`` (eq 28).

The Jacobian is exact (the ``h0``-derivatives of the flow factors by central differences of
their interpolation, the Poiseuille operator's coefficient derivatives by probing it with
nine colourings of the grid).  Each Newton step is solved by
right-preconditioned GMRES with the exact Jacobian action (``E`` by FFT); the preconditioner
is the Jacobian with the elastic coupling kept, as a dense block, on the set ``S`` of nodes
where it outweighs the pressure flow (the loaded zone of the contact), and dropped
elsewhere; ``S`` is eliminated by a Schur complement on a sparse LU of the rest.  Steps are
limited so no film thins by more than half, then backtracked on the scaled residual.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import MixedNotConverged
from .couette import couette, couette_matrix
from .problem import MAX_COEFFICIENT_PRESSURE, Problem

#: a node joins the dense elastic block when its elastic coupling exceeds this fraction of
#: its pressure-flow coupling
DENSE_THRESHOLD = 0.02
#: halvings of a Newton step in its line search
HALVINGS = 30
#: ``STALL`` line-search steps in a row shorter than ``SHORT_STEP`` (a stall at a kink)
#: are followed by a clamped step
SHORT_STEP = 2.0 ** -6
STALL = 3
#: Newton steps in a row that may fail to decrease the merit function
WATCHDOG = 8
#: the preconditioner is kept from step to step until GMRES needs more iterations than this
REBUILD_AFTER = 6
#: most nodes in the dense block (a 4000^2 LU takes about 2 s here)
MAX_DENSE = 4000


@dataclass(frozen=True, eq=False)
class State:
    phi: np.ndarray            # (n,) p-theta switch, boundary nodes at p_amb - p_cav [Pa]
    w: np.ndarray              # (ny, nx) elastic deformation h_el [m]
    h_d: float                 # rigid-body separation [m]


def evaluate(P: Problem, x: State, load: float) -> dict:
    """Residuals ``R, G, L`` and every field the Jacobian and the result need."""
    s = P.settings
    shape = P.shape
    p = np.maximum(x.phi, 0).reshape(shape)
    theta = (np.maximum(-x.phi, 0) / s.p_ref).reshape(shape)
    h_raw = x.h_d + P.gap + x.w
    h0 = np.maximum(h_raw, s.gap_floor)
    loc, mu, rho, g, q = P.coefficients(p, h0)
    K = P.poiseuille(g, loc.A)
    q1, q2 = (q * loc.b[..., 0]).ravel(), (q * loc.b[..., 1]).ravel()
    C = couette(q1.reshape(shape), q2.reshape(shape), P.spacing, s.couette)
    B = C.matrix()
    flux = K @ p.ravel() + B @ (1 - theta.ravel())
    size = abs(K) @ p.ravel() + C.size()
    p_tot = p + s.cavitation_pressure + loc.p_con - s.ambient_pressure
    F = float(np.sum(P.area * p_tot))
    return dict(p=p, theta=theta, h0=h0, touching=h_raw <= s.gap_floor, loc=loc, mu=mu,
                rho=rho, g=g, q=q, K=K, B=B, couette=C, p_con=loc.p_con,
                R=flux[P.interior], size=size[P.interior] + 1e-300,
                G=x.w - P.elastic(p_tot), F=F,
                F_hd=float(np.sum(P.area * (p + s.cavitation_pressure - s.ambient_pressure))),
                L=F - load)


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


def jacobian(P: Problem, ev: dict) -> dict:
    """The sparse blocks of the Jacobian: ``J_pp = dR/dphi`` (interior x interior),
    ``J_ph = dR/dh0`` (interior x all, through h_m, A and b), ``pos`` (dp/dphi) and
    ``dpc = dp_con/dh0``."""
    lub, I = P.lubricant, P.interior
    pos = ev["p"].ravel() > 0
    p_coef = np.minimum(ev["p"], MAX_COEFFICIENT_PRESSURE)
    unclipped = ev["p"] < MAX_COEFFICIENT_PRESSURE
    dlnrho = lub.density_log_slope(p_coef) * unclipped
    dlnmu = lub.viscosity_log_slope(p_coef) * unclipped
    d = P.factors.slopes(ev["h0"])
    free = ~ev["touching"]
    g, q, loc, p = ev["g"], ev["q"], ev["loc"], ev["p"].ravel()
    Kg = _probe(P, lambda c: (c, loc.A), p)
    KA = _probe(P, lambda c: (g, c[..., None, None] * d["A"] * free[..., None, None]), p)
    Q1, Q2 = ev["couette"].q_derivatives(1 - ev["theta"].ravel())
    b1, b2 = loc.b[..., 0].ravel(), loc.b[..., 1].ravel()
    Bq = Q1 @ sp.diags(b1) + Q2 @ sp.diags(b2)
    Bb = (Q1 @ sp.diags(q.ravel() * d["b"][..., 0].ravel())
          + Q2 @ sp.diags(q.ravel() * d["b"][..., 1].ravel()))
    dg_dp, dq_dp = (g * (dlnrho - dlnmu)).ravel(), (q * dlnrho).ravel()
    dhm = d["h_m"] * free
    dg_dh, dq_dh = (3 * g * dhm / loc.h_m).ravel(), (q * dhm / loc.h_m).ravel()
    dtheta = np.where(pos, 0.0, 1.0 / P.settings.p_ref)
    J_p = (ev["K"] @ sp.diags(pos * 1.0) + ev["B"] @ sp.diags(dtheta)
           + (Kg @ sp.diags(dg_dp) + Bq @ sp.diags(dq_dp)) @ sp.diags(pos * 1.0))
    J_h = Kg @ sp.diags(dg_dh) + Bq @ sp.diags(dq_dh) + KA + Bb @ sp.diags(free.ravel() * 1.0)
    J_p, J_h = J_p.tocsr()[I], J_h.tocsr()[I]
    return dict(J_pp=J_p[:, I].tocsc(), J_ph=J_h.tocsr(), pos=pos,
                dpc=(d["p_con"] * free).ravel())


class Preconditioner:
    """Approximate inverse of the Newton matrix: the Jacobian with ``E`` kept on ``S x S``.

    Outside ``S`` the deformation update is the elastic residual alone; on ``S`` it is
    eliminated exactly (``dw_S = M_S (r_G + E_SS (D dphi + p_con' dh))``,
    ``M_S = (I - E_SS p_con')^-1``), which leaves the pressure system ``J_pp + J_ph[:, S] W``
    bordered by the load row; that is solved with a sparse LU outside ``S`` and a dense LU of
    the Schur complement on ``S``.
    """

    def __init__(self, P: Problem, jac: dict):
        I, n = P.interior, P.gap.size
        J_pp, J_ph, pos, dpc = jac["J_pp"], jac["J_ph"], jac["pos"], jac["dpc"]
        sI = dense_set(P, jac)
        S = I[sI]
        self.P, self.jac, self.sI, self.S = P, jac, sI, S
        E = P.dense_elastic(S)
        if np.any(dpc[S]):                                # contact stiffness on S
            self.M = la.inv(np.eye(S.size) - E * dpc[S])
            self.ME = self.M @ E                          # M_S E_SS
        else:
            self.M, self.ME = None, E
        W = self.ME * pos[S]                              # M_S E_SS D_S
        self.JphS = J_ph[:, S].tocsr()
        a = P.area.ravel()
        self.v = self._M(a[S] * dpc[S], transpose=True)
        l = a[I] * pos[I]
        l[sI] += pos[S] * (E.T @ self.v)
        self.l = l
        self.delta = float(a @ dpc + self.v @ (E @ dpc[S]))
        self._factor(J_pp, W)
        c = J_ph @ np.ones(n) + self.JphS @ (self.ME @ dpc[S])
        self.y2 = self.solve_pressure(c)

    def _factor(self, J_pp, W):
        nI = J_pp.shape[0]
        sI = self.sI
        O = np.setdiff1d(np.arange(nI), sI)
        self.O = O
        J = J_pp.tocsr()
        self.lu = spla.splu(J[O][:, O].tocsc())
        if sI.size == 0:
            return
        JOS = J[O][:, sI]
        CsO = self.JphS[O]
        ring = np.flatnonzero(np.asarray(abs(JOS).sum(axis=1)).ravel()
                              + np.asarray(abs(CsO).sum(axis=1)).ravel())
        self.B_ring = JOS[ring].toarray() + CsO[ring] @ W
        unit = np.zeros((O.size, ring.size))
        unit[ring, np.arange(ring.size)] = 1.0
        self.Z = self.lu.solve(unit)
        self.C = J[sI][:, O].tocsr()
        D = J[sI][:, sI].toarray() + self.JphS[sI] @ W
        self.schur = la.lu_factor(D - (self.C @ self.Z) @ self.B_ring)

    def _M(self, r, transpose=False):
        if self.M is None:
            return r
        return (self.M.T if transpose else self.M) @ r

    def solve_pressure(self, r):
        """``(J_pp + J_ph[:, S] W)^-1 r`` by the block elimination."""
        x = np.empty_like(r)
        yO = self.lu.solve(r[self.O])
        if self.sI.size == 0:
            x[self.O] = yO
            return x
        xS = la.lu_solve(self.schur, r[self.sI] - self.C @ yO)
        x[self.O] = yO - self.Z @ (self.B_ring @ xS)
        x[self.sI] = xS
        return x

    def __call__(self, r_R, r_G, r_L):
        S, sI = self.S, self.sI
        dpc = self.jac["dpc"]
        a = self.P.area.ravel()
        r_GO = r_G.copy()
        r_GO[S] = 0.0
        MrS = self._M(r_G[S])
        r_t = r_R - self.jac["J_ph"] @ r_GO - self.JphS @ MrS
        r_tL = r_L - float(np.sum(a * dpc * r_GO)) - float(self.v @ r_G[S])
        y1 = self.solve_pressure(r_t)
        dhd = (r_tL - self.l @ y1) / (self.delta - self.l @ self.y2)
        dphi = y1 - self.y2 * dhd
        dw = r_GO
        dw[S] = MrS + self.ME @ (self.jac["pos"][S] * dphi[sI] + dpc[S] * dhd)
        return dphi, dw, dhd


def dense_set(P: Problem, jac: dict) -> np.ndarray:
    """Interior positions where the elastic coupling of a node's own deformation outweighs
    ``DENSE_THRESHOLD`` of its pressure coupling (or of its contact stiffness), grown by two
    nodes; at most ``MAX_DENSE``, the strongest first."""
    from scipy.ndimage import maximum_filter
    e0 = float(P.kernel()[0, 0])
    I = P.interior
    diag = np.abs(jac["J_pp"].diagonal())
    row = np.asarray(abs(jac["J_ph"]).sum(axis=1)).ravel()
    score = np.zeros(P.gap.size)
    score[I] = e0 * row / np.maximum(diag, 1e-300 + 1e-12 * diag.max())
    score = np.maximum(score, e0 * np.abs(jac["dpc"]))
    score = maximum_filter(score.reshape(P.shape), size=5, mode="constant").ravel()[I]
    chosen = np.flatnonzero(score > DENSE_THRESHOLD)
    if chosen.size > MAX_DENSE:
        chosen = np.sort(chosen[np.argsort(score[chosen])[-MAX_DENSE:]])
    return chosen


def apply_jacobian(P: Problem, jac: dict, dphi, dw, dhd):
    """The exact Jacobian action (``E`` by FFT) on an update ``(dphi, dw, dhd)``."""
    dp = np.zeros(P.gap.size)
    dp[P.interior] = jac["pos"][P.interior] * dphi
    dh = dw + dhd
    dpt = dp + jac["dpc"] * dh
    return (jac["J_pp"] @ dphi + jac["J_ph"] @ dh,
            dw - P.elastic(dpt.reshape(P.shape)).ravel(), float(P.area.ravel() @ dpt))


def newton_step(P: Problem, ev: dict, load: float, rtol: float, pre=None):
    """The Newton update ``(dphi, dw, dhd)``, the GMRES iteration count and the
    preconditioner (built from this step's Jacobian unless ``pre`` is given).  GMRES runs on
    the system scaled by the residuals' natural sizes (:func:`scales`) to ``rtol``."""
    s = P.settings
    jac = jacobian(P, ev)
    pre = Preconditioner(P, jac) if pre is None else pre
    nI, n = P.interior.size, P.gap.size
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

    b = -_stack((ev["R"], ev["G"].ravel(), ev["L"])) * row
    op = spla.LinearOperator((b.size, b.size), matvec=matvec)
    count = [0]
    y, info = spla.gmres(op, b, rtol=rtol, atol=0.0, restart=60, maxiter=4,
                         callback=lambda _: count.__setitem__(0, count[0] + 1),
                         callback_type="pr_norm")
    return split(precondition(y)), count[0], pre


def _stack(parts):
    return np.concatenate([np.atleast_1d(np.asarray(v, float)).ravel() for v in parts])


def scales(ev: dict, s, load: float) -> tuple:
    """Natural sizes of the residuals ``(R, G, L)``: each node's flux magnitude, the
    thinnest loaded film (at most h_ref) and the load."""
    loaded = ev["p"] > 0
    film = float(ev["h0"][loaded].min()) if loaded.any() else s.h_ref
    return ev["size"], min(s.h_ref, max(film, 10 * s.gap_floor)), load


def merit(ev: dict, sizes: tuple) -> float:
    """Scaled residual norm: root of the summed mean squares of ``R``, ``G`` and ``L``, each
    divided by its size from :func:`scales` (held fixed over a line search)."""
    return float(np.sqrt(np.mean((ev["R"] / sizes[0]) ** 2)
                         + np.mean((ev["G"] / sizes[1]) ** 2) + (ev["L"] / sizes[2]) ** 2))


def solve(P: Problem, x: State, load: float, *, tol: float, max_iter: int, progress=None):
    """Newton iterations from ``x`` to ``tol``; returns ``(x, ev, iterations, history)``.

    Each step is globalised by :func:`line_search`.  Converged when a full step changes
    ``h_el`` by less than ``tol h_ref``, ``p`` and ``p_con`` by less than ``tol p_ref``, the
    load error is below ``tol`` and the merit function below ``tol``;
    :class:`MixedNotConverged` otherwise, or after ``WATCHDOG`` steps in a row that did not
    decrease the merit function.
    """
    s = P.settings
    ev = evaluate(P, x, load)
    history, pre, uphill, short = [], None, 0, 0
    for it in range(1, max_iter + 1):
        sizes = scales(ev, s, load)
        f = merit(ev, sizes)
        step, gm, pre = newton_step(P, ev, load, pre=pre, rtol=min(1e-3, max(1e-8, 0.1 * f)))
        if gm > REBUILD_AFTER:
            pre = None
        trial, ev_t, f_t, alpha, downhill = line_search(P, x, ev, step, load, sizes, f)
        short = short + 1 if alpha < SHORT_STEP else 0
        if not downhill or short >= STALL:
            # no decrease, or steps so short that the iteration stalls at a kink
            trial, ev_t, f_t, alpha = clamped_step(P, x, step[0], load, sizes)
            downhill, short = f_t < f, 0
        uphill = 0 if downhill else uphill + 1
        if uphill > WATCHDOG or not np.isfinite(f_t):
            raise MixedNotConverged(f"Newton coupling: the residual did not decrease in "
                                    f"{uphill} steps up to iteration {it}", history)
        changes = (float(np.abs(trial.w - x.w).max() / s.h_ref),
                   float(np.abs(ev_t["p_con"] - ev["p_con"]).max() / s.p_ref),
                   float(np.abs(ev_t["p"] - ev["p"]).max() / s.p_ref), ev_t["L"] / load)
        history.append((it, *changes, trial.h_d, gm))
        x, ev = trial, ev_t
        if progress is not None:
            progress(it, f_t)
        if alpha == 1.0 and max(max(map(abs, changes)), f_t) < tol:
            return x, ev, it, history
    raise MixedNotConverged(f"Newton coupling did not reach {tol} in {max_iter} iterations "
                            f"(merit {f_t:.2e})", history)


def clamped_step(P: Problem, x: State, dphi, load: float, sizes):
    """The Newton step with the nodes that the step ``dphi`` moves across the p-theta kink
    held on it (``p = theta = 0``, their own mass balance dropped for this step): where a
    degenerate node of the solution sits on the kink, the plain step overshoots it back
    and forth between the two branches.  Returns ``(state, ev, merit, 1.0)``."""
    I = P.interior
    crossing = (x.phi[I] + dphi) * x.phi[I] < 0
    clamped = replace(P, interior=I[~crossing])
    phi = x.phi.copy()
    phi[I[crossing]] = 0.0
    held = State(phi, x.w, x.h_d)
    ev_c = evaluate(clamped, held, load)
    (dphi_c, dw, dhd), _, _ = newton_step(clamped, ev_c, load, rtol=1e-6)
    phi = held.phi.copy()
    phi[clamped.interior] += dphi_c
    trial = State(phi, held.w + dw.reshape(P.shape), held.h_d + dhd)
    ev_t = evaluate(P, trial, load)
    return trial, ev_t, merit(ev_t, sizes), 1.0


def line_search(P: Problem, x: State, ev: dict, step, load: float, sizes, f: float):
    """The accepted trial ``(state, ev, merit, alpha, decreased)`` along a Newton step.

    The step is first shortened so that no film thins by more than half.  If the merit
    function does not decrease, the nodes that would cross the p-theta kink stop on it
    (their Jacobian changes there) and the step is halved until it does (Armijo, at most
    ``HALVINGS`` times).  Without a decrease (``decreased`` False: the projected full step
    is returned), or after ``STALL`` steps shorter than ``SHORT_STEP``, :func:`solve` takes
    a :func:`clamped_step` instead (its watchdog limits the steps that do not decrease the
    merit function).
    """
    dphi, dw, dhd = step
    I = P.interior
    dh = (dw + dhd).reshape(P.shape)
    thinning = (dh < 0) & ~ev["touching"]
    alpha = min(1.0, float(np.min(0.5 * ev["h0"][thinning] / -dh[thinning], initial=np.inf)))
    fallback = None
    for trial_no in range(2 + HALVINGS):
        phi = x.phi.copy()
        phi[I] += alpha * dphi
        trial = State(phi, x.w + alpha * dw.reshape(P.shape), x.h_d + alpha * dhd)
        ev_t = evaluate(P, trial, load)
        f_t = merit(ev_t, sizes)
        if np.isfinite(f_t) and f_t <= (1 - 1e-4 * alpha) * f:
            return trial, ev_t, f_t, alpha, True
        if trial_no == 0:
            crossing = (x.phi[I] + alpha * dphi) * x.phi[I] < 0
            dphi = np.where(crossing, -x.phi[I] / alpha, dphi)
            continue
        if fallback is None:
            fallback = (trial, ev_t, f_t, alpha, False)
        alpha /= 2
    return fallback


def state_from(result, settings) -> State:
    """The Newton state of a converged :class:`MixedResult` (a warm start)."""
    p = (result.pressure - settings.cavitation_pressure).ravel()
    theta = result.cavity_fraction.ravel()
    phi = np.where(theta > 0, -theta * settings.p_ref, np.maximum(p, 0))
    return State(phi, np.asarray(result.elastic_deformation, float).copy(), float(result.h_d))


def rigid_start(P: Problem, load: float, ratio: float):
    """The cold start: the rigid (``w = 0``), isoviscous film at the largest separation
    (halving ``h_d - h_touch`` from the first-contact separation) whose load reaches
    ``load`` or whose elastic deformation reaches ``ratio`` of its thinnest loaded film.
    Returns the state and the load it carries (at most ``load``)."""
    from .reynolds import solve_complementarity
    s = P.settings
    touch = s.gap_floor - float(P.gap.min())
    t = float(P.factors.h0[-1]) - float(P.gap.min()) - touch
    for _ in range(80):
        h_d = touch + t
        loc, _, _, g, q = P.coefficients(np.zeros(P.shape), np.maximum(h_d + P.gap,
                                                                         s.gap_floor))
        B = couette_matrix(q * loc.b[..., 0], q * loc.b[..., 1], P.spacing, s.couette)
        phi, _, _ = solve_complementarity(P.poiseuille(g, loc.A), B, P.boundary,
                                          s.ambient_pressure - s.cavitation_pressure, s.p_ref)
        x = State(phi, np.zeros(P.shape), h_d)
        ev = evaluate(P, x, load)
        loaded = ev["p"] > 0
        if ev["F"] >= load or (loaded.any() and np.abs(ev["G"]).max()
                               >= ratio * float(ev["h0"][loaded].min())):
            break
        t /= 2
    return x, min(ev["F"], load)


def continuation(P: Problem, load: float, *, tol: float, max_iter: int, progress=None,
                 ratio: float = 0.3):
    """Cold start by load continuation: the rigid film of :func:`rigid_start`, then Newton
    solves at loads growing by a factor (x4, its logarithm halved after a failure and
    doubled after a success) up to ``load``.  Returns what :func:`solve` returns, with the iterations of every stage."""
    x, F = rigid_start(P, load, ratio)
    total, history, factor, target = 0, [], 4.0, F
    while True:
        last = target == load
        try:
            x, ev, its, hist = solve(P, x, target, tol=tol if last else max(tol, 1e-4),
                                     max_iter=max_iter, progress=progress)
        except MixedNotConverged as err:
            history += err.history
            factor = np.sqrt(factor)
            if factor < 1.02 or target == F:
                raise MixedNotConverged("load continuation of the Newton coupling stalled "
                                        f"at {F:.3g} N of {load:.3g} N", history) from err
            target = min(load, F * factor)
            continue
        total += its
        history += hist
        F = target
        if last:
            return x, ev, total, history
        factor = min(factor ** 2, 100.0)
        target = min(load, F * factor)
