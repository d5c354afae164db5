"""Simulated Stribeck curves against measured ones (paper 3.3): C_f,dev of eq 35 at the
measured speeds, a table and a plot per curve."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..io.table import write_csv
from .curve import MeasuredCurve, deviation_from_measured, plot_stribeck, read_measured_csv


def check_like_with_like(measured: MeasuredCurve, load: float, viscosity: float,
                         where: str) -> None:
    """Refuse comparing a measured curve whose file names its test's ``load_N`` or
    ``viscosity_Pa_s`` with a simulated one at another ``load`` [N] or ``viscosity``
    [Pa s] (as ``fem-twin fit`` reads them: the twin must be run at the test's)."""
    for what, test, sim, unit in (("load", measured.load, load, "N"),
                                  ("viscosity", measured.viscosity, viscosity, "Pa s")):
        if test is not None and not np.isclose(test, sim, rtol=1e-6):
            raise InputError(f"{where}: the test ran at {what} {test:g} {unit} (its "
                             f"{'load_N' if what == 'load' else 'viscosity_Pa_s'} column) "
                             f"and the simulated curve is at {sim:g} {unit}; run the twin at "
                             "the test's (or fem-twin fit, which sweeps it there)")


def validate_curves(curves, measured, boundary_friction: float, labels, table, plot_of) -> list:
    """C_f,dev (eq 35, relative to ``boundary_friction`` = C_f,b) of each simulated curve against
    its measured CSV (``measured``: a path or None per curve); all rows into the CSV ``table``,
    one plot per curve at ``plot_of(viscosity)``.  Returns ``max |C_f,dev|`` per curve."""
    rows, result = [], []
    for curve, path, label in zip(curves, measured, labels):
        if path is None:
            continue
        m = read_measured_csv(path)
        dev = deviation_from_measured(curve, m, boundary_friction)
        rows += [(curve.viscosity, u, cf, d) for u, cf, d in
                 zip(m.speed, m.friction_coefficient, dev)]
        band = None if m.low is None else (m.low, m.high)
        plot_stribeck([curve], plot_of(curve.viscosity), labels=[label],
                      reference=(m.speed, m.friction_coefficient, band),
                      boundary_friction=boundary_friction)
        result.append({"viscosity_Pa_s": curve.viscosity, "measured": str(path),
                       "max_abs_cf_dev": float(np.nanmax(np.abs(dev)))})
    write_csv(table, dict(zip(("viscosity_Pa_s", "speed_m_s", "measured_cf", "cf_dev"),
                              zip(*rows) if rows else ((),) * 4)))
    return result
