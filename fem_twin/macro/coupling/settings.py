"""The macro solver's settings, one declaration each (:func:`fem_twin.checks.setting`):
the case file's ``[macro]`` section is this dataclass (with the macro pin and a ball's grid,
:class:`fem_twin.case.sections.MacroSpec`), its reference page is generated from it, and
:func:`fem_twin.macro.solve_mixed` takes it.  Table 6 defaults, SI units."""

from __future__ import annotations

from dataclasses import dataclass

from ... import tables as T
from ...checks import check_choices, check_ranges, setting
from ...errors import InputError
from ..film.cavitation import MODELS, cavitation_model
from ..film.contact_load import RULES
from ..film.couette import SCHEMES
from ..laws.boundary_friction import BoundaryLaw, boundary_friction_setting
from ..laws.friction import LAWS, READINGS


@dataclass(frozen=True)
class MacroSettings:
    """Settings of the macro solver (Table 6 defaults, SI units)."""

    ambient_pressure: float = setting(T.AMBIENT_PRESSURE, "ambient pressure p_amb on the "
                                      "edges of the pin (Table 6)", "pressure")
    cavitation_pressure: float = setting(T.CAVITATION_PRESSURE, "cavitation pressure p_cav "
                                         "(Table 6)", "pressure")
    e_reduced: float = setting(T.E_REDUCED, "E' of eq 22", "solver_modulus",
                               section="materials")
    boundary_friction: float = boundary_friction_setting(section="tribometer")
    boundary: BoundaryLaw = setting(BoundaryLaw(), "the boundary shear's law (eq 32 or the "
                                    "shear law, fem_twin.macro.laws.boundary_friction)",
                                    unit="a section", section="boundary")
    reading: str = setting("force", "what the rig reads: the tangential force on the pin "
                           "holder, or the disk's reaction torque over the track radius",
                           choices=READINGS, section="tribometer")
    track_radius: float | None = setting(
        None, "the disk's axis at this distance from the face's centre: the disk's velocity "
        "field over the face (fem_twin.macro.laws.kinematics); none: uniform sliding along x1",
        "axis_distance", section="tribometer")
    friction: str = setting("pin", "friction law: the force on the pin (wall shear and "
                            "the film pressure on the asperity flanks and the face's slope), "
                            "or the paper's eq 31 (the pin's wall shear)", choices=LAWS)
    method: str = setting("fe", "Poiseuille term by finite elements or the paper's finite "
                          "volumes", choices=("fe", "fvm"))
    coupling: str = setting("auto", "pressure-deformation-load coupling (auto: Anderson, "
                            "Newton for concentrated contacts or when it fails; pid: the "
                            "paper's)", choices=("auto", "anderson", "newton", "pid"))
    complementarity: str = setting("switch", "cavitation model (fem_twin.macro.film.cavitation): "
                                   + ", ".join(f'"{m}"' for m in MODELS) + " (fb: the paper's "
                                   "FBNS, slower)", unit="a registered model")
    couette: str = setting("central", "Couette flux of eq 17: second order, or the paper's "
                           "first-order upwind", choices=SCHEMES)
    contact_quadrature: str = setting("gauss", "nodal contact pressure: the Galerkin load "
                                      "of p_con over the bilinear film (3 x 3 Gauss points "
                                      "a pixel), or the paper's p_con at the nodes",
                                      choices=RULES)
    relaxation_pcon: float = setting(T.RELAXATION_PCON, "under-relaxation alpha_pcon of "
                                     "p_con, eq 26 (pid coupling)", "relaxation")
    relaxation_elastic: float = setting(0.1, "under-relaxation of h_el (pid coupling)",
                                        "relaxation")
    gains: tuple = setting(T.MACRO_GAINS, "K_P, K_I, K_D of the PID on h_d, eq 29 (pid "
                           "coupling)", "pid_gain")
    anderson_depth: int = setting(8, "iterates the Anderson acceleration keeps",
                                 "history")
    # 0.5: fewer coupling iterations than undamped, C_f the same to 3.3e-5 C_f,b
    # (``python benchmarks/run.py newton``)
    anderson_damping: float = setting(0.5, "damping beta of the Anderson step (1: undamped)",
                                      "relaxation")
    inner_steps: int = setting(1, "Newton steps per Reynolds solve while far from the fixed "
                               "point (0: every solve to convergence)", "newton_steps")
    p_ref: float = setting(100e6, "pressure scale of the residuals and of theta",
                           "pressure_scale")
    h_ref: float = setting(1e-6, "length scale of the residuals", "separation")
    # 1e-4: C_f within 2.1e-5 C_f,b of 1e-6, far below the points' error estimates
    # (docs/accuracy.md)
    tol: float = setting(1e-4, "convergence tolerance of the coupling (scaled residuals)",
                         "solver_tolerance")
    max_iter: int = setting(300, "iterations of the coupling before it gives up",
                           "iterations")
    gap_floor: float = setting(1e-9, "smallest h0 passed to the flow factors", "gap_floor")
    grid_order: float | None = setting(
        None, "the macro grid's order of convergence in C_f that the error estimate's macro "
        "part assumes; none: a pin's observed on the point's grids coarsened once and twice "
        "(1 to 2), 2 for a ball's sphere (measured, docs/accuracy.md)", "convergence_order")

    def __post_init__(self):
        check_choices(self)
        check_ranges(self)
        if self.ambient_pressure < self.cavitation_pressure:
            raise InputError("ambient pressure must not be below the cavitation pressure [Pa]")
        cavitation_model(self.complementarity)              # a registered model
        if self.reading == "torque" and not LAWS[self.friction].drag:
            raise InputError("reading = \"torque\" reads the disk's drag, the force law's; "
                             "it needs friction = \"pin\" (eq 31 is the pin's wall shear)")
        if len(self.gains) != 3:
            raise InputError(f"gains: K_P, K_I, K_D (three numbers), got {self.gains!r}")
