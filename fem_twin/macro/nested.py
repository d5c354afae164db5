"""Sweep points started from the grid coarsened by two: nested iteration with a coarse-grid
correction (the full approximation scheme, Brandt 1977).

A point is solved first on every other node, warm from the previous speed's coarse state;
the fine start is then the previous fine state plus the coarse change, interpolated,

    x_0(h) = x_prev(h) + P (x(2h) - x_prev(2h)),

for the elastic deformation, the contact pressure and ``h_d``; the film pressure and the
cavity fraction, whose free boundary the coarse solve places closer, are the coarse
solution's, interpolated.  The coarse point is itself solved so, down to the coarsest
level; a sweep keeps every level of its last point, and the coarse solution is the base
of the point's macro error estimate (:mod:`fem_twin.macro.estimate`).  A cold point's
Anderson coupling also starts from the coarser level's last differences.  What it saves:
docs/performance.md, "Design choices, measured"."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import MixedNotConverged
from .coupling.result import MixedResult, resampled
from .mixed import COARSE_START, seeded_point
from .point import OperatingPoint

#: the fields a coarse-grid correction moves (``h_d`` besides)
CORRECTED = ("pressure", "elastic_deformation", "cavity_fraction", "contact_pressure")


def nested_levels(shape, smallest: int | None = None) -> int:
    """How many coarsenings by two :func:`solve_nested` solves below a grid of ``shape``
    (down to sides of ``smallest`` to twice that; None: the solve's own,
    :data:`~fem_twin.macro.mixed.COARSE_START`)."""
    smallest = COARSE_START if smallest is None else smallest
    side, levels = min(shape), 0
    while side >= 2 * smallest:
        side, levels = (side + 1) // 2, levels + 1
    return levels


def solve_nested(point: OperatingPoint, previous: tuple[MixedResult, ...] = ()
                 ) -> tuple[MixedResult, ...]:
    """The operating ``point`` on its grid and on each coarsening by two down to the coarse
    start (:data:`~fem_twin.macro.mixed.COARSE_START`), finest first: ``(point, coarse,
    ...)``.

    ``previous``: the last point's levels as this returned them (empty for a cold point; a
    point reloaded from its checkpoint without its levels: ``(point,)``), or a guide: this
    point solved on a coarser grid, which starts that level, the finer ones each from the
    coarser level's solution as in a cold point.  Each level starts from the previous
    point's same level moved by the change one level down (the full approximation scheme,
    recursively): only the coarsest grid iterates the whole speed change.  A level whose
    solve fails leaves the finer ones to start from ``previous`` alone, and is left out."""
    return _levels(point, tuple(previous))[0]


def _levels(point, previous):
    """``(levels, secants)``: :func:`solve_nested`'s levels and the finest one's secants."""
    shape = point.gap.shape
    if min(shape) < 2 * COARSE_START:
        result, secants = seeded_point(point, initial=_last(previous))
        return (result,), secants
    guide = bool(previous) and min(previous[0].pressure.shape) < min(shape)
    try:
        levels, secants = _levels(point.coarsened(),
                                  previous if guide else previous[1:] or previous[:1])
    except MixedNotConverged:
        result, secants = seeded_point(point, initial=_last(previous))
        return (result,), secants
    coarse = levels[0]
    if not previous or guide:
        start = coarse
    elif len(previous) > 1 and previous[1].pressure.shape == coarse.pressure.shape:
        start = _film_from(coarse, corrected(previous[0], previous[1], coarse))
    else:
        start = previous[0]
    result, own = seeded_point(point, initial=start,
                               secants=secants if guide or not previous else None)
    return (result, *levels), own


def _film_from(coarse: MixedResult, start: MixedResult) -> MixedResult:
    """``start`` with the film pressure and cavity fraction of the ``coarse`` solution,
    interpolated: where film and cavity meet.  Moved by the coarse change instead, the
    previous point's free boundary lies farther from the new one than the coarse solution's
    does: its first Reynolds solve switches about twice the nodes in twice the
    factorisations (``python benchmarks/run.py scale``)."""
    shape, spacing = start.pressure.shape, start.spacing
    return replace(start, pressure=resampled(coarse.pressure, coarse.spacing, shape, spacing),
                   cavity_fraction=np.clip(resampled(coarse.cavity_fraction, coarse.spacing,
                                                     shape, spacing), 0.0, 1.0))


def _last(previous):
    """The previous point's finest level, or None."""
    return previous[0] if previous else None


def corrected(previous: MixedResult, previous_coarse: MixedResult,
              coarse: MixedResult) -> MixedResult:
    """``previous`` moved by the change from ``previous_coarse`` to ``coarse``, interpolated
    onto its grid (see the module docstring); pressures kept at or above the cavitation
    pressure, cavity fractions in [0, 1]."""
    moved = {name: getattr(previous, name) + resampled(
        getattr(coarse, name) - getattr(previous_coarse, name), coarse.spacing,
        previous.pressure.shape, previous.spacing) for name in CORRECTED}
    moved["cavity_fraction"] = np.clip(moved["cavity_fraction"], 0.0, 1.0)
    moved["pressure"] = np.maximum(moved["pressure"], previous.pressure.min())
    return replace(previous, h_d=previous.h_d + coarse.h_d - previous_coarse.h_d, **moved)
