"""The run-time cost model: a case's wall time on the calibration machine, before it runs.

``fem-twin run`` prints it scaled to this machine by :func:`fem_twin.case.machine.slowdown` and
asks for ``--yes`` above seven times the bundled case's.  The constants were fitted to the
bundled, paper and ball cases on the calibration machine (their measurements:
``benchmarks/README.md``, "The run-time cost model"); ``tests/test_cli.py`` holds the
estimate within 0.7-1.3x of those runs.
"""

from __future__ import annotations

import math

#: a warm Stribeck point of a pin at 128^2 [s], its growth with the pixels, and the cost of
#: a main-curve point with its C_f error estimate in plain points
POINT_SECONDS, POINT_GROWTH, ESTIMATE_COST = 1.38, 0.7, 1.28
#: a ball's warm point at 73^2 (Newton coupling) [s] and its growth with the grid's side
BALL_POINT_SECONDS, BALL_POINT_GROWTH = 3.9, 2.4
#: a band point in main-curve points, by ``[run] band_grid`` (the band's sweeps converge to
#: ``[run] band_tol`` and carry no error estimate; "coarse" runs them on the coarsened grid)
BAND_POINT_COST = {"coarse": 0.14, "full": 0.54}
#: a band point on a grid coarsened once more, against one on the grid before
BAND_LEVEL_COST = 0.33
#: the Stribeck stage of the thermal twin (``[thermal] model = "flash"``) against the
#: isothermal one: each point iterates its film temperature (2-5 warm solves)
THERMAL_COST = 1.5
#: micro stage cost per cell pixel, time step and separation on one core [s] (the cell
#: problems, the periodic contact and the coarsened cell of the error estimate)
MICRO_SECONDS = 3.5e-6
#: separations an adaptive h0 sample solves per patch pair: ``a + k / sqrt(h0_tol)`` (at
#: most the candidates)
ADAPTIVE_H0 = (5.5, 2.7)


def estimated_seconds(case, cores: int = 2) -> float:
    """Rough wall time of ``fem-twin run`` of ``case`` (a :class:`~fem_twin.case.Case`) on
    ``cores`` cores of the calibration machine [s]: the micro stage at ``MICRO_SECONDS``
    per cell pixel, step and separation on one core, and one sweep per viscosity (and per
    patch with ``[run] patch_band``) of warm points at ``POINT_SECONDS`` (a ball's at
    ``BALL_POINT_SECONDS``), the main curves' with their error estimates."""
    patches = len(case.geometry.patches)
    mc = case.micro
    h0 = mc.h0_count
    if mc.h0_tol:
        a, k = ADAPTIVE_H0
        h0 = min(h0, a + k / math.sqrt(mc.h0_tol))
    pixels = mc.resolution[0] * mc.resolution[1]
    micro = MICRO_SECONDS * pixels * mc.steps * h0 * patches / max(cores, 1)
    if case.tribometer.ball:         # Newton coupling
        point = BALL_POINT_SECONDS * (case.macro.grid / 73) ** BALL_POINT_GROWTH
        estimate = 1.0
    else:
        res = case.preprocessing.resolution or (256, 256)
        point = POINT_SECONDS * ((res[0] * res[1]) / 128 ** 2) ** POINT_GROWTH
        estimate = ESTIMATE_COST
    n_mu = len(case.lubricant.viscosities)
    points = case.sweep.count * (1 + 0.5 * case.sweep.refine)   # refinement: ~+50 %
    band = patches if case.run.patch_band and patches > 1 else 0
    band *= _band_point_cost(case)
    sweeps = n_mu * (1 + (patches if band else 0))
    macro = point * points * n_mu * (estimate + band) / max(1, min(cores, sweeps))
    return micro + macro * (THERMAL_COST if case.thermal.model != "none" else 1.0)


def _band_point_cost(case) -> float:
    """A band point in main-curve points, by ``[run] band_grid`` and the macro grid
    (``BAND_LEVEL_COST`` for each coarsening beyond the first)."""
    if case.run.band_grid != "coarsest":
        return BAND_POINT_COST[case.run.band_grid]
    shape = ((case.macro.grid,) * 2 if case.tribometer.ball
             else case.preprocessing.resolution or (256, 256))
    return BAND_POINT_COST["coarse"] * BAND_LEVEL_COST ** (case.band_coarsening(shape) - 1)
