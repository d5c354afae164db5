"""Stribeck curves: speed sweeps of the macro solver, Hersey number, deviations (eqs 35, 46)."""

from .curve import (
                    MeasuredCurve,
                    StribeckCurve,
                    deviation_from_measured,
                    friction_deviation,
                    hersey_number,
                    plot_stribeck,
                    read_measured_csv,
                    read_stribeck_csv,
                    write_stribeck_csv,
)
from .request import RollingSliding, Sliding, SweepRequest
from .sweep import stribeck_sweep
from .traction import TractionCurve, traction_sweep

__all__ = ["MeasuredCurve", "deviation_from_measured", "read_measured_csv", "StribeckCurve",
           "friction_deviation", "hersey_number", "plot_stribeck", "read_stribeck_csv",
           "write_stribeck_csv", "SweepRequest", "Sliding", "RollingSliding",
           "stribeck_sweep", "TractionCurve", "traction_sweep"]
