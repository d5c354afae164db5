"""The linear response of a converged operating point's friction coefficient (eq 34) to a
change of its flow factors, for the error estimate's micro parts (:mod:`..estimate`).

At the converged state ``x`` of the point with its factors ``f``, the state with factors
``f + df`` is ``x + dx`` with ``J dx = -(R(x; f + df) - R(x; f))`` to first order in
``df``: ``R`` the residuals ``(R, G, L)`` of the monolithic coupling (:mod:`.newton`: film,
elastic deformation, load balance) and ``J`` its exact Jacobian at ``x`` with the point's own
factors, built and preconditioned once for every change.  The change of C_f is the friction
of ``x + dx`` with ``f + df`` minus that of ``x`` with ``f``; the converged state's own
residual (its coupling's tolerance) cancels in the difference.  Against the variants solved
to convergence: ``tests/test_linearised.py``, ``tests/test_estimate.py`` and, on the
bundled cases, docs/accuracy.md ("The micro parts are linear responses")."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...micro.rolling import at_slide_to_roll
from .jacobian import Preconditioner, jacobian, newton_step, scales
from .newton import State, evaluate, state_from
from .problem import macro_problem
from .result import Convergence, mixed_result, on_grid

#: GMRES's relative tolerance for a response: a part matters from 5e-4 of C_f, and its
#: change is at most a few per cent of C_f, so 1e-4 leaves it exact to far below that (the
#: parts of the ``estimate`` subsets move by at most 1e-6 C_f,b from 1e-6)
RESPONSE_RTOL = 1e-4
#: the most steps of a response: the Newton step, then chord steps with the same Jacobian
#: kept while the residual falls (in the boundary regime a second step can move away): on
#: the ``estimate-ball`` subset the parts lie within 0.045 % C_f,b of the converged
#: variants' changes after one step, within 0.007 % after two (docs/accuracy.md)
CHORD_STEPS = 2


def friction_responses(point, result, changed: dict) -> dict:
    """``{kind: C_f(changed[kind]) - C_f}`` [-] to first order in the change of the
    factors, at the converged ``result`` of the operating ``point``
    (:class:`~fem_twin.macro.point.OperatingPoint`); ``changed``: ``{kind: FlowFactors}``
    at the pin's SRR 2, as the point's own.  Raises
    :class:`~fem_twin.errors.SolverError` (or ValueError) where the Jacobian is singular."""
    P = macro_problem(point)
    load = point.load
    x = state_from(on_grid(result, point.gap.shape, point.spacing), P)
    ev = evaluate(P, x, load)
    jac = jacobian(P, ev)
    pre = Preconditioner(P, jac)
    own = _friction(P, ev, x)
    out = {}
    for kind, factors in changed.items():
        moved = replace(P, point=replace(point, factors=factors),
                        factors=at_slide_to_roll(factors, point.slide_to_roll))
        out[kind] = _chord(P, ev, x, moved, jac, pre) - own
    return out


def _chord(P, ev, x, moved, jac, pre) -> float:
    """C_f of the state of problem ``moved`` reached from ``x`` by chord steps with the
    Jacobian ``jac`` of ``P`` at ``x`` (evaluated as ``ev``): at most ``CHORD_STEPS``, each
    kept only while the scaled residual (``R(y; moved) - R(x; P)``) decreases."""
    load, sizes = P.point.load, scales(ev, P.point.settings, P.point.load)
    y, ev_y, best = x, evaluate(moved, x, load), np.inf
    for _ in range(CHORD_STEPS):
        residual = (ev_y.R - ev.R, (ev_y.G - ev.G).ravel(), ev_y.L - ev.L)
        (dphi, dw, dhd), _, _ = newton_step(P, ev, load, RESPONSE_RTOL, pre=pre, jac=jac,
                                              residual=residual)
        phi = y.phi.copy()
        phi[P.interior] += dphi
        trial = State(phi, y.w + dw.reshape(P.shape), y.h_d + dhd)
        ev_t = evaluate(moved, trial, load)
        left = _size(ev_t, ev, sizes)
        if left >= best:
            break
        y, ev_y, best = trial, ev_t, left
    return _friction(moved, ev_y, y)


def _size(ev_y, ev, sizes) -> float:
    """The scaled norm of the residual change from ``ev`` to ``ev_y`` (as :func:`.newton.merit`)."""
    return float(np.sqrt(np.mean(((ev_y.R - ev.R) / sizes[0]) ** 2)
                         + np.mean(((ev_y.G - ev.G) / sizes[1]) ** 2)
                         + ((ev_y.L - ev.L) / sizes[2]) ** 2))


def _friction(P, ev, x) -> float:
    """C_f of the state ``x`` of problem ``P`` evaluated as ``ev``."""
    return mixed_result(P, ev, x.w, x.h_d, Convergence(0, [], 0.0)).friction_coefficient
