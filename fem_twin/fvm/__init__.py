"""FVM reference twin of the FE solvers: the paper's own discretisation (issue 6)."""

from .cell import CellSolverFV

__all__ = ["CellSolverFV"]
