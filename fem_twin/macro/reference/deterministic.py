"""Deterministic mixed lubrication of a pad whose gap carries the resolved roughness: the
reference the homogenised twin is verified against in the mixed regime (docs/accuracy.md,
"The mixed regime against a deterministic solution").  Nothing here is homogenised.

The pin at rest over the disk sliding at U along +x1 (steady: the roughness is the
pin's); ``h = h_d + shape + K (p + p_con)`` (eqs 19-22 resolved): ``p`` from Reynolds, JFO
cavitation (eqs 17-18 with A = I, b = e1; the cells' Q1 Poiseuille and central Couette
flux; eqs 23-24 at the local pressure), ``p_con`` from the CG-FFT contact with the hardness
cap (:func:`fem_twin.contact.solve`), ``K`` the non-periodic half-space; gauge pressures.
Each pass solves the contact against the shape deformed by the film, then the film on the
contact's gap (floored at ``gap_floor``); deformation, viscosity and density are mixed
(Anderson) until they settle; ``h_d`` balances the load (Brent on its log).  Friction:
:func:`.film_friction.pad_friction` plus the twin's boundary law node by node
(:func:`boundary_force`: eq 32 on the contact load and the film's where the gap is at most
the boundary film, or the shear law with tau_0 on the resolved spots; trapezoidal rule)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import brentq

from ... import tables as T
from ...checks import (
    arguments,
    as_field,
    as_pair,
    check_choices,
    check_ranges,
    number,
    plausible,
    setting,
)
from ...contact import solve as contact_solve
from ...contact.elastic import elastic_operator
from ...errors import InputError, NotConverged, ReynoldsNotConverged
from ...micro.sliding import CellSettings
from ...numerics.anderson import Anderson
from ..coupling.problem import MAX_COEFFICIENT_PRESSURE
from ..film.cavitation import cavitation_model
from ..film.couette import couette_matrix
from ..film.reynolds import fe_poiseuille, trapezoid_weights
from ..laws.boundary_friction import (
    BoundaryLaw,
    asperity_load,
    boundary_friction_setting,
    temperature_factor,
    traction,
)
from ..laws.friction import FilmFields
from ..laws.lubricant import Lubricant
from .film_friction import film_force

__all__ = ["DeterministicNotConverged", "DeterministicResult", "DeterministicSettings",
           "boundary_force", "solve_deterministic"]


#: Anderson mixing of the film's deformation, viscosity and density (the micro-EHL
#: coupling): depth and damping; a pass whose change is ``GROWTH`` times the smallest so
#: far steps back (:class:`_Mixing`)
ANDERSON_DEPTH, ANDERSON_DAMPING, GROWTH = 6, 0.5, 10.0


class DeterministicNotConverged(NotConverged):
    """The load balance or the film-contact iteration missed its tolerance."""


@dataclass(frozen=True)
class DeterministicSettings:
    """Materials and numerics of :func:`solve_deterministic` (SI units)."""

    boundary_friction: float = boundary_friction_setting()
    e_reduced: float = setting(T.E_REDUCED, "E' of eq 22", "reduced_modulus")
    hardness: float = setting(T.HARDNESS, "the cap on the contact pressure", "hardness")
    boundary_film: float = setting(CellSettings.boundary_film, "films thinner than this "
                                   "carry no wall shear (the cells' default)",
                                   "boundary_film")
    gap_floor: float = setting(CellSettings.gap_floor, "the film in a contact spot (the "
                               "cells' default)", "gap_floor")
    boundary: BoundaryLaw = setting(BoundaryLaw(), "the boundary shear's law, the twin's "
                                    "(fem_twin.macro.laws.boundary_friction), node by node on the "
                                    "resolved spots", unit="a section")
    temperature: float = setting(24.0, "the oil's temperature [C], where the shear law's "
                                 "temperature factor is read (isothermal)", "temperature_C")
    film_deforms: bool = setting(True, "the film pressure deforms the surfaces (False: the "
                                 "asperities feel their contact pressure alone)", unit="-")
    sides: str = setting("open", "the pad's edges along x1 (x2 = 0 and L2) at ambient "
                         "pressure, or walls that no flow crosses (a strip of a wide pad: "
                         "an x2-invariant gap then gives the 1-D solution)",
                         choices=("open", "sealed"))
    tol: float = setting(1e-7, "log load residual; the film's deformation per micrometre, "
                         "log viscosity and density ratio changes", "solver_tolerance")
    contact_tol: float = setting(1e-9, "tolerance of each contact solve", "solver_tolerance")
    max_iter: int = setting(60, "load evaluations, and film-contact passes per evaluation",
                            "iterations")

    def __post_init__(self):
        check_ranges(self)
        check_choices(self)
        if not (0 < self.gap_floor < self.boundary_film < 1e-6 and 0 < self.tol < 1
                and 0 < self.contact_tol < 1 and self.max_iter >= 2):
            raise InputError("DeterministicSettings: need 0 < gap_floor < boundary_film < 1 um, "
                             "tolerances in (0, 1) and max_iter >= 2")


@dataclass(frozen=True, eq=False)
class DeterministicResult:
    """A converged deterministic point (SI units): ``separation`` h_d [m]; ``film_load``,
    ``contact_load``, ``load`` [N]; ``film_friction`` (wall shear and film pressure on the
    pin; with ``thin_films = "viscous"`` the confined films' too), ``boundary_force`` (the
    boundary law over the resolved spots, :func:`boundary_force`) [N]; fields ``pressure``,
    ``contact_pressure`` [Pa], ``cavity_fraction`` [-], ``gap`` [m]; ``history``: the log
    load residual of each evaluation."""

    speed: float
    load: float
    separation: float
    film_load: float
    contact_load: float
    film_friction: float
    boundary_force: float
    spacing: tuple
    pressure: np.ndarray
    contact_pressure: np.ndarray
    cavity_fraction: np.ndarray
    gap: np.ndarray
    history: tuple = field(default=())

    @property
    def load_share(self) -> float:
        """The share of the load the asperities carry [-]."""
        return self.contact_load / self.load

    @property
    def friction_coefficient(self) -> float:
        """C_f = (film friction + boundary force) / load (eq 34) [-]."""
        return (self.film_friction + self.boundary_force) / self.load


def state_film(state: dict) -> FilmFields:
    """The film of a solved instant's fields ``state`` (:meth:`Pad.at`)."""
    return FilmFields(state["p"], state["gap"], state["theta"], state["mu"])


#: the film deformation's scale in the mixed state [m]: its change per micrometre
H_REF = 1e-6


@dataclass
class Pad:
    """What one solve keeps between evaluations: the grid's operators and the warm starts,
    ``coupled``: the film's deformation over ``H_REF``, its log viscosity ratio and its
    density ratio, stacked (the fixed point's unknowns)."""

    shape: np.ndarray
    spacing: tuple
    speed: float
    lubricant: Lubricant
    settings: DeterministicSettings
    area: np.ndarray = None
    boundary: np.ndarray = None
    side_rows: object = None
    elastic: object = None
    p_con: np.ndarray | None = None
    phi: np.ndarray | None = None
    coupled: np.ndarray | None = None

    def __post_init__(self):
        self.area = trapezoid_weights(self.shape.shape, self.spacing)
        self.boundary = np.zeros(self.shape.shape, bool)
        self.boundary[:, [0, -1]] = True
        if self.settings.sides == "open":
            self.boundary[[0, -1], :] = True
        rows = np.ones(self.shape.shape)
        rows[[0, -1], :] = 0.5
        self.side_rows = sp.diags(rows.ravel())
        self.elastic = elastic_operator(self.shape.shape, self.spacing, self.settings.e_reduced)
        self.coupled = np.zeros((3, *self.shape.shape))
        self.coupled[2] = 1.0

    def film(self, gap, mu, rho, mass=None):
        """Reynolds with JFO on ``gap`` [m] at the viscosity ``mu`` and density ratio ``rho``
        (fields): ``(p, theta)`` [Pa, -].  ``mass``: a time step's term ``(rate, source)``,
        ``rate d(rho h (1 - theta))`` at each node [m^2/s] and the earlier content's inflow
        ``source`` [m^3/s] (:mod:`.time_resolved`); None: steady."""
        model, dx = cavitation_model("switch"), self.spacing
        scale = (6 * self.lubricant.viscosity * self.speed * float(np.mean(dx))
                 / float(np.mean(gap)) ** 2)
        B = couette_matrix(rho * gap * self.speed / 2, np.zeros_like(gap), dx, "central")
        if self.settings.sides == "sealed":            # the side rows' dual cells: half wide
            B = self.side_rows @ B
        options = {}
        if mass is not None:
            B = B + sp.diags((mass[0] * rho * gap).ravel())
            options["source"] = mass[1]
        self.phi, _, _ = model.solve(fe_poiseuille(rho * gap ** 3 / (12 * mu), dx), B,
                                     self.boundary, 0.0, scale, phi0=self.phi, tol=1e-10,
                                     **options)
        return (v.reshape(gap.shape) for v in model.split(self.phi, scale))

    def coupling(self, p, gap) -> np.ndarray:
        """The stacked unknowns the film pressure ``p`` [Pa] implies (eqs 20-24) on ``gap``
        [m]: in contact spots and boundary films (the gap at most ``boundary_film``, where
        the twin has no film) the oil keeps its ambient viscosity and density, as the
        cells' oil does everywhere, and takes the film's from twice that thickness on
        (linear between: the map stays continuous in the gap)."""
        lub, cut = self.lubricant, self.settings.boundary_film
        film = np.clip(gap / cut - 1.0, 0.0, 1.0)
        clipped = film * np.minimum(p, MAX_COEFFICIENT_PRESSURE)
        deform = self.elastic(p) / H_REF if self.settings.film_deforms else 0 * p
        return np.stack([deform, np.log(lub.viscosity_at(clipped) / lub.viscosity),
                         lub.density_ratio(clipped)])

    def at(self, separation: float, shape=None, mass=None):
        """The film and the contact at the rigid separation ``h_d`` [m] (on ``shape``,
        default the pad's; ``mass``: a time step's term, :meth:`film`): a dict of fields
        and loads.  Each pass solves the contact against the shape deformed by the film,
        then the film; the film's deformation, viscosity and density are mixed
        (:class:`_Mixing`) until they change by less than ``tol``."""
        s, history, mixing = self.settings, [], _Mixing()
        shape = self.shape if shape is None else shape
        for _ in range(s.max_iter):
            c = contact_solve(shape + H_REF * self.coupled[0], self.spacing,
                              s.e_reduced, separation=separation, hardness=s.hardness,
                              gap_floor=s.gap_floor, initial_pressure=self.p_con,
                              tol=s.contact_tol)
            self.p_con = c.pressure if c.load > 0 else None
            mu, rho = self.lubricant.viscosity * np.exp(self.coupled[1]), self.coupled[2]
            try:
                p, theta = self.film(c.gap, mu, rho, mass)
            except ReynoldsNotConverged:               # an overshot iterate: step back
                history.append(np.inf)
                self.coupled, self.phi = mixing.back(), None
                continue
            change = self.coupling(p, c.gap) - self.coupled
            history.append(float(np.abs(change).max()))
            if history[-1] < s.tol:
                break
            self.coupled = mixing.next(self.coupled, change, history[-1])
        else:
            raise DeterministicNotConverged("the film's deformation and viscosity did not "
                                            "settle with the contact", history)
        return {"p": p, "theta": theta, "mu": mu, "rho": rho, "p_con": c.pressure, "gap": c.gap,
                "film_load": float(np.sum(self.area * p)),
                "contact_load": float(np.sum(self.area * c.pressure))}


class _Mixing:
    """Anderson mixing of the coupled fields, safeguarded: a pass whose change grows past
    ``GROWTH`` times the smallest so far (or whose film does not solve) returns to the
    iterate of that smallest change, and the mixing restarts there with half the damping
    (micro-EHL squeeze spots, where eqs 23-24 and the deformation feed back strongly)."""

    def __init__(self):
        self.damping = ANDERSON_DAMPING
        self.mixer = Anderson(ANDERSON_DEPTH, self.damping)
        self.best = (np.inf, None, None)

    def next(self, coupled, change, residual):
        if residual < self.best[0]:
            self.best = (residual, coupled.copy(), change.copy())
        elif residual > GROWTH * self.best[0]:
            return self.back()
        return self.mixer.step(coupled.ravel(), change.ravel()).reshape(coupled.shape)

    def back(self):
        """The smallest change's iterate, moved by its damped change; the mixing restarted."""
        if self.best[1] is None:
            raise DeterministicNotConverged("the first film-contact pass did not solve", [])
        self.damping /= 2
        self.mixer = Anderson(ANDERSON_DEPTH, self.damping)
        return self.best[1] + self.damping * self.best[2]


def solve_deterministic(shape, spacing, *, load: float, speed: float, lubricant: Lubricant,
                        settings: DeterministicSettings = DeterministicSettings(),
                        initial: DeterministicResult | None = None) -> DeterministicResult:
    """Solve one operating point of the resolved pad (module docstring).

    Parameters
    ----------
    shape : (ny, nx) undeformed gap at zero separation [m]
        the pad's form plus its roughness, ``disk - pin``, x1 (sliding) along the columns;
        the pad fills the grid
    spacing : (dx1, dx2) [m]
    load : F_N [N]
    speed : the disk's U [m/s]
    settings : the pad's materials and numerics (default: the paper's, Table 6)
    initial : a neighbouring point whose separation starts the bracket of h_d
    """
    s, dx, load, speed = checked_point(shape, spacing, load, speed, (lubricant, settings))
    pad = Pad(s, dx, speed, lubricant, settings)
    h_d, st, history, _ = balance(pad, load, initial.separation if initial else None)
    film = film_force(state_film(st), dx, speed, viscous_cut(settings))
    return DeterministicResult(speed, load, float(h_d), st["film_load"], st["contact_load"],
                               film, boundary_force(pad.area, st, settings, speed),
                               dx, st["p"], st["p_con"], st["theta"], st["gap"],
                               tuple(history))


def checked_point(shape, spacing, load, speed, models):
    """The checked ``(shape, spacing, load, speed)`` of a deterministic point (SI), with
    ``models = (lubricant, settings)``; an :class:`~fem_twin.errors.InputError` before any
    work otherwise."""
    lubricant, settings = models
    s = as_field("shape [m]", shape, 5)
    plausible("shape [m] (its height range: form plus roughness)", float(np.ptp(s)) or 1e-8,
              "height")
    dx = as_pair("spacing [m]", spacing)
    plausible("spacing [m]", dx, "pitch")
    load, speed = number("load [N]", load, "load"), number("speed [m/s]", speed, "speed")
    if not isinstance(lubricant, Lubricant) or not isinstance(settings, DeterministicSettings):
        raise InputError("lubricant must be a Lubricant and settings DeterministicSettings")
    return s, dx, load, speed


@arguments(area="field", state=dict, settings=DeterministicSettings, speed="number")
def boundary_force(area, state: dict, settings: DeterministicSettings, speed: float) -> float:
    """The boundary law's force [N] (eq 32 or the shear law, :mod:`.boundary_laws`) node by
    node on the resolved pad: the spots (``p_con > 0``, a_c = 1) carry ``p_con``, and with
    ``film_on_contacts`` the film's pressure there and, under ``thin_films =
    "boundary"``, where the gap is at most the boundary film; tau_0 on the spots alone;
    the temperature factor at the oil's ``settings.temperature`` (isothermal).  ``area``: the
    nodes' weights [m^2], ``state`` a solved instant's fields, ``speed`` the disk's."""
    law, p_con = settings.boundary, state["p_con"]
    spots = (p_con > 0).astype(float)
    wet = state["gap"] <= settings.boundary_film if law.thin_films == "boundary" else spots > 0
    load = asperity_load(p_con, np.maximum(state["p"], 0.0), wet, law)
    tau = traction(load, spots, speed, law, settings.boundary_friction)
    return float(np.sum(area * tau)) * temperature_factor(law, settings.temperature)


def viscous_cut(settings: DeterministicSettings) -> float:
    """The thinnest film [m] that carries the film's viscous shear: the boundary film, or
    the gap floor where the confined films shear too (``thin_films = "viscous"``)."""
    return settings.gap_floor if settings.boundary.thin_films == "viscous" else \
        settings.boundary_film


def balance(pad: Pad, load: float, start: float | None = None):
    """``(h_d, state, history, slope)``: the separation [m] at which ``pad`` carries
    ``load`` [N] (Brent on the log of the load, bracketed from ``start``), its solved
    state, the log load residual of each evaluation and ``d log W / d h_d`` [1/m] from the
    evaluation nearest the root (the time-resolved solver's load updates)."""
    states, history, settings = {}, [], pad.settings
    std = float(np.std(pad.shape))

    def residual(h_d):
        states[h_d] = pad.at(h_d)
        history.append(np.log((states[h_d]["film_load"] + states[h_d]["contact_load"]) / load))
        return history[-1]

    lo, hi = _bracket(residual, 2 * std if start is None else start, max(std / 4, 1e-9),
                      settings.max_iter)
    h_d = brentq(residual, lo, hi, xtol=1e-15, rtol=1e-10, maxiter=settings.max_iter)
    if abs(residual(h_d)) > settings.tol:
        raise DeterministicNotConverged("the load balance missed its tolerance", history)
    near = min((h for h in states if h != h_d), key=lambda h: abs(h - h_d))
    slope = (_log_load(states[near]) - _log_load(states[h_d])) / (near - h_d)
    return h_d, states[h_d], history, slope


def _log_load(state) -> float:
    return float(np.log(state["film_load"] + state["contact_load"]))


def _bracket(residual, start: float, step: float, max_iter: int):
    """``(lo, hi)`` separations [m] around the balance: from ``start``, steps that double."""
    a, fa = start, residual(start)
    for _ in range(max_iter):
        b = a + (step if fa > 0 else -step)
        fb = residual(b)
        if fa * fb <= 0:
            return min(a, b), max(a, b)
        a, fa, step = b, fb, 2 * step
    raise DeterministicNotConverged("no separation found that carries the load", [fa])
