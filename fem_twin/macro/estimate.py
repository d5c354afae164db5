"""The discretisation error of an operating point's friction coefficient C_f (eq 34).

Each part is a change of C_f [-] (why each is so: docs/accuracy.md, "The error bar on
every friction coefficient"): ``"macro"``, the point on the macro grid coarsened by two,
``|C_f(h) - C_f(2h)| / (2^p - 1)``, ``p`` the settings' ``grid_order`` or else the order
observed on the grids coarsened once and twice (:func:`observed_order`); ``"time"``,
``"grid"``, ``"h0"``, the flow factors' own estimates carried into C_f (the linear response
of the point, on the level :func:`micro_parts_level` gives, to each variant of the factors,
:meth:`FlowFactors.variants`: :mod:`.coupling.linearised`; ``"h0"`` over
``H0_SPACING_RATIO``).  ``"total"`` sums their magnitudes, a bound (a root sum of squares
fell below the truth where they add with one sign); ``"signed"`` keeps their signs, whose
sum (:func:`signed_total`) the accuracy warning reads.  Beside them, ``"film"``: the
friction of the point's fields with half and twice the boundary film, times
``FILM_COUPLING``, a model sensitivity no refinement reduces (not in the total).  A part
not estimated is NaN, left out of the total and named in ``"missing"`` (the reason in
``"failed"``).  Smooth factors have no micro parts (0); a screening model's point
(:attr:`FlowFactors.screening`) has no estimate (NaN, :data:`SCREENING`)."""

from __future__ import annotations

import numpy as np

from ..errors import MixedNotConverged, SolverError
from ..micro.estimate import FILM_VARIANTS
from .coupling.linearised import friction_responses
from .coupling.result import friction_with
from .mixed import solve_point
from .point import OperatingPoint

#: the lowest macro order ``p`` of ``|C_f(h) - C_f(2h)| / (2^p - 1)`` a pin's map takes
#: where ``[macro] grid_order`` (``MacroSettings.grid_order``) does not set it, and the
#: order where none is observed: a map resampled from the measured pin converges at first
#: order in the mixed regime, where the face's edge moves by a fraction of a pixel from
#: grid to grid (observed 0.69-1.10 on the paper pair's maps at 128^2, 256^2 and 512^2;
#: ``benchmarks/run.py estimate-paper``)
MACRO_ORDER = 1.0
#: the highest observed order taken: the Q1 scheme's on a smooth film
SCHEME_ORDER = 2.0
#: the fewest nodes a side of the grid coarsened twice on which the order is observed
ORDER_SIDE = 16
#: the order of a ball's sphere, smooth on every grid: observed 1.77-2.15 in the mixed
#: regime on its meshes graded over 73^2, 145^2 and 289^2 (``benchmarks/run.py
#: estimate-ball``); a ball's run sets ``grid_order`` to it
SPHERE_ORDER = 2.0
#: the C_f change of the interpolant through every other separation over the error of the
#: whole sample: 4, as for factors smooth in log h0 (:mod:`fem_twin.micro.sampling`).
#: Measured on the bundled case against 61 candidates: on its range (0.1-1 um) the h0
#: error is 0.013 % C_f,b and the part at most 0.16 %; from 20 nm (16 candidates, 1.30
#: apart) the change it reads is about the error itself, 0.09 % against 0.33 %
#: (docs/accuracy.md, "The h0 range")
H0_SPACING_RATIO = 4.0
#: the film part over the fixed-field change: a run with half or twice the boundary film
#: also moves the film temperature and the adaptive h0 sample, which the re-evaluation
#: leaves out.  The bundled pin at 450 N (98 % of the load on asperities) moved by up to
#: 1.8 times the re-evaluated change in the mixed regime (share above 0.1), at most 0.052 %
#: C_f,b (docs/accuracy.md, "The boundary film where it matters")
FILM_COUPLING = 2.0
#: why a screening model's point (:attr:`FlowFactors.screening`) has no estimate
SCREENING = ("the average-flow screening model: its C_f has no error bar, its gap to the "
             "deterministic reference is measured in docs/peers.md")
#: the discretisation parts of an estimate, which its total sums, in the order of the
#: NetCDF output
PARTS = ("macro", "time", "grid", "h0")
#: the model sensitivity reported beside them: C_f's change with the boundary film
FILM = "film"
#: how the estimate is made, kept with it as ``"method"``: a checkpointed point whose
#: estimate was made another way (by an earlier fem_twin: the film's sensitivity in the
#: total, the micro parts' variants solved to 1e-3) gets it made again when a run resumes
METHOD = ("discretisation parts, micro parts as linear responses, macro order observed on "
          "the point's nested grids")
#: the fewest nodes a side of the grid the micro parts are solved on: there their sum is
#: within a few per cent of the next finer level's at a seventh of the time
#: (docs/accuracy.md)
MICRO_PARTS_SIDE = 192


def micro_parts_level(shape) -> int:
    """How many coarsenings by two of a grid of ``shape`` the micro parts are solved on:
    the most that leave at least :data:`MICRO_PARTS_SIDE` nodes a side, at least one
    (512^2: 1; 1024^2: 2, to 256^2; 1997^2: 3, to 250^2)."""
    side, level = min(shape), 0
    while (side + 1) // 2 >= MICRO_PARTS_SIDE or level == 0:
        side, level = (side + 1) // 2, level + 1
    return level


def friction_error(result, point: OperatingPoint, levels=()) -> dict:
    """Estimated discretisation error of ``result.friction_coefficient`` per part and in
    total (see the module docstring), for the point ``result`` that
    :func:`~fem_twin.macro.mixed.solve_point` returned for the operating ``point`` (its
    ``lubricant`` the film's); ``levels``: the same point already solved on the grid's
    coarsenings by two, finest first (:func:`.nested.solve_nested`'s levels after the
    first), which are then not solved again."""
    factors = point.factors
    if factors.screening:                         # a statistical model: no error bar
        return _not_estimated(SCREENING)
    solve = _Levels(result, point, levels)
    try:
        base = solve(1)
    except MixedNotConverged as err:
        return _not_estimated(f"coarse grid: {err.args[0]}")
    order, observed = _order(solve, point)
    signed = {"macro": (base.friction_coefficient - result.friction_coefficient)
              / (2 ** order - 1)}
    micro, failed = _micro_parts(solve, factors, micro_parts_level(point.gap.shape))
    signed.update(micro)
    films = [v for k, v in factors.variants().items() if k in FILM_VARIANTS]
    if films:                                 # the friction factor alone: no solve
        own = friction_with(result, factors, point)
        moved = [friction_with(result, v, point) - own for v in films]
        signed[FILM] = FILM_COUPLING * max(moved, key=abs)
    smooth = factors.meta.get("smooth", False)              # no roughness: no micro error
    parts = (*PARTS, FILM)
    for kind in set(parts) - set(signed):
        signed[kind] = 0.0 if smooth else np.nan
    out = {part: abs(float(signed[part])) for part in parts}
    out["total"] = float(np.nansum([out[part] for part in PARTS]))
    out["signed"] = {part: float(signed[part]) for part in parts}
    out["method"], out["macro_order"] = METHOD, order
    out["grid_order"], out["observed_order"] = point.settings.grid_order, observed
    missing = [part for part in parts if np.isnan(out[part])]
    if missing:
        out["missing"] = missing
    if failed:
        out["failed"] = failed
    return out


def _micro_parts(solve, factors, level) -> tuple[dict, list]:
    """``({kind: signed change of C_f}, failures)`` of the factors' variants, each the
    linear response (:func:`.coupling.linearised.friction_responses`) of the point on the
    grid coarsened ``level`` times (NaN where that failed)."""
    variants = {k: v for k, v in factors.variants().items() if k not in FILM_VARIANTS}
    if not variants:
        return {}, []
    try:                                # the coarse point, or a singular Jacobian, NaN
        moved = friction_responses(solve.point(level), solve(level), variants)
    except (MixedNotConverged, SolverError, ValueError) as err:
        return {kind: np.nan for kind in variants}, [f"level {level}: {err.args[0]}"]
    return {kind: change / (H0_SPACING_RATIO if kind == "h0" else 1.0)
            for kind, change in moved.items()}, []


def _not_estimated(reason: str) -> dict:
    """An estimate with every part NaN, for ``reason``."""
    return {**{part: np.nan for part in (*PARTS, FILM)}, "total": np.nan, "failed": [reason],
            "method": METHOD}


def is_current(meta: dict, settings) -> bool:
    """Whether a point's metadata ``meta`` holds a C_f error estimate made by this
    :data:`METHOD` for the ``grid_order`` of ``settings`` (a resumed run makes any other
    again; a screening model's estimate, which has no macro part, for any)."""
    estimate = meta.get("error_estimate") or {}
    return (estimate.get("method") == METHOD
            and estimate.get("grid_order", settings.grid_order) == settings.grid_order)


def observed_order(c0: float, c1: float, c2: float) -> float | None:
    """The macro order observed from C_f on a grid (``c0``) and on its coarsenings by two
    (``c1``) and four (``c2``), ``log2((c2 - c1) / (c1 - c0))``, clipped to
    [:data:`MACRO_ORDER`, :data:`SCHEME_ORDER`]; None where the changes differ in sign."""
    d1, d2 = c2 - c1, c1 - c0
    if not d1 * d2 > 0:
        return None
    return float(np.clip(np.log2(d1 / d2), MACRO_ORDER, SCHEME_ORDER))


def _order(solve, point) -> tuple[float, float | None]:
    """``(p, observed)``: the macro part's order, the settings' ``grid_order`` or else the
    :func:`observed_order` of the point's ``solve`` levels 0-2 (:data:`MACRO_ORDER` where
    none is observed: the changes differ in sign, the grid coarsened twice has fewer than
    :data:`ORDER_SIDE` nodes a side, or its solve fails)."""
    if point.settings.grid_order:
        return point.settings.grid_order, None
    if min(point.gap.shape) < 4 * ORDER_SIDE:
        return MACRO_ORDER, None
    try:
        observed = observed_order(*(solve(k).friction_coefficient for k in range(3)))
    except MixedNotConverged:
        return MACRO_ORDER, None
    return observed or MACRO_ORDER, observed


def signed_total(estimate: dict) -> float:
    """The sum of an estimate's discretisation parts with their signs [-], the estimate of
    C_f minus its converged value where the parts add (docs/accuracy.md measures how far);
    the accuracy warning reads it, and ``"total"``, the sum of their magnitudes, bounds
    it.  NaN for an estimate without signed parts."""
    signed = estimate.get("signed")
    if not signed:
        return float("nan")
    return float(np.nansum([signed[part] for part in PARTS]))


class _Levels:
    """``solve(level)``: the point on the grid coarsened ``level`` times (0: the point's
    own ``result``), warm from the next finer level; a known level is taken, not solved
    again (nor twice)."""

    def __init__(self, result, point, levels):
        self.result, self.points, self.known = result, [point], {0: result}
        for k, level in enumerate(levels, 1):
            if level.pressure.shape != self.point(k).gap.shape:
                break                                     # a level the nested solve left out
            self.known[k] = level

    def point(self, level):
        while len(self.points) <= level:
            self.points.append(self.points[-1].coarsened())
        return self.points[level]

    def __call__(self, level):
        if level not in self.known:
            self.known[level] = solve_point(self.point(level),
                                            initial=self.known.get(level - 1, self.result))
        return self.known[level]
