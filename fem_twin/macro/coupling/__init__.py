"""The coupled point: the film, the elastic deformation, the contacts and the load
balance solved together (eqs 19-30), and the converged point it gives (eqs 31-34).

It reads the film solver (:mod:`fem_twin.macro.film`) and the laws
(:mod:`fem_twin.macro.laws`); the porch (:func:`fem_twin.macro.solve_mixed`) calls it.

    settings     the macro solver's settings (``MacroSettings``, the case's ``[macro]``)
    problem      an operating point's assembled problem: grid, physics, eq 17's coefficients
    evaluation   the record of one evaluation of the coupled problem at a state
    start        cold starts: the rigid separations the iteration begins from
    partitioned  the partitioned couplings (fixed-point iterations): Anderson, paper's PID
    newton       the monolithic Newton coupling, for elastically dominated contacts
    jacobian     one Newton step's linear algebra: exact Jacobian, Schur preconditioner
    linearised   the linear response of a converged point's C_f to a change of its factors
    result       the converged point: fields, friction on the pin, files
"""

from .evaluation import Evaluation, NewtonEvaluation, PartitionedEvaluation
from .jacobian import Preconditioner, newton_step
from .partitioned import solve_partitioned
from .problem import Problem, macro_problem
from .result import FIELDS, MixedResult, friction_with, mixed_result, pin_friction
from .settings import MacroSettings
from .start import dry_separation, rigid_separation

__all__ = ["MacroSettings",
           "Problem", "macro_problem",
           "Evaluation", "PartitionedEvaluation", "NewtonEvaluation",
           "dry_separation", "rigid_separation",
           "solve_partitioned",
           "Preconditioner", "newton_step",
           "FIELDS", "MixedResult", "friction_with", "mixed_result", "pin_friction"]
