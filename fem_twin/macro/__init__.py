"""Macro scale: (homogenised) Reynolds equation with mass-conserving cavitation (eqs 17-18)."""

from .reynolds import ReynoldsNotConverged, ReynoldsResult, solve_reynolds

__all__ = ["ReynoldsNotConverged", "ReynoldsResult", "solve_reynolds"]
