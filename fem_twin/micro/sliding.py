"""One sliding pass of a roughness cell at one separation: contact, squeeze term and the
three cell problems at each instant, and their time average (paper eqs 8-16).

The disk moves at ``U = 2 u_m`` over the pin at rest: one pass over the period ``L_r1`` in
``N_t`` instants.  With ``h = h0 + z_up(x1 - U t, x2) - z_low + w`` the time term of eq 8 is
exactly ``tau = (1 / u_m) dh/dt = -2 d z_up / dx1 + (1 / u_m) dw/dt``;
``time_derivative="exact"`` (default) evaluates it at every instant (``dw/dt`` from the
contact's tangent), leaving only the trapezoidal rule of a periodic average; the paper's
implicit Euler (``"backward"``) is first order in ``1 / N_t``.  Frames (``moving``): the
disk's (``"lower"``) gives ``A' = A``, ``C' = C``, ``b' = 2 e1 - b``, ``d' = -d``; the
mean-speed frame (``"both"``, default) has no Couette term in eq 8, so the spurious pressure
the pin's frame leaves at contact edges does not arise, and its factors are the pin frame's
exactly (:mod:`.rolling`; measurements in docs/rolling_sliding.md)."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .. import tables as T
from ..checks import arguments, check_choices, check_ranges, setting
from ..contact import contact_rate
from ..contact import solve as contact_solve
from ..errors import InputError, SolverError
from .cell_fv import CellSolverFV
from .film import Triangles
from .flow_factors import FlowFactors
from .rolling import SLIDING


@dataclass(frozen=True)
class CellSettings:
    """Everything besides the surfaces and h0 that the flow factors depend on (SI units),
    each declared once (:func:`fem_twin.checks.setting`); :func:`~fem_twin.micro.homogenise`
    takes it whole (``settings=``) or field by field as keyword shortcuts."""

    steps: int = setting(32, "time steps N_t of one sliding pass (paper: 32)", "time_steps")
    e_reduced: float = setting(T.E_REDUCED, "E' of eq 22", "reduced_modulus",
                               section="materials")
    hardness: float = setting(T.HARDNESS, "the cap on the contact pressure",
                              "hardness", section="materials")
    gap_floor: float = setting(1e-9, "smallest film of the cell problems (a contact spot)",
                               "gap_floor")
    boundary_film: float = setting(10e-9, "films thinner than this carry no film friction "
                                   "(contact spots carry the boundary shear, eq 32)",
                                   "boundary_film")
    pockets: str = setting("sealed", "fluid regions that contact spots and boundary films "
                           "wall in keep their volume (their net squeeze removed), or leak it "
                           "through the contact spots at the gap floor (the paper)",
                           choices=("sealed", "leaking"))
    method: str = setting("fe", "cell problems by Q1 finite elements or the paper's finite "
                          "volumes", choices=("fe", "fvm"))
    moving: str = setting("both", "the cell's frame: the disk at +U/2 and the pin at -U/2 "
                          "(the mean-speed frame, no Couette term in eq 8), the disk at +U "
                          "over the pin at rest (the paper), or the pin at -U (the disk's "
                          "frame)", choices=("both", "upper", "lower"))
    slide_to_roll: float = setting(SLIDING, "SRR = u_r / u_m of the cell's kinematics: the pin or "
                                   "ball at u_m (1 - SRR/2), the disk at u_m (1 + SRR/2) "
                                   "(2: the pin at rest; exact squeeze term only)",
                                   "slide_to_roll")
    first_step: str = setting("steady", "backward scheme only: no time term at the first "
                              "step (the paper), or the last instant before the first",
                              choices=("steady", "periodic"))
    contact_tol: float = setting(1e-10, "tolerance of the periodic contact at each instant",
                                 "solver_tolerance")
    time_derivative: str = setting("exact", "squeeze term of eq 8: exact at every instant, or "
                                   "the paper's implicit Euler", choices=("exact", "backward"))
    rate_tol: float = setting(1e-6, "tolerance of the contact rate (the squeeze term), far "
                              "below the time and grid errors", "solver_tolerance")
    time_tol: float | None = setting(0.0, "adaptive instants per h0 (exact scheme): "
                                     "midpoints while A11, b1 or d1 change by more (0 or None: "
                                     "off)", "adaptive_tolerance")

    def __post_init__(self):
        if not self.time_tol:                          # 0 means off, as in the case file
            object.__setattr__(self, "time_tol", None)
        check_choices(self)
        if self.slide_to_roll != 2 and not (self.moving == "upper"
                                            and self.time_derivative == "exact"):
            raise InputError("slide_to_roll other than 2 is computed in the pin's frame "
                             "(moving='upper') with time_derivative='exact'")
        if self.moving == "both" and self.time_derivative != "exact":
            raise InputError("the paper's time_derivative='backward' needs the paper's frame, "
                             "moving='upper' (the pin at rest)")
        if self.time_tol is not None and not (0 < self.time_tol < 1
                                              and self.time_derivative == "exact"):
            raise InputError("time_tol is a relative tolerance in (0, 1), with "
                             "time_derivative='exact' only")
        check_ranges(self)
        for name in ("e_reduced", "hardness", "gap_floor", "slide_to_roll",
                     "boundary_film"):                                    # 2e11 = 2e11.0
            object.__setattr__(self, name, float(getattr(self, name)))
        object.__setattr__(self, "steps", int(self.steps))


@dataclass(frozen=True, eq=False)
class SlidingPass:
    """One periodic pass of the moving surface over the cell, in ``N_t`` instants.

    Attributes
    ----------
    shapes
        undeformed gap geometry ``z_up - z_low`` at each instant [m]
    moving
        the moving surface's part of that geometry at each instant (``z_up`` shifted for
        the disk, ``-z_low`` shifted for the pin in the disk's frame) [m]
    um_dt
        ``u_m dt`` between instants [m], ``+s/2`` (disk moving) or ``-s/2`` (pin)
    rigid_rate
        ``(1/u_m) d(z_up - z_low)/dt`` of the rigid surfaces at each instant, the rigid part
        of the squeeze term of eq 8 (central differences, the discrete derivative of the
        Couette flux) [-]: ``-2 d(moving)/dx1`` with one surface at rest,
        ``-(1 + SRR/2) d z_up/dx1 + (1 - SRR/2) d z_low/dx1`` with both moving, and
        ``-d z_up/dx1 - d z_low/dx1`` (over ``U/2``) in the mean-speed frame
    couette
        whether eq 8 has its Couette term (not in the mean-speed frame)
    """

    shapes: list
    moving: list
    um_dt: float
    rigid_rate: list
    couette: bool = True


@arguments(z_low="field", z_up="field", spacing="pair", settings=CellSettings)
def sliding_pass(z_low, z_up, spacing, settings: CellSettings, n_steps: int | None = None,
                 offset: float = 0.0) -> SlidingPass:
    """The moving surface shifts by ``s = L_r1 / N_t`` per step (``+s`` for the disk, ``-s``
    for the pin in the disk's frame); ``u_m dt = (shift_up + shift_low) / 2``.  The instants
    are ``(k + offset) s`` for ``k < N_t`` (``offset = 1/2``: the midpoints), each a shift by
    whole pixels (:func:`whole_pixel_steps`: a measured surface has no other positions).

    Both surfaces moving (``settings.slide_to_roll`` = SRR < 2, :mod:`.rolling`): the pin at
    ``u_1 = u_m (1 - SRR/2)`` and the disk at ``u_2 = u_m (1 + SRR/2)``.  The cell averages
    see only the relative position, so the instants are the same relative shifts, the pin
    kept in place (a common translation of both leaves every average unchanged), and the
    squeeze term is that of both translations at each instant."""
    nx = z_low.shape[1]
    n_steps = settings.steps if n_steps is None else n_steps
    whole_pixel_steps(nx, n_steps, offset)
    px = nx // n_steps                           # pixels per step
    n = [int((k + offset) * px) for k in range(n_steps)]
    if settings.moving == "both":
        moving = [_shift(z_up, k) for k in n]
        lower = _d_dx1(z_low, spacing[0])
        return SlidingPass([m - z_low for m in moving], moving, 0.0,
                           [-_d_dx1(m, spacing[0]) - lower for m in moving], couette=False)
    if settings.moving == "upper":
        moving = [_shift(z_up, k) for k in n]
        shapes, um_dt = [m - z_low for m in moving], px * spacing[0] / 2
    else:
        moving = [-_shift(z_low, -k) for k in n]
        shapes, um_dt = [z_up + m for m in moving], -px * spacing[0] / 2
    rates = [-2.0 * _d_dx1(m, spacing[0]) for m in moving]
    if settings.slide_to_roll != 2:
        r = settings.slide_to_roll / 2
        lower = (1 - r) * _d_dx1(z_low, spacing[0])
        rates = [(1 + r) / 2 * rate + lower for rate in rates]
    return SlidingPass(shapes, moving, um_dt, rates)


def whole_pixel_steps(nx: int, steps: int, offset: float = 0.0) -> None:
    """Refuse ``steps`` instants over ``nx`` pixels along x1 unless each instant (at
    ``offset`` steps) shifts the moving surface by whole pixels: a fraction would sample an
    interpolated surface, not the measured one, and bias the flow factors (its size on the
    bundled pin: docs/accuracy.md, "Whole-pixel instants")."""
    if nx % steps or not float(offset * (nx // steps)).is_integer():
        near = [d for d in range(1, nx + 1) if nx % d == 0]
        both = {max(d for d in near if d <= steps), min((d for d in near if d >= steps),
                                                         default=nx)}
        raise InputError(f"{steps} time steps over a cell of {nx} pixels along the sliding "
                         "direction shift the surface by a fraction of a pixel, an "
                         "interpolated surface that biases the flow factors; take a divisor "
                         f"of {nx} (e.g. {' or '.join(map(str, sorted(both)))} steps)")


def _shift(z, px: int):
    """Periodic translation of ``z`` by ``px`` whole pixels along x1."""
    return np.roll(z, px, axis=1) if px else z


def _d_dx1(z, dx1):
    """Periodic central difference along x1 (the Couette flux difference of the FVM)."""
    return (np.roll(z, -1, axis=1) - np.roll(z, 1, axis=1)) / (2 * dx1)


def cell_solver(shape, spacing, method):
    if method == "fe":
        from .cell import CellSolver
        return CellSolver(shape, spacing)
    return CellSolverFV(shape, spacing)


def sliding_contacts(shapes, spacing, settings: CellSettings, h0: float, warm=None):
    """Periodic contact at imposed ``h0`` for each step's shape; ``warm`` (a list, one
    pressure or None per step) is used as the initial guess and updated in place."""
    warm = [None] * len(shapes) if warm is None else warm
    results = []
    for n, s in enumerate(shapes):
        r = contact_solve(s, spacing, settings.e_reduced, separation=h0,
                          hardness=settings.hardness, periodic=True,
                          gap_floor=settings.gap_floor, initial_pressure=warm[n],
                          tol=settings.contact_tol)
        warm[n] = r.pressure if r.load > 0 else None
        results.append(r)
    return results


def sliding_squeeze(contacts, sliding: SlidingPass, spacing, settings: CellSettings):
    """The squeeze term ``tau = (1/u_m) dh/dt`` of eq 8 at each instant (None: steady).

    ``"exact"``: the moving surface translates at ``V = 2 u_m``, so the rate of the rigid
    geometry is ``sliding.rigid_rate`` exactly at every instant; the contact deformation
    adds ``K p'`` from
    :func:`fem_twin.contact.contact_rate`; ``tau = 0`` where the gap sits at the floor.
    No time-step error: the time average of eqs 11-16 over the ``N_t`` instants is then the
    trapezoidal rule of a periodic function.
    ``"backward"`` (paper): ``(h^n - h^(n-1)) / (u_m dt)``, the first step steady
    (``first_step="steady"``) or preceded by the last (``"periodic"``); first order.
    """
    if settings.time_derivative == "backward":
        gaps = [r.gap for r in contacts]
        steady = settings.first_step == "steady"
        return [None if (n == 0 and steady) else (h - gaps[n - 1]) / sliding.um_dt
                for n, h in enumerate(gaps)]
    out = []
    for r, rigid in zip(contacts, sliding.rigid_rate):
        _, elastic = contact_rate(r, rigid, spacing, settings.e_reduced,
                                  hardness=settings.hardness, periodic=True,
                                  tol=settings.rate_tol)
        out.append(np.where(r.raw_gap > settings.gap_floor, rigid + elastic, 0.0))
    return out


#: the boundary films of the friction moments, in units of ``CellSettings.boundary_film``:
#: the setting itself, and half and twice it for the sensitivity (:func:`film_moments`)
FILM_CUTS = (1.0, 0.5, 2.0)


def sliding_cells(contacts, squeezes, solver, settings: CellSettings, couette: bool = True):
    """Cell solutions of each step for its contact's gap and squeeze term (``couette``:
    with eq 8's Couette term), with the film dissipation above each of :data:`FILM_CUTS`,
    each sealed at its own film unless ``settings.pockets`` is ``"leaking"``, and the
    spread of the local shear there (:func:`.film.shear_spread`)."""
    film = tuple(c * settings.boundary_film for c in FILM_CUTS)
    weight = 3 * (2 * frame_speed_ratio(settings)) ** 2          # 3 k^2 of film_moments
    for r, tau in zip(contacts, squeezes):
        yield solver.solve(r.gap, tau, couette=couette, film=film,
                           sealed=settings.pockets == "sealed", shear_weight=weight)


def film_moments(contact, cell: dict, settings: CellSettings) -> dict:
    """The contact's cell averages of one instant, ``p_con`` (eq 11) and the contact
    fraction, and the film's dissipation per ``mu u_r^2``, ``s_c = <1/h> + 3 k^2 <h^3
    |grad chi_1|^2>`` [1/m] (Couette shear and the sliding flow's pressure; ``cell``: the
    instant's cell moments, ``k = 2 u_m / u_r`` of the cell's frame), the friction on the
    pin times u_r (docs/model.md, "Friction on the pin"; ``<1/h>`` exact on the linear
    interpolant of the gap, :mod:`fem_twin.micro.film`), over the film thicker than
    ``settings.boundary_film``, then half and twice it (:data:`FILM_CUTS`): contact spots
    carry the boundary shear (eq 32) instead, and thinner films near them are boundary
    films.  ``h3_g1_pin``: eq 14's ``<h^3 grad chi_1>`` with the pin at rest (``k`` times
    the frame's), for the Poiseuille friction ``2 e1 - b``.  ``s_thin`` and ``a_thin``:
    ``<1/h>`` over the films between the gap floor and each cut and their area, the
    confined films' Couette shear and where it acts (:attr:`FlowFactors.thin_friction`,
    :attr:`FlowFactors.thin_area`)."""
    k = 2 * frame_speed_ratio(settings)
    cuts = [c * settings.boundary_film for c in FILM_CUTS]
    film = Triangles.of(contact.raw_gap)                 # sorted once for every cut
    h_inv = np.array([film.mean_inverse(c) for c in cuts])
    above_floor = film.mean_inverse(settings.gap_floor)
    area = [film.area_above(c) for c in (settings.gap_floor, *cuts)]
    return {"p_con": float(contact.pressure.mean()),
            "contact_fraction": contact.contact_fraction,
            "h3_g1_pin": k * cell["h3_g1"], "s_c": h_inv + 3 * k * k * cell["h3_g1g1"],
            "s_thin": above_floor - h_inv, "a_thin": area[0] - np.array(area[1:])}


def frame_speed_ratio(settings: CellSettings) -> float:
    """u_m / u_r of the cell's frame: 1/SRR with the pin at rest or both moving (the
    mean-speed frame's moments are the pin's frame's), -1/2 in the disk's frame; chi_1 of
    the pin at rest is ``2 u_m / u_r`` times the frame's (the same pressure field)."""
    if settings.moving == "lower":
        return -0.5
    # pure rolling: chi_1 = 0 and no Couette friction to weigh (u_r = 0)
    return 1.0 / settings.slide_to_roll if settings.slide_to_roll else 0.0


def instants(sliding, h0, warm, solver, spacing, settings):
    """Contacts and cell moments at the instants of ``sliding``; (contact, cell) seconds."""
    t0 = time.perf_counter()
    contacts = sliding_contacts(sliding.shapes, spacing, settings, h0, warm)
    squeezes = sliding_squeeze(contacts, sliding, spacing, settings)
    t1 = time.perf_counter()
    steps = [cell.moments for cell in
             sliding_cells(contacts, squeezes, solver, settings, sliding.couette)]
    for m, r in zip(steps, contacts):
        m.update(film_moments(r, m, settings))
    return contacts, steps, [t1 - t0, time.perf_counter() - t1]


#: d1 changes are measured against at least 1/3, its weight beside the sliding term of eq 31
#: (as the adaptive h0 sampling does, :mod:`fem_twin.micro.sampling`)
D1_SCALE = 1.0 / 3.0


def _time_error(steps) -> float:
    """Relative change of A11, b1 and d1 (eqs 13, 14, 16) from every other instant to all
    (d1's relative to at least :data:`D1_SCALE`)."""
    def a11_b1_d1(ms):
        m = time_average(ms)
        return np.array([m["h3_grad"][0, 0] / m["h"] ** 3, 1 - m["h3_g1"][0] / m["h"],
                         m["h_g1"][0] * m["h"]])
    full, half = a11_b1_d1(steps), a11_b1_d1(steps[::2])
    scale = np.abs(full)
    scale[2] = max(scale[2], D1_SCALE)
    return float(np.max(np.abs(full - half) / scale))


def refine_instants(contacts, steps, h0, z_low, z_up, solver, spacing, settings, midpoints):
    """Adaptive instants (``settings.time_tol``, exact scheme): while A11, b1 or d1 change by
    more than the tolerance from every other instant to all, add the midpoints (the time
    average is then over twice the instants) while they fall on whole pixels.  In heavy contact
    the integrand jumps whenever a pixel enters contact, and a fixed N_t samples it
    unevenly; light contact stops at ``steps``.  ``midpoints`` keeps each level's pass and
    warm starts across the separations of a chunk."""
    seconds = [0.0, 0.0]
    while _time_error(steps) > settings.time_tol and z_low.shape[1] % (2 * len(steps)) == 0:
        n = len(steps)
        if n not in midpoints:
            midpoints[n] = (sliding_pass(z_low, z_up, spacing, settings, n_steps=n,
                                         offset=0.5), [None] * n)
        mid, warm = midpoints[n]
        c, m, sec = instants(mid, h0, warm, solver, spacing, settings)
        contacts = [x for pair in zip(contacts, c) for x in pair]
        steps = [x for pair in zip(steps, m) for x in pair]
        seconds = [a + b for a, b in zip(seconds, sec)]
    return contacts, steps, seconds


def half_pass_moments(steps, contacts, sliding, solver, spacing, settings):
    """Moments of the pass with ``N_t / 2`` instants: every other instant; the backward
    difference quotient is redone over the doubled step (its error is not in the sampling)."""
    if settings.time_derivative == "exact":
        return steps[::2]
    half = SlidingPass(sliding.shapes[::2], sliding.moving[::2], 2 * sliding.um_dt,
                       sliding.rigid_rate[::2])
    squeezes = sliding_squeeze(contacts[::2], half, spacing, settings)
    out = [cell.moments for cell in sliding_cells(contacts[::2], squeezes, solver, settings)]
    for m, r in zip(out, contacts[::2]):
        m.update(film_moments(r, m, settings))
    return out


def time_average(steps):
    """Mean of each moment over the instants (the trapezoidal rule of a periodic function)."""
    return {k: sum(m[k] for m in steps) / len(steps) for k in steps[0]}


def factors_from_moments(h0, moments, meta, prefix: str = "") -> FlowFactors:
    """Eqs 11-16 from space-time averaged moments (see :meth:`CellSolver.moments`);
    ``prefix="half_"`` takes the averages over every other instant."""
    def get(key):
        values = np.array([m[prefix + key] for m in moments])
        bad = ~np.isfinite(values).reshape(len(values), -1).all(axis=1)
        if bad.any():                                  # the cells' own failure, not input
            raise SolverError(f"the cell problems gave a non-finite {prefix + key} at h0 = "
                              f"{np.asarray(h0)[bad][0]:.4g} m; please report it")
        return values

    h_m = get("h")
    optional = {}
    if all(prefix + "film_area" in m for m in moments):
        optional = film_spread(get("film_area")[:, 0], get("log_shear")[:, 0], h_m)
    if all(prefix + "s_thin" in m and prefix + "a_thin" in m for m in moments):
        optional.update(thin_friction=get("s_thin")[:, 0] * h_m, thin_area=get("a_thin")[:, 0])
    return FlowFactors(h0=np.asarray(h0, float), h_m=h_m, p_con=get("p_con"), **optional,
                       A=get("h3_grad") / h_m[:, None, None] ** 3,
                       b=np.array([1.0, 0.0]) - get("h3_g1") / h_m[:, None],
                       C=get("h_grad") / h_m[:, None, None], d=get("h_g1") * h_m[:, None],
                       friction_factor=get("s_c")[:, 0] * h_m,
                       pressure_friction=np.array([1.0, 0.0]) + get("h3_g1_pin") / h_m[:, None],
                       contact_fraction=get("contact_fraction"), meta=meta)


def film_spread(film_area, log_shear, h_m) -> dict:
    """``FlowFactors.film_fraction`` and ``log_friction`` from the time-averaged moments
    ``film_area`` [-] and ``log_shear`` (the area mean of ``ln s``, s in 1/m) at ``h_m``
    [m]: ``<ln(h_m s)>`` over the film."""
    return {"film_fraction": film_area, "log_friction": log_shear + film_area * np.log(h_m)}
