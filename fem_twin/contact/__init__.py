"""Contact stage: elastic half-space operators and CG-FFT dry contact (paper 2.2.1)."""

from .elastic import ElasticOperator, elastic_operator, love_rectangle, reduced_modulus
from .levelling import LevellingResult, average_pins, level_pin, tilt_pin, torque_residuals
from .rate import contact_rate
from .solver import ContactNotConverged, ContactResult, solve

__all__ = ["ElasticOperator", "elastic_operator", "love_rectangle", "reduced_modulus",
           "ContactNotConverged", "ContactResult", "solve", "contact_rate", "LevellingResult",
           "average_pins", "level_pin", "tilt_pin", "torque_residuals"]
