"""Sweep points started from the grid coarsened by two: nested iteration with a coarse-grid
correction.

A point warm-started from the previous speed's state starts from a film the speed change
has moved everywhere, and the coupling needs 20-50 iterations to move it back (more on
finer grids).  Solved first on every other node (a quarter of the nodes), warm from the
previous speed's coarse state, the speed change is known on the coarse grid; the fine
start is then the previous fine state plus that change, interpolated:

    x_0(h) = x_prev(h) + P (x(2h) - x_prev(2h))

for the pressure, cavity fraction, elastic deformation, contact pressure and ``h_d`` (the
full approximation scheme's correction, Brandt 1977).  The fine grid keeps its own detail
and needs 8-10 iterations instead of 19-26 (sample pin 1 at 256^2, 8 speeds of the paper's
sweep: 33.5 s against 46.5 s, C_f the same to 7e-9 C_f,b).  The coarse solution is also
the base of the point's macro error estimate (:mod:`fem_twin.macro.estimate`), which no
longer solves it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import MixedNotConverged
from .mixed import COARSE_START, solve_mixed
from .result import MixedResult, resampled

#: the fields a coarse-grid correction moves (``h_d`` besides)
CORRECTED = ("pressure", "elastic_deformation", "cavity_fraction", "contact_pressure")


def coarsened(gap, spacing, face):
    """``(gap, spacing, face)`` on every other node of the grid [m] (``face`` None: None)."""
    return (np.asarray(gap)[::2, ::2], (2 * spacing[0], 2 * spacing[1]),
            None if face is None else np.asarray(face, bool)[::2, ::2])


def solve_nested(gap, spacing, factors, *, previous: MixedResult | None = None,
                 previous_coarse: MixedResult | None = None, face=None,
                 **point) -> tuple[MixedResult, MixedResult | None]:
    """One sweep point and its solution on the grid coarsened by two (None on grids under
    ``2 COARSE_START`` nodes a side, or when the coarse solve fails).  ``previous`` and
    ``previous_coarse`` are the last point's pair; ``point`` the other arguments of
    :func:`~fem_twin.macro.solve_mixed` (``load``, ``speed``, ``lubricant``, ...)."""
    if min(np.shape(gap)) < 2 * COARSE_START:
        return solve_mixed(gap, spacing, factors, face=face, initial=previous, **point), None
    gap2, spacing2, face2 = coarsened(gap, spacing, face)
    try:
        coarse = solve_mixed(gap2, spacing2, factors, face=face2,
                             initial=previous_coarse or previous, **point)
    except MixedNotConverged:
        return solve_mixed(gap, spacing, factors, face=face, initial=previous, **point), None
    start = (coarse if previous is None else previous if previous_coarse is None
             else corrected(previous, previous_coarse, coarse))
    return solve_mixed(gap, spacing, factors, face=face, initial=start, **point), coarse


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
