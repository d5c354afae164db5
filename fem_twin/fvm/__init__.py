"""The paper's finite volumes, the reference twin of the FE solvers (one import for all).

They live beside their FE counterparts: the cell problems in :mod:`fem_twin.micro.cell_fv`,
the Poiseuille operator in :mod:`fem_twin.macro.film.reynolds_fv`, the FBNS complementarity solver
in :mod:`fem_twin.macro.film.fbns`; ``method="fvm"`` selects them in the solvers.
"""

from ..macro.film.fbns import solve_complementarity_fb
from ..macro.film.reynolds_fv import fvm_poiseuille
from ..micro.cell_fv import CellSolverFV

__all__ = ["CellSolverFV", "fvm_poiseuille", "solve_complementarity_fb"]
