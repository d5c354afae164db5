"""The boundary laws of ``[boundary] law`` and their registry :data:`LAWS`.

- ``"constant"`` (eq 32): ``tau_b = C_f,b (p_con + p a_r)``;
- ``"shear"`` (Briscoe and Tabor's ``tau = tau_0 + alpha p`` on the real contact area,
  activated in the sliding speed): ``tau_b = (tau_0 a_c + alpha (p_con + p a_r)) s(u)``
  with ``s(u) = 1 + c_u log10(u / u_ref)``, a_c the dry contact fraction; its temperature
  factor ``1 - c_T (T_c - T_ref)`` follows the asperities' absolute temperature T_c.

``tau_0 = 0``, ``alpha = C_f,b`` and ``c_u = c_T = 0`` give the constant law exactly
(docs/model.md, "Boundary friction").  Each law (as the cavitation models of
:data:`fem_twin.macro.film.cavitation.MODELS`) owns its ``[boundary]`` keys, its checks, its
shear and factors and what a fit may vary of it; the case parser, the fit, the macro scale
and the deterministic solver ask the law of a section (:mod:`.boundary_friction`) instead
of testing its name.  Adding one: ARCHITECTURE.md, "Adding a boundary law".
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ...checks import arguments, plausible, registered
from ...errors import InputError

#: the largest fall of the boundary shear the temperature term may give before any heat
#: (the linear law is a local expansion about reference_temperature): the case parser's
#: limit at the hottest oil, :func:`.boundary_friction.temperature_factor`'s at its
#: temperature
FADED = 0.5
#: the largest distance [K] of a temperature from reference_temperature the linear law
#: spans: farther, one of them is a kelvin value typed as Celsius (24 C is 24.0, not
#: 297.15); the case parser's limit from every oil,
#: :func:`.boundary_friction.temperature_factor`'s
REFERENCE_REACH = 100.0


class Fitted(NamedTuple):
    """What a fit may vary of a law: one parameter's ``low`` and ``high`` bounds and the
    ``quantity`` of :data:`fem_twin.checks.QUANTITIES` a fitted value is checked against."""

    low: float
    high: float
    quantity: str


class Law:
    """A boundary law of the registry :data:`LAWS`, what it owns: its ``name`` (``[boundary]
    law``), the ``keys`` of ``[boundary]`` it reads beside
    :data:`.boundary_friction.COMMON_KEYS`, what a fit may vary (``fitted``, :class:`Fitted`
    by case-file key; ``limits``: those whose bound is a physical limit, a fit pinned there
    fits nothing) and the simulated curves' columns such a fit reads (:meth:`columns`).  Its
    methods take the section ``law`` (a :class:`.boundary_friction.BoundaryLaw` of this law)
    whose values they read.  The defaults: no speed or temperature term, no check."""

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
        (:func:`.boundary_friction.heated_factor`): none (1)."""
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
        it keeps, for a case of section ``law`` (eq 32's constant law where the case gives
        none) and C_f,b ``boundary_friction``."""
        return law

    def unknowns(self, law, boundary_friction: float) -> list:
        """``(name, start, low, high)`` of each parameter of ``fitted``, for a case of
        section ``law`` (as :meth:`start`'s)."""
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
        alpha = C_f,b): a new section of the case's class, its other keys at their
        defaults."""
        if law.model is self:
            return law
        return type(law)(law=self.name, shear_strength=0.0,
                         pressure_coefficient=min(boundary_friction, 1.0))

    def fit_force(self, curve, values: dict) -> np.ndarray:
        """The force from the curve's real contact area and asperity load, the film
        temperature and the spots' flash for the temperature factor
        (:func:`.boundary_friction.temperature_factor`, dT the untempered shear's flash);
        the iterate's tau_0 [Pa] enters the force directly (the optimiser passes through
        tau_0 below the law's plausible floor, 10 kPa, on its way from 0)."""
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
    return registered("law", LAWS, name)


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
