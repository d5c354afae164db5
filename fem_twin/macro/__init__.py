"""Macro scale: homogenised Reynolds with mass-conserving cavitation, elastic deformation,
contact pressure and load balance (eqs 17-34).

Four rooms and a porch.  A room imports only from its own room or an earlier one, and the
porch (the modules of ``macro/`` itself) sits on top of them all; no room imports it
(tests/test_architecture.py reads this table)::

    1    laws
    2    film
    3    coupling
    4    reference
    5    point, mixed, nested, estimate, figures

The rooms, each listing its modules in its own docstring:

    laws       :mod:`fem_twin.macro.laws`: lubricant, viscosity, friction, boundary laws,
               boundary friction, thermal and kinematics
    film       :mod:`fem_twin.macro.film`: the homogenised Reynolds solver with JFO
               cavitation, its Couette flux and the nodal contact pressure
    coupling   :mod:`fem_twin.macro.coupling`: the coupled point (settings, the assembled
               problem, partitioned and Newton couplings, the converged result)
    reference  :mod:`fem_twin.macro.reference`: the deterministic and time-resolved
               references and the ball's point-contact formulas

The porch, what a caller uses:

    point      ``OperatingPoint``: one operating point as a value, checked once
    mixed      ``solve_mixed``, ``solve_point``: the checks and the choice of coupling
    nested     sweep points started from the grid coarsened by two (nested iteration)
    estimate   the discretisation error of a point's C_f
    figures    the fields of operating points as PNG
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
