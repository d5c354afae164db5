"""Micro scale: homogenisation of the roughness cell (paper 2.2.1, eqs 8-16).

``homogenise(pin, disk, h0)`` -> :class:`FlowFactors` (h_m, p_con, A, b, C, d versus h0).
"""

from .cell import CellSolution, CellSolver
from .flow_factors import FlowFactors, LocalFactors, average
from .homogenisation import DEFAULT_H0, homogenise
from .rolling import at_slide_to_roll
from .sliding import CellSettings, sliding_pass

__all__ = ["CellSolution", "CellSolver", "FlowFactors", "LocalFactors", "average", "DEFAULT_H0",
           "at_slide_to_roll",
           "CellSettings", "homogenise", "sliding_pass"]
