"""The boundary shear of the asperity contacts (eq 32 and its generalisation).

The cell's dry contact at imposed h0 gives the asperities' pressure above the film's: a
film pressure uniform over a cell leaves the cell's gap unchanged, so the contact spots,
a fraction a_r of the area, carry ``p_con + p a_r`` (p the film's gauge pressure).  Both
laws act on that load:

- ``"constant"`` (eq 32): ``tau_b = C_f,b (p_con + p a_r)``;
- ``"shear"`` (Briscoe and Tabor's ``tau = tau_0 + alpha p`` on the real contact area,
  activated in the sliding speed): ``tau_b = (tau_0 a_c + alpha (p_con + p a_r)) s(u)``
  with ``s(u) = 1 + c_u log10(u / u_ref)``, a_c the dry contact fraction; its temperature
  factor ``1 - c_T (T_c - T_ref)`` follows the asperities' absolute temperature T_c (the
  oil's, the bulk rise, the face's and the spot's flash), :func:`temperature_factor`.

``tau_0 = 0``, ``alpha = C_f,b`` and ``c_u = c_T = 0`` give the constant law exactly
(docs/model.md, "Boundary friction").  The films between the gap floor and the cell's
boundary film (``thin_films``, :data:`THIN_FILMS`) join a_r, the area whose film pressure
the asperities' load takes (``"boundary"``), or shear as confined viscous films
(``"viscous"``, :func:`.friction.confined_shear`), or carry nothing (``"none"``); tau_0
acts on the dry contact alone.

The laws are classes in the registry :data:`LAWS` (as the cavitation models are in
:data:`fem_twin.macro.film.cavitation.MODELS`): each owns its ``[boundary]`` keys, its
checks, its shear and what a fit may vary of it, and the case parser, the fit, the macro
scale and the deterministic solver ask the law of a section (:attr:`BoundaryLaw.model`)
instead of testing its name.  Adding one: ARCHITECTURE.md, "Adding a boundary law".
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from ...checks import arguments, check_choices, check_ranges, plausible, setting
from ...errors import InputError
from ...tables import BOUNDARY_FRICTION

#: what the films thinner than the boundary film carry: the boundary shear on their film
#: pressure, a confined film's viscous shear, or nothing
THIN_FILMS = ("boundary", "viscous", "none")
#: the ``[boundary]`` keys every law reads: which law, and the asperities' load
COMMON_KEYS = ("law", "film_on_contacts", "thin_films")
#: the largest fall of the boundary shear the temperature term may give before any heat
#: (the linear law is a local expansion about reference_temperature): the case parser's
#: limit at the hottest oil, :func:`temperature_factor`'s at its temperature
FADED = 0.5
#: the largest distance [K] of a temperature from reference_temperature the linear law
#: spans: farther, one of them is a kelvin value typed as Celsius (24 C is 24.0, not
#: 297.15); the case parser's limit from every oil, :func:`temperature_factor`'s
REFERENCE_REACH = 100.0


def boundary_friction_setting(doc: str = "C_f,b of eq 32", **where):
    """The one declaration of C_f,b, eq 32's boundary friction coefficient: its default
    (:data:`BOUNDARY_FRICTION`, the paper's 1/(3 sqrt 3), exported as
    ``fem_twin.macro.BOUNDARY_FRICTION``) and its quantity (a friction coefficient); the
    case's ``[tribometer] boundary_friction``, :class:`~fem_twin.macro.MacroSettings` and
    :class:`~fem_twin.macro.DeterministicSettings` declare their field with it (their own
    ``doc``; ``where``: :func:`~fem_twin.checks.setting`'s ``section``)."""
    return setting(BOUNDARY_FRICTION, doc, "friction", **where)


class Fitted(NamedTuple):
    """What a fit may vary of a law: one parameter's ``low`` and ``high`` bounds and the
    ``quantity`` of :data:`fem_twin.checks.QUANTITIES` a fitted value is checked against."""

    low: float
    high: float
    quantity: str


class Law:
    """A boundary law of the registry :data:`LAWS`, what it owns: its ``name`` (``[boundary]
    law``), the ``keys`` of ``[boundary]`` it reads beside :data:`COMMON_KEYS`, what a fit
    may vary (``fitted``, :class:`Fitted` by case-file key; ``limits``: those whose bound is
    a physical limit, a fit pinned there fits nothing) and the simulated curves' columns
    such a fit reads (:meth:`columns`).  Its methods take the section ``law`` (a
    :class:`BoundaryLaw` of this law) whose values they read.  The defaults: no speed or
    temperature term, no check."""

    name = ""
    keys: tuple = ()
    fitted: dict = {}
    limits: tuple = ()
    #: what the law reads instead of the keys it leaves (the parser's message)
    reads = ""

    def traction(self, law, load, dry_fraction, speed, boundary_friction):
        """The boundary shear [Pa] on the asperities' ``load`` [Pa], ``dry_fraction`` a_c
        [-], at the sliding ``speed`` [m/s], before any temperature factor."""
        raise NotImplementedError

    def speed_factor(self, law, speed) -> np.ndarray:
        """The shear's factor at the sliding ``speed`` [m/s]: none (1)."""
        return np.ones_like(np.asarray(speed, float))

    def heated_factor(self, law, temperature: float, rise_per_shear: float) -> float:
        """The shear's factor at the asperities' ``temperature`` [C]
        (:func:`heated_factor`): none (1)."""
        return 1.0

    def check_temperature(self, law, temperature: float) -> None:
        """Refuse a ``temperature`` [C] the law's temperature term cannot span."""

    def check_friction(self, boundary_friction) -> None:
        """Refuse a C_f,b the law reads that is not a friction coefficient."""

    def from_case(self, law, given, boundary_friction: float):
        """The section of a case file that gives the keys ``given``: ``law`` with the
        values the law takes from elsewhere in the case where they are not given
        (``boundary_friction``: the case's C_f,b)."""
        return law

    def check_case(self, law, given, temperatures) -> None:
        """Refuse values of a case file's section ``law`` (``given``: the keys it gives)
        that a case with oils at ``temperatures`` [C] cannot run (:class:`InputError`
        naming the key)."""

    def columns(self, params, walther: bool) -> tuple:
        """The simulated curves' columns a fit of ``params`` (this law's among them) reads,
        ``walther``: whether the case's oils give a viscosity-temperature law."""
        return ()

    def check_fit(self, law) -> None:
        """Refuse a fit of this law's parameters for a case of section ``law`` that does
        not read them (:class:`InputError`)."""

    def start(self, law, boundary_friction: float):
        """The section a fit of this law's parameters starts from and whose unfitted values
        it keeps, for a case of section ``law`` (None: eq 32's constant law) and C_f,b
        ``boundary_friction``."""
        return law

    def unknowns(self, law, boundary_friction: float) -> list:
        """``(name, start, low, high)`` of each parameter of ``fitted``, for a case of
        section ``law`` (None: eq 32's constant law)."""
        base = self.start(law, boundary_friction)
        return [(name, min(max(getattr(base, name), lo), hi), lo, hi)
                for name, (lo, hi, _) in self.fitted.items()]

    def fit_force(self, curve, values: dict) -> np.ndarray:
        """The boundary force [N] of a simulated curve read at the measured speeds
        (``curve``: :class:`fem_twin.stribeck.fit.Readings`) with the fitted ``values``
        (case-file keys of ``fitted``)."""
        raise NotImplementedError

    def shares(self, law, share, area, load) -> dict:
        """C_f's relative sensitivity to each of the law's parameters, ``share_q`` by name,
        from the boundary ``share`` of C_f and the curve's real contact ``area`` [m^2] and
        asperity ``load`` [N] (each per point, None where the curve has none)."""
        return {}


class ConstantLaw(Law):
    """Eq 32: ``tau_b = C_f,b (p_con + p a_r)``, C_f,b the case's ``[tribometer]
    boundary_friction``."""

    name = "constant"
    fitted = {"boundary_friction": Fitted(1e-4, 1.0, "friction")}
    limits = ("boundary_friction",)
    reads = "eq 32 with [tribometer] boundary_friction"

    def traction(self, law, load, dry_fraction, speed, boundary_friction):
        return boundary_friction * np.asarray(load, float)

    def check_friction(self, boundary_friction) -> None:
        if boundary_friction is None:
            raise InputError("boundary_traction: boundary_friction: the constant law's C_f,b "
                             "(a friction coefficient), got None")
        plausible("boundary_traction: boundary_friction", boundary_friction, "friction")

    def check_fit(self, law) -> None:
        if law is not None and law.model is not self:
            raise InputError(f"boundary_friction is eq 32's constant C_f,b; the case's "
                             f"[boundary] law = \"{law.law}\" does not read it: fit the other "
                             "parameters, or set law = \"constant\"")

    def unknowns(self, law, boundary_friction: float) -> list:
        lo, hi, _ = self.fitted["boundary_friction"]
        return [("boundary_friction", boundary_friction, lo, hi)]

    def fit_force(self, curve, values: dict) -> np.ndarray:
        return values["boundary_friction"] * curve.read("boundary_force") / \
            curve.boundary_friction

    def shares(self, law, share, area, load) -> dict:
        return {"share_boundary_friction": share}


class ShearLaw(Law):
    """Briscoe and Tabor's ``tau = tau_0 + alpha p`` on the real contact area, in the
    sliding speed and the spots' temperature (module docstring): ``tau_b = (tau_0 a_c +
    alpha (p_con + p a_r)) s(u) t(T_c)``."""

    name = "shear"
    keys = ("shear_strength", "pressure_coefficient", "speed_coefficient", "reference_speed",
            "temperature_coefficient", "reference_temperature")
    fitted = {"shear_strength": Fitted(0.0, 5e8, "shear_strength"),
              "pressure_coefficient": Fitted(0.0, 1.0, "pressure_coefficient"),
              "speed_coefficient": Fitted(-0.3, 0.3, "speed_coefficient"),
              "temperature_coefficient": Fitted(0.0, 0.05, "temperature_coefficient")}

    def columns(self, params, walther: bool) -> tuple:
        """The real contact area and the asperity load, and for a temperature term without
        a Walther law the spots' flash per shear (a temperature that varies)."""
        return ("real_contact_area", "asperity_load") + (
            ("spot_rise",) if "temperature_coefficient" in params and not walther else ())

    def traction(self, law, load, dry_fraction, speed, boundary_friction):
        shear = law.shear_strength * np.asarray(dry_fraction, float)
        return (shear + law.pressure_coefficient * load) * self.speed_factor(law, speed)

    def speed_factor(self, law, speed) -> np.ndarray:
        u = np.asarray(speed, float)
        if law.speed_coefficient == 0:
            return np.ones_like(u)
        ratio = np.where(u > 0, u, law.reference_speed) / law.reference_speed
        return 1 + law.speed_coefficient * np.log10(ratio)

    def heated_factor(self, law, temperature: float, rise_per_shear: float) -> float:
        c = law.temperature_coefficient
        if c == 0:
            return 1.0
        base = 1.0 - c * (temperature - law.reference_temperature)
        return max(base, 0.0) / (1.0 + c * max(rise_per_shear, 0.0))

    def check_temperature(self, law, temperature: float) -> None:
        fall = law.temperature_coefficient * (temperature - law.reference_temperature)
        if law.temperature_coefficient and abs(
                temperature - law.reference_temperature) > REFERENCE_REACH:
            raise InputError(f"temperature_factor: temperature = {temperature:g} C lies more "
                             f"than {REFERENCE_REACH:g} K from reference_temperature = "
                             f"{law.reference_temperature:g} C, beyond the linear law; "
                             "temperatures are in degrees Celsius, not kelvin (24 C is 24.0, "
                             "not 297.15)")
        if fall >= FADED:
            raise InputError(f"temperature_factor: temperature = {temperature:g} C lies "
                             f"{temperature - law.reference_temperature:g} K above "
                             f"reference_temperature = {law.reference_temperature:g} C, where "
                             f"c_T = {law.temperature_coefficient:g} takes {fall:.0%} of the "
                             "shear before any heat; temperatures are in degrees Celsius, not "
                             "kelvin (24 C is 24.0, not 297.15)")

    def from_case(self, law, given, boundary_friction: float):
        """alpha by default the case's C_f,b (the constant law's value)."""
        if "pressure_coefficient" not in given:
            return replace(law, pressure_coefficient=boundary_friction)
        return law

    def check_case(self, law, given, temperatures) -> None:
        """Some shear (tau_0 or alpha), a reference temperature within
        :data:`REFERENCE_REACH` of an oil, a temperature term that leaves more than
        :data:`FADED` of the shear at the hottest oil."""
        if not (law.shear_strength or law.pressure_coefficient):
            raise InputError("[boundary]: shear_strength = pressure_coefficient = 0 leaves the "
                             "asperities no shear at all; give tau_0 [Pa] (10 MPa is 1e7) or "
                             "alpha (0.1), or law = \"constant\"")
        reference = law.reference_temperature
        if "reference_temperature" in given and min(
                abs(t - reference) for t in temperatures) > REFERENCE_REACH:
            raise InputError(f"[boundary] reference_temperature = {reference:g}: more than "
                             f"{REFERENCE_REACH:g} K from every oil temperature "
                             f"{list(temperatures)} C; it is in degrees Celsius, not kelvin "
                             "(24 C is 24.0, not 297.15)")
        hottest = max(temperatures) - reference
        if law.temperature_coefficient * hottest >= FADED:
            raise InputError(f"[boundary] temperature_coefficient = "
                             f"{law.temperature_coefficient:g}: at the oil's "
                             f"{max(temperatures):g} C, {hottest:g} K above "
                             f"reference_temperature, the shear would fall by "
                             f"{law.temperature_coefficient * hottest:.0%} before any heat; "
                             "a relative fall per kelvin (0.2 % is 0.002)")

    def start(self, law, boundary_friction: float):
        """The case's own shear law, or eq 32's constant C_f,b as a shear law (tau_0 = 0,
        alpha = C_f,b)."""
        if law is not None and law.model is self:
            return law
        return BoundaryLaw(law=self.name, shear_strength=0.0,
                           pressure_coefficient=min(boundary_friction, 1.0))

    def fit_force(self, curve, values: dict) -> np.ndarray:
        """The force from the curve's real contact area and asperity load, the film
        temperature and the spots' flash for the temperature factor
        (:func:`temperature_factor`, dT the untempered shear's flash); the iterate's tau_0
        [Pa] enters the force directly (the optimiser passes through tau_0 below the
        law's plausible floor, 10 kPa, on its way from 0)."""
        base = curve.base
        tau0 = values.get("shear_strength", base.shear_strength)
        law = replace(base, law=self.name, **{k: v for k, v in values.items()
                                              if k != "shear_strength"})
        area, load = curve.read("real_contact_area"), curve.read("asperity_load")
        force = (tau0 * area + law.pressure_coefficient * load) * law.speed_factor(curve.speed)
        if law.temperature_coefficient:
            spot = curve.read("spot_rise")
            rise = (0.0 if spot is None else spot * np.divide(
                force, area, out=np.zeros_like(force), where=area > 0))
            c_t, hot = law.temperature_coefficient, curve.film_temperature()
            force = (force * np.maximum(1 - c_t * (hot - law.reference_temperature), 0.0)
                     / (1 + c_t * np.maximum(rise, 0.0)))
        return force

    def shares(self, law, share, area, load) -> dict:
        """C_f,b's share split between tau_0 (``tau_0 A_r``) and alpha (``alpha W``)."""
        if area is None or load is None:
            return {}
        tau = law.shear_strength * area
        alpha = law.pressure_coefficient * load
        with np.errstate(invalid="ignore", divide="ignore"):
            part = np.where(tau + alpha > 0, tau / (tau + alpha), 0.0)
        return {"share_shear_strength": share * part,
                "share_pressure_coefficient": share * (1 - part)}


#: the boundary laws by name (``[boundary] law``): eq 32's constant C_f,b, or the shear
#: strength of a boundary film
LAWS = {law.name: law() for law in (ConstantLaw, ShearLaw)}


@arguments(name=str)
def boundary_law(name: str) -> Law:
    """The registered law called ``name`` (:data:`LAWS`)."""
    try:
        return LAWS[name]
    except KeyError:
        raise InputError(f"law: one of {', '.join(map(repr, LAWS))}, got {name!r}") from None


def fitted_parameters() -> tuple:
    """Every registered law's fitted parameters (case-file keys), law by law."""
    return tuple(name for law in LAWS.values() for name in law.fitted)


def fitted_law(names) -> Law | None:
    """The law whose fitted parameters ``names`` name (None: none); :class:`InputError`
    for the parameters of two laws."""
    if isinstance(names, (str, bytes)) or not isinstance(names, Collection) or not all(
            isinstance(name, str) for name in names):
        raise InputError(f"fitted_law: names: expected parameter names (case-file keys), got "
                         f"{type(names).__name__}")
    laws = [law for law in LAWS.values() if set(names) & set(law.fitted)]
    if len(laws) > 1:
        parts = [f"{', '.join(n for n in names if n in law.fitted)} law = \"{law.name}\"'s"
                 for law in laws]
        raise InputError(f"{' and '.join(parts)}: two boundary laws replace each other; "
                         "fit one law")
    return laws[0] if laws else None


def thin_films_choice(value):
    """``[boundary] thin_films`` as one of :data:`THIN_FILMS`: the flag of case files and
    run folders written before the choice, ``true`` and ``false``, read as ``"boundary"``
    and ``"none"``; anything else unchanged (for the choice check)."""
    if isinstance(value, (bool, np.bool_)):
        return "boundary" if value else "none"
    return value


@dataclass(frozen=True)
class BoundaryLaw:
    """``[boundary]``: the boundary shear on the real contact area (module docstring);
    ``law = "constant"`` reads ``[tribometer] boundary_friction`` (eq 32)."""

    law: str = setting("constant", "eq 32's C_f,b times the asperities' load, or the shear "
                       "law tau_0 a_r + alpha (p_con + p a_r), in the sliding speed and the "
                       "spots' temperature", choices=LAWS)
    shear_strength: float = setting(0.0, "tau_0, the boundary film's shear strength at no "
                                    "pressure", "shear_strength")
    pressure_coefficient: float = setting(BOUNDARY_FRICTION, "alpha, the shear's growth "
                                          "with the contact pressure", "pressure_coefficient")
    speed_coefficient: float = setting(0.0, "c_u, the shear's relative change per decade of "
                                       "sliding speed about reference_speed",
                                       "speed_coefficient")
    reference_speed: float = setting(1.0, "u_ref of the speed factor", "speed")
    temperature_coefficient: float = setting(0.0, "c_T, the shear's relative fall per kelvin "
                                             "of the asperities' temperature above "
                                             "reference_temperature (the oil's, and with the "
                                             "thermal model its bulk rise and the face's and "
                                             "spot's flash)", "temperature_coefficient")
    reference_temperature: float = setting(24.0, "T_ref [C], where the shear law holds "
                                           "without its temperature term (the oil "
                                           "temperature of the plateau it was fitted on)",
                                           "temperature_C")
    film_on_contacts: bool = setting(True, "the film's pressure on the contact spots joins "
                                     "the asperities' load, p_con + p a_r (false: the "
                                     "paper's p_con alone)", unit="true or false")
    thin_films: str = setting("boundary", "films between [micro] gap_floor and boundary_film: "
                              "their film pressure joins the asperities' load (boundary "
                              "films; true in older case files), they shear as confined "
                              "viscous films mu u / h, or they carry no shear (false)",
                              choices=THIN_FILMS)

    def __post_init__(self):
        object.__setattr__(self, "thin_films", thin_films_choice(self.thin_films))
        check_choices(self)
        check_ranges(self)

    @property
    def model(self) -> Law:
        """The registered law of ``law`` (:data:`LAWS`)."""
        return boundary_law(self.law)

    def speed_factor(self, speed) -> np.ndarray:
        """``s(u) = 1 + c_u log10(u / u_ref)`` at the sliding ``speed`` [m/s] (1 where it
        is 0, and for a law without a speed term)."""
        return self.model.speed_factor(self, speed)

    def check_speeds(self, low: float, high: float) -> None:
        """Refuse a speed factor that is not positive over the speeds ``low`` to ``high``
        [m/s] (a shear that changes sign with the speed)."""
        worst = float(np.min(self.speed_factor([low, high])))
        if worst <= 0:
            raise InputError(f"[boundary] speed_coefficient = {self.speed_coefficient:g}: the "
                             f"speed factor falls to {worst:.3g} between {low:g} and {high:g} "
                             "m/s; it must stay positive (a relative change per decade, "
                             "0.05 is 5 %)")


@arguments(law=BoundaryLaw)
def boundary_area(shear, law: BoundaryLaw) -> np.ndarray:
    """a_r [-], the area whose film pressure the asperities carry, from the shear factors
    ``shear`` (LocalFactors): the dry contact fraction, and with ``law.thin_films ==
    "boundary"`` the films below the boundary film too, ``1 - film_fraction`` (at most 1:
    an error estimate's variant of the factors may overshoot)."""
    if not all(hasattr(shear, name) for name in ("contact_fraction", "film_fraction")):
        raise InputError("boundary_area: shear: expected the shear factors at the nodes "
                         f"(FlowFactors.at(h0)), got {type(shear).__name__}")
    if law.thin_films != "boundary" or shear.film_fraction is None:
        return shear.contact_fraction
    return np.clip(np.maximum(shear.contact_fraction, 1 - shear.film_fraction), 0.0, 1.0)


@arguments(contact_pressure="numbers", film_pressure="numbers", law=BoundaryLaw)
def asperity_load(contact_pressure, film_pressure, contact_fraction,
                  law: BoundaryLaw) -> np.ndarray:
    """The asperities' mean normal stress ``p_con + p a_r`` [Pa]: the dry contact's pressure
    over the film's gauge pressure ``film_pressure`` on the contact spots' fraction (p_con
    alone without ``law.film_on_contacts``, the paper's eq 32)."""
    p_con = np.asarray(contact_pressure, float)
    if not law.film_on_contacts:
        return p_con
    return p_con + np.asarray(film_pressure, float) * np.asarray(contact_fraction, float)


@arguments(contact_pressure="numbers", film_pressure="numbers", contact_fraction="numbers",
           sliding_speed="numbers", law=BoundaryLaw, boundary_friction="number")
def boundary_traction(contact_pressure, film_pressure, contact_fraction, sliding_speed,
                      law: BoundaryLaw, boundary_friction: float | None = None) -> np.ndarray:
    """The boundary shear ``tau_b`` [Pa] of ``law`` (module docstring) at each node, its
    temperature factor apart (:func:`temperature_factor`), for spots of dry
    ``contact_fraction`` a_c [-] without thin films beside them (a_r = a_c);
    ``boundary_friction``: the constant law's C_f,b (a friction coefficient; unread by the
    shear law)."""
    law.model.check_friction(boundary_friction)
    try:
        np.broadcast_shapes(*(np.shape(a) for a in (contact_pressure, film_pressure,
                                                    contact_fraction, sliding_speed)))
    except ValueError:
        raise InputError("boundary_traction: the pressures, contact fraction and speed must "
                         "share one grid (or be numbers)") from None
    fraction = np.asarray(contact_fraction, float)
    if np.any(fraction < 0) or np.any(fraction > 1) or np.any(
            np.asarray(contact_pressure, float) < 0):
        raise InputError("boundary_traction: contact_fraction lies in [0, 1] and the contact "
                         "pressure [Pa] is not negative")
    load = asperity_load(contact_pressure, film_pressure, contact_fraction, law)
    return traction(load, contact_fraction, sliding_speed, law, boundary_friction)


@arguments(law=BoundaryLaw)
def traction(load, dry_fraction, sliding_speed, law: BoundaryLaw,
             boundary_friction: float | None) -> np.ndarray:
    """The boundary shear [Pa] on the asperities' ``load`` (:func:`asperity_load`) [Pa],
    tau_0 on the ``dry_fraction`` a_c [-] of the dry contact; :func:`boundary_traction`
    without its checks, for the macro scale's own fields (an error estimate's perturbed
    factors may step outside the physical ranges)."""
    return law.model.traction(law, load, dry_fraction, sliding_speed, boundary_friction)


@arguments(law=BoundaryLaw, temperature="number", rise_per_shear="number")
def temperature_factor(law: BoundaryLaw, temperature: float, rise_per_shear: float = 0.0) -> float:
    """The law's temperature factor at the asperities' temperature ``T_c = temperature +
    dT`` [C], ``temperature`` the film's (the oil's plus the bulk rise and the face's flash)
    and dT the spots' flash of the tempered shear, ``dT = G tau t`` (the flash is linear in
    the flux); the shear law's ``t = 1 - c_T (T_c - T_ref)`` is so ``t = (1 - c_T
    (temperature - T_ref)) / (1 + c_T G tau)``; ``rise_per_shear`` is ``G tau`` [K], the
    rise of the untempered shear (0: no spot flash).  Refused, naming the argument: a
    ``temperature`` outside -40 to 300 C, a negative ``rise_per_shear``, and what the law's
    temperature term cannot span (the shear law: more than :data:`REFERENCE_REACH` from
    T_ref, a kelvin ``reference_temperature``, and a temperature at which the linear law
    alone takes :data:`FADED` (half) of the shear or more, as the case parser refuses at
    the case's hottest oil: 297.15, kelvin typed as C, with c_T = 0.002 about 24 C); the
    film's own heat may take it further (:func:`heated_factor`)."""
    plausible("temperature_factor: temperature [C]", temperature, "temperature_C")
    if rise_per_shear < 0:
        raise InputError(f"temperature_factor: rise_per_shear = {rise_per_shear:g} K: the "
                         "spots' flash of the untempered shear, not negative (0: none)")
    law.model.check_temperature(law, temperature)
    return heated_factor(law, temperature, rise_per_shear)


@arguments(law=BoundaryLaw, temperature="number", rise_per_shear="number")
def heated_factor(law: BoundaryLaw, temperature: float, rise_per_shear: float) -> float:
    """:func:`temperature_factor` without its range checks, at a film's own ``temperature`` [C]
    in the thermal loop (its heat may take the shear further): at least 0, a shear that
    would change sign is none."""
    return law.model.heated_factor(law, temperature, rise_per_shear)
