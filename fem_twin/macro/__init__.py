"""Macro scale: homogenised Reynolds with mass-conserving cavitation, elastic deformation,
contact pressure and load balance (eqs 17-34)."""

from .boundary import BOUNDARY_FRICTION, BoundaryLaw, boundary_traction
from .deterministic import DeterministicResult, DeterministicSettings, solve_deterministic
from .friction import hydrodynamic_shear
from .kinematics import disk_velocity
from .lubricant import Lubricant
from .mixed import MacroSettings, MixedNotConverged, MixedResult, solve_mixed, solve_point
from .point import OperatingPoint
from .reynolds import ReynoldsNotConverged, ReynoldsResult, solve_reynolds

__all__ = ["BOUNDARY_FRICTION", "BoundaryLaw", "boundary_traction", "hydrodynamic_shear",
           "disk_velocity",
           "DeterministicResult", "DeterministicSettings", "solve_deterministic",
           "Lubricant",
           "MacroSettings", "MixedNotConverged", "MixedResult", "OperatingPoint", "solve_mixed",
           "solve_point",
           "ReynoldsNotConverged", "ReynoldsResult", "solve_reynolds"]
