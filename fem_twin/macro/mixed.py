"""Homogenised mixed elasto-hydrodynamic operating point (paper 2.2.2, eqs 17-34).

One operating point (imposed load F_N,imp, sliding speed U): homogenised Reynolds with JFO
cavitation (eqs 17-18) with the flow factors at the local separation ``h0``
(:meth:`FlowFactors.at`), Roelands viscosity (eq 23) and Dowson-Higginson density (eq 24);
``h0 = h_d + h_g + h_el`` (eq 19) with ``h_el`` from ``p_hd + p_con - p_amb`` by the FFT
half-space (eqs 20-22); the contact pressure ``p_con(h0)`` (eqs 25-27), the load balance on
``h_d`` (eqs 28-30) and the friction (eqs 31-34).

Three couplings reach the same state: ``"anderson"`` and the paper's ``"pid"``, partitioned
(:mod:`.partitioned`) and the monolithic ``"newton"`` (:mod:`.newton`); ``"auto"`` (default)
takes Anderson and switches to Newton for elastically dominated contacts or when Anderson
fails.  Converged when the changes of ``h_el`` / h_ref, ``p_con`` / p_ref and ``p`` / p_ref
between two iterations and the load residual (eq 30) are all below ``tol``; otherwise
:class:`MixedNotConverged` carries the history."""

from __future__ import annotations

import time
from dataclasses import replace

from .. import tables as T
from ..checks import check
from ..errors import MixedNotConverged
from ..micro.flow_factors import FlowFactors
from ..micro.rolling import at_slide_to_roll
from ..numerics.threads import one_thread
from .coupling import newton
from .coupling.partitioned import Concentrated, solve_partitioned
from .coupling.problem import macro_problem
from .coupling.result import Convergence, MixedResult, mixed_result, on_grid
from .coupling.settings import MacroSettings
from .laws.lubricant import Lubricant
from .point import OperatingPoint

__all__ = ["MacroSettings", "MixedNotConverged", "MixedResult", "OperatingPoint", "solve_mixed",
           "solve_point"]

#: Newton iterations per load of the ``"newton"`` coupling (it converges in 5-20), at most
#: ``MacroSettings.max_iter``
NEWTON_MAX_ITER = 60

#: Cold starts on grids of at least twice this size begin with a solve on the coarser grid,
#: and a sweep on such a grid is guided by its points there (a ball's 73^2 by 37^2, a/6 a
#: node: its points then run in parallel, C_f within 0.005 % C_f,b of the chained sweep's)
COARSE_START = 36


@one_thread
def solve_mixed(gap, spacing, factors: FlowFactors, *, load: float = T.LOAD, speed: float,
                entrainment: float | None = None,
                lubricant: Lubricant, face=None, settings: MacroSettings = MacroSettings(),
                initial: MixedResult | None = None, progress=None) -> MixedResult:
    """Solve one operating point of the homogenised mixed-EHL problem.

    Parameters
    ----------
    gap : (ny, nx) rigid gap ``h_g = x3_up - x3_low`` of the macro geometry [m]; x1 (the
        sliding direction of the disk) along the columns
    spacing : (dx1, dx2) [m]
    factors : flow factors of the micro scale (patch average)
    load : imposed normal load F_N,imp [N] (default: Table 6's, 150 N)
    speed : sliding speed U of the disk [m/s] (``u_r = U``; ``u_m = U/2`` on a pin)
    entrainment : mean speed ``u_m`` of the surfaces [m/s] when it is not ``U/2``: a ball on
        a disk at slide-to-roll ratio ``SRR = u_r / u_m`` has ``speed = SRR u_m`` (0: pure
        rolling).  The flow factors (computed with the pin at rest, SRR 2) are carried to
        that SRR by :func:`fem_twin.micro.at_slide_to_roll` (the rolling-sliding Couette and
        shear factors; :mod:`fem_twin.micro.rolling`)
    lubricant : mu_0 and the constants of eqs 23-24
    face : (ny, nx) bool, the pin face for the friction integral (eq 33); all if None
    initial : a result to warm-start from (e.g. the neighbouring speed of a sweep)
    progress : optional callable ``progress(iteration, residual)``

    The same as :func:`solve_point` of the :class:`~fem_twin.macro.point.OperatingPoint`
    of these arguments.
    """
    point = OperatingPoint(gap, spacing, factors, load=load, speed=speed,
                           entrainment=entrainment, lubricant=lubricant, face=face,
                           settings=settings)
    return seeded_point(point, initial=initial, progress=progress)[0]


@one_thread
def solve_point(point: OperatingPoint, initial: MixedResult | None = None,
                progress=None) -> MixedResult:
    """The converged state of the operating ``point`` (eqs 17-34), warm from ``initial``
    (a result on any grid), reporting ``progress(iteration, residual)``."""
    return seeded_point(point, initial=initial, progress=progress)[0]


@one_thread
def seeded_point(point: OperatingPoint, *, initial: MixedResult | None = None, secants=None,
                 progress=None):
    """:func:`solve_point` whose Anderson coupling starts from ``secants``, the last
    differences of the same point's coupling on a coarser grid
    (:class:`~fem_twin.macro.coupling.partitioned.Secants`, interpolated).  Returns ``(result,
    secants)``, the second this solve's own (None where the coupling is not Anderson):
    :func:`~fem_twin.macro.nested.solve_nested` hands them from level to level.
    """
    check("point", point, OperatingPoint)
    settings = point.settings
    factors = at_slide_to_roll(point.factors, point.slide_to_roll)
    t0 = time.perf_counter()
    if initial is None and min(point.gap.shape) >= 2 * COARSE_START:
        initial, secants = _coarse_start(replace(point, factors=factors))
    if initial is not None:
        initial = on_grid(initial, point.gap.shape, point.spacing)
    P = macro_problem(point, factors)
    if settings.coupling == "newton" or (settings.coupling == "auto" and initial is not None
                                         and initial.meta.get("coupling") == "newton"):
        return _solve_newton(P, initial, progress, t0), None
    try:
        ev, h_el, h_d, it, history, secants = solve_partitioned(P, point.load, point.face,
                                                                initial, progress, secants)
    except (MixedNotConverged, Concentrated):
        if settings.coupling != "auto":
            raise
        return _solve_newton(P, initial, progress, t0), None
    run = Convergence(it, history, time.perf_counter() - t0)
    return mixed_result(P, ev, h_el, h_d, run), secants


def _coarse_start(point: OperatingPoint):
    """The point solved on the grid coarsened by 2 (recursively), to a looser tolerance,
    with its coupling's secants, or ``(None, None)`` when that grid is too coarse to resolve
    the contact."""
    coarse = point.coarsened()
    try:
        return seeded_point(replace(coarse, settings=replace(
            coarse.settings, tol=max(coarse.settings.tol, 1e-4))))
    except MixedNotConverged:
        return None, None


def _solve_newton(P, initial, progress, t0):
    """The ``"newton"`` coupling (:mod:`.newton`): warm from ``initial``, else by load
    continuation from the rigid film."""
    s, load = P.point.settings, P.point.load
    max_iter = min(s.max_iter, NEWTON_MAX_ITER)
    if initial is None:
        x, ev, it, history = newton.continuation(P, load, tol=s.tol, max_iter=max_iter,
                                                 progress=progress)
    else:
        x, ev, it, history = newton.solve(P, newton.state_from(initial, P), load, tol=s.tol,
                                          max_iter=max_iter, progress=progress)
    run = Convergence(it, history, time.perf_counter() - t0, coupling="newton")
    return mixed_result(P, ev, x.w, x.h_d, run)
