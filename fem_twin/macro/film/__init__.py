"""The film solver: the homogenised Reynolds equation with mass-conserving cavitation on
the macro grid (eqs 17-18) and the contact pressure it carries (eq 11 on the nodes).

It reads the laws (:mod:`fem_twin.macro.laws`); the coupled point
(:mod:`fem_twin.macro.coupling`) and the references (:mod:`fem_twin.macro.reference`)
call it.

    reynolds        FE Poiseuille operator and ``solve_reynolds`` (eqs 17-18)
    reynolds_fv     the paper's finite-volume Poiseuille operator (eq 17)
    cavitation      the cavitation models' contract and registry (``MODELS``)
    switch          the p-theta switch's semismooth Newton (the default model)
    fbns            the paper's Fischer-Burmeister-Newton-Schur solver
    stencil_solver  the switch's Newton steps on the grid's 3x3 stencil (PARDISO)
    couette         the Couette flux div(q (1 - theta)): central or the paper's upwind
    contact_load    the asperity contact pressure on the nodes (Galerkin or nodal)
"""

from .cavitation import MODELS, FischerBurmeister, PThetaSwitch, cavitation_model
from .contact_load import ContactLoad, nodal_contact_pressure
from .couette import SCHEMES, Couette, couette_matrix
from .fbns import solve_complementarity_fb
from .reynolds import (
    PoiseuilleAssembly,
    ReynoldsNotConverged,
    ReynoldsResult,
    fe_poiseuille,
    solve_reynolds,
    trapezoid_weights,
)
from .reynolds_fv import fvm_poiseuille
from .stencil_solver import newton_solver
from .switch import solve_complementarity

__all__ = ["PoiseuilleAssembly", "ReynoldsNotConverged", "ReynoldsResult", "fe_poiseuille",
           "solve_reynolds", "trapezoid_weights",
           "fvm_poiseuille",
           "MODELS", "FischerBurmeister", "PThetaSwitch", "cavitation_model",
           "solve_complementarity", "solve_complementarity_fb", "newton_solver",
           "SCHEMES", "Couette", "couette_matrix",
           "ContactLoad", "nodal_contact_pressure"]
