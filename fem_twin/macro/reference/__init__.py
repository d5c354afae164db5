"""The references the homogenised twin is checked against: the roughness resolved on the
film's grid, steady or in time, and the closed forms of a ball's point contact.

They read the laws (:mod:`fem_twin.macro.laws`), the film solver
(:mod:`fem_twin.macro.film`) and the coupled point's pressure scale
(:mod:`fem_twin.macro.coupling.problem`); nothing of the twin's solve imports them.

    deterministic  mixed lubrication with the roughness resolved (``solve_deterministic``)
    film_friction  the resolved film's force on the pin (``pad_friction``)
    time_resolved  the same with both bodies rough, the disk sliding over the pin in time
    point_contact  ball-on-disk contacts: Hertz, Moes parameters, Hamrock-Dowson films
"""

from .deterministic import (
    DeterministicNotConverged,
    DeterministicResult,
    DeterministicSettings,
    solve_deterministic,
)
from .point_contact import PointContact, film_thickness
from .time_resolved import TimeResolvedResult, TimeSettings, solve_time_resolved

__all__ = ["DeterministicNotConverged", "DeterministicResult", "DeterministicSettings",
           "solve_deterministic",
           "TimeResolvedResult", "TimeSettings", "solve_time_resolved",
           "PointContact", "film_thickness"]
