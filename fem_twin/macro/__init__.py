"""Macro scale: homogenised Reynolds with mass-conserving cavitation, elastic deformation,
contact pressure and load balance (eqs 17-34).

Four rooms, each listing its modules in its own docstring: laws (lubricant, viscosity,
friction, boundary laws and friction, thermal, kinematics), film (Reynolds with JFO
cavitation, its Couette flux, the nodal contact pressure), coupling (the coupled point) and
reference (the deterministic, time-resolved and point-contact references); over them the
porch a caller uses (``OperatingPoint``, ``solve_mixed``, nested starts, the C_f estimate,
figures).  A room imports only from its own room or an earlier one, and none imports the
porch (tests/test_architecture.py reads this table)::

    1    laws
    2    film
    3    coupling
    4    reference
    5    point, mixed, nested, estimate, figures
"""

from ..tables import BOUNDARY_FRICTION
from .film.reynolds import ReynoldsNotConverged, ReynoldsResult, solve_reynolds
from .laws.boundary_friction import BoundaryLaw, boundary_traction
from .laws.friction import FilmFields, hydrodynamic_shear
from .laws.kinematics import disk_velocity
from .laws.lubricant import Lubricant
from .mixed import MacroSettings, MixedNotConverged, MixedResult, solve_mixed, solve_point
from .point import OperatingPoint
from .reference.deterministic import DeterministicResult, DeterministicSettings, solve_deterministic

__all__ = ["BOUNDARY_FRICTION", "BoundaryLaw", "boundary_traction", "FilmFields",
           "hydrodynamic_shear",
           "disk_velocity",
           "DeterministicResult", "DeterministicSettings", "solve_deterministic",
           "Lubricant",
           "MacroSettings", "MixedNotConverged", "MixedResult", "OperatingPoint", "solve_mixed",
           "solve_point",
           "ReynoldsNotConverged", "ReynoldsResult", "solve_reynolds"]
