"""Monolithic Newton coupling of the macro problem, for elastically dominated contacts.

When the elastic deformation is much larger than the film (a ball: ~1.5 um over a 0.2 um
film) no fixed point on ``h_el`` converges; as the paper's EHL-FBNS, the elastic operator
goes into the Newton system.  Unknowns: ``phi`` (the p-theta switch, interior nodes), the
deformation ``w = h_el`` (all nodes) and ``h_d``; equations, fully implicit:
``R = K(g) p + B(q) (1 - theta) = 0`` (eqs 17-18, with ``h0 = h_d + h_g + w``, eq 19, Roelands
and Dowson-Higginson), ``G = w - E (p + p_cav + p_con(h0) - p_amb) = 0`` (eqs 20-22, ``E``
the FFT half-space) and ``L = sum(a (p + p_cav + p_con - p_amb)) - F_N,imp = 0`` (eq 28).
The Jacobian is exact and each step is solved by preconditioned GMRES (:mod:`.jacobian`);
steps are limited so no film thins by more than half, then backtracked on the scaled
residual."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...errors import MixedNotConverged, SolverError
from ..film.cavitation import cavitation_model
from ..film.couette import couette, couette_matrix
from .evaluation import NewtonEvaluation
from .jacobian import newton_step, scales
from .problem import Problem

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


@dataclass(frozen=True, eq=False)
class State:
    phi: np.ndarray            # (n,) p-theta switch, boundary nodes at p_amb - p_cav [Pa]
    w: np.ndarray              # (ny, nx) elastic deformation h_el [m]
    h_d: float                 # rigid-body separation [m]


def evaluate(P: Problem, x: State, load: float) -> NewtonEvaluation:
    """Residuals ``R, G, L`` and every field the Jacobian and the result need."""
    s = P.point.settings
    shape = P.shape
    p, theta = (v.reshape(shape) for v in
                cavitation_model(s.complementarity).split(x.phi, s.p_ref))
    h_raw = x.h_d + P.point.gap + x.w
    h0 = np.maximum(h_raw, s.gap_floor)
    loc, mu, rho, g, q = P.coefficients(p, h0)
    K = P.poiseuille(g, loc.A)
    q1, q2 = (q * loc.b[..., 0]).ravel(), (q * loc.b[..., 1]).ravel()
    C = couette(q1.reshape(shape), q2.reshape(shape), P.point.spacing, s.couette)
    B = C.matrix()
    flux = K @ p.ravel() + B @ (1 - theta.ravel())
    size = abs(K) @ p.ravel() + C.size()
    p_tot = p + s.cavitation_pressure + loc.p_con - s.ambient_pressure
    F = float(np.sum(P.area * p_tot))
    return NewtonEvaluation(
        p=p, theta=theta, h0=h0, loc=loc, mu=mu, rho=rho, p_con=loc.p_con, F=F,
        F_hd=float(np.sum(P.area * (p + s.cavitation_pressure - s.ambient_pressure))),
        phi=x.phi, touching=h_raw <= s.gap_floor, g=g, q=q, K=K, B=B, couette=C,
        R=flux[P.interior], size=size[P.interior] + 1e-300, G=x.w - P.elastic(p_tot),
        L=F - load)


@dataclass(frozen=True)
class Merit:
    """The merit function of one Newton step at ``load`` [N]: the scaled residual norm
    (:func:`merit`) with the residuals' ``sizes`` held fixed over its line search."""

    load: float
    sizes: tuple

    def __call__(self, ev: NewtonEvaluation) -> float:
        return merit(ev, self.sizes)


def merit(ev: NewtonEvaluation, sizes: tuple) -> float:
    """Scaled residual norm: root of the summed mean squares of ``R``, ``G`` and ``L``, each
    divided by its size from :func:`scales` (held fixed over a line search); inf for a
    trial step that overflows, which the line search then rejects."""
    with np.errstate(over="ignore"):
        return float(np.sqrt(np.mean((ev.R / sizes[0]) ** 2)
                             + np.mean((ev.G / sizes[1]) ** 2)
                             + np.square(np.float64(ev.L) / sizes[2])))


def solve(P: Problem, x: State, load: float, *, tol: float, max_iter: int, progress=None):
    """Newton iterations from ``x`` to ``tol``; returns ``(x, ev, iterations, history)``.

    Each step is globalised by :func:`line_search`.  Converged when a full step changes
    ``h_el`` by less than ``tol h_ref``, ``p`` and ``p_con`` by less than ``tol p_ref``, the
    load error is below ``tol`` and the merit function below ``tol``;
    :class:`MixedNotConverged` otherwise, or after ``WATCHDOG`` steps in a row that did not
    decrease the merit function.
    """
    s = P.point.settings
    ev = evaluate(P, x, load)
    history, pre, elastic, uphill, short = [], None, None, 0, 0
    for it in range(1, max_iter + 1):
        measure = Merit(load, scales(ev, s, load))
        f = measure(ev)
        try:
            step, gm, pre = newton_step(P, ev, load, pre=pre, elastic=elastic,
                                        rtol=min(1e-3, max(1e-8, 0.1 * f)))
            if gm > REBUILD_AFTER:
                pre, elastic = None, pre.elastic
            trial, ev_t, f_t, alpha, downhill = line_search(P, x, ev, step, measure)
            short = short + 1 if alpha < SHORT_STEP else 0
            if not downhill or short >= STALL:
                # no decrease, or steps so short that the iteration stalls at a kink
                trial, ev_t, f_t, alpha = clamped_step(P, x, step[0], measure)
                downhill, short = f_t < f, 0
        except (SolverError, ValueError) as err:      # a singular matrix, NaN in a step
            raise MixedNotConverged(f"Newton coupling, iteration {it}: {err}", history) from err
        uphill = 0 if downhill else uphill + 1
        if uphill > WATCHDOG or not np.isfinite(f_t):
            raise MixedNotConverged(f"Newton coupling: the residual did not decrease in "
                                    f"{uphill} steps up to iteration {it}", history)
        changes = (float(np.abs(trial.w - x.w).max() / s.h_ref),
                   float(np.abs(ev_t.p_con - ev.p_con).max() / s.p_ref),
                   float(np.abs(ev_t.p - ev.p).max() / s.p_ref), ev_t.L / load)
        history.append((it, *changes, trial.h_d, gm))
        x, ev = trial, ev_t
        if progress is not None:
            progress(it, f_t)
        if alpha == 1.0 and max(max(map(abs, changes)), f_t) < tol:
            return x, ev, it, history
    raise MixedNotConverged(f"Newton coupling did not reach {tol} in {max_iter} iterations "
                            f"(merit {f_t:.2e})", history)


def clamped_step(P: Problem, x: State, dphi, measure: Merit):
    """The Newton step with the nodes that the step ``dphi`` moves across the p-theta kink
    held on it (``p = theta = 0``, their own mass balance dropped for this step): where a
    degenerate node of the solution sits on the kink, the plain step overshoots it back
    and forth between the two branches.  Returns ``(state, ev, merit, 1.0)``."""
    I, load = P.interior, measure.load
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
    return trial, ev_t, measure(ev_t), 1.0


def line_search(P: Problem, x: State, ev: NewtonEvaluation, step, measure: Merit):
    """The accepted trial ``(state, ev, merit, alpha, decreased)`` along a Newton ``step``
    from ``x`` (evaluated as ``ev``), by the ``measure`` of the step's merit function.

    The step is first shortened so that no film thins by more than half.  If the merit
    function does not decrease, the nodes that would cross the p-theta kink stop on it
    (their Jacobian changes there) and the step is halved until it does (Armijo, at most
    ``HALVINGS`` times).  Without a decrease (``decreased`` False: the projected full step
    is returned), or after ``STALL`` steps shorter than ``SHORT_STEP``, :func:`solve` takes
    a :func:`clamped_step` instead (its watchdog limits the steps that do not decrease the
    merit function).
    """
    dphi, dw, dhd = step
    I, load, f = P.interior, measure.load, measure(ev)
    dh = (dw + dhd).reshape(P.shape)
    thinning = (dh < 0) & ~ev.touching
    alpha = min(1.0, float(np.min(0.5 * ev.h0[thinning] / -dh[thinning], initial=np.inf)))
    fallback = None
    for trial_no in range(2 + HALVINGS):
        phi = x.phi.copy()
        phi[I] += alpha * dphi
        trial = State(phi, x.w + alpha * dw.reshape(P.shape), x.h_d + alpha * dhd)
        ev_t = evaluate(P, trial, load)
        f_t = measure(ev_t)
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


def state_from(result, P: Problem) -> State:
    """The Newton state of a converged :class:`MixedResult` (a warm start), its Dirichlet
    nodes at ambient pressure."""
    s = P.point.settings
    phi = cavitation_model(s.complementarity).unknown(
        (result.pressure - s.cavitation_pressure).ravel(), result.cavity_fraction.ravel(),
        s.p_ref)
    phi[P.boundary.ravel()] = s.ambient_pressure - s.cavitation_pressure
    return State(phi, np.asarray(result.elastic_deformation, float).copy(), float(result.h_d))


def rigid_start(P: Problem, load: float, ratio: float):
    """The cold start: the rigid (``w = 0``), isoviscous film at the largest separation
    (halving ``h_d - h_touch`` from the first-contact separation) whose load reaches
    ``load`` or whose elastic deformation reaches ``ratio`` of its thinnest loaded film.
    Returns the state and the load it carries (at most ``load``)."""
    s = P.point.settings
    model = cavitation_model(s.complementarity)
    touch = s.gap_floor - float(P.point.gap.min())
    t = float(P.factors.h0[-1]) - float(P.point.gap.min()) - touch
    for _ in range(80):
        h_d = touch + t
        loc, _, _, g, q = P.coefficients(np.zeros(P.shape), np.maximum(h_d + P.point.gap,
                                                                         s.gap_floor))
        B = couette_matrix(q * loc.b[..., 0], q * loc.b[..., 1], P.point.spacing, s.couette)
        phi, _, _ = model.solve(P.poiseuille(g, loc.A), B, P.boundary,
                                s.ambient_pressure - s.cavitation_pressure, s.p_ref)
        x = State(phi, np.zeros(P.shape), h_d)
        ev = evaluate(P, x, load)
        loaded = ev.p > 0
        if ev.F >= load or (loaded.any() and np.abs(ev.G).max()
                               >= ratio * float(ev.h0[loaded].min())):
            break
        t /= 2
    return x, min(ev.F, load)


def continuation(P: Problem, load: float, *, tol: float, max_iter: int, progress=None,
                 ratio: float = 0.3):
    """Cold start by load continuation: the rigid film of :func:`rigid_start`, then Newton
    solves at loads growing by a factor (x4, its logarithm halved after a failure and
    doubled after a success) up to ``load``.  Returns what :func:`solve` returns, with the
    iterations of every stage."""
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
                raise MixedNotConverged(
                    f"the Newton coupling did not converge at {target:.3g} N within max_iter "
                    f"= {max_iter} iterations (the load continuation had carried {F:.3g} N "
                    f"of {load:.3g} N; {err}); raise [macro] max_iter", history) from err
            target = min(load, F * factor)
            continue
        total += its
        history += hist
        F = target
        if last:
            return x, ev, total, history
        factor = min(factor ** 2, 100.0)
        target = min(load, F * factor)
