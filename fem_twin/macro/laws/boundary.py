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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...checks import arguments, check_choices, check_ranges, plausible, setting
from ...errors import InputError
from ...tables import BOUNDARY_FRICTION

#: the boundary laws: eq 32's constant C_f,b, or the shear strength of a boundary film
LAWS = ("constant", "shear")
#: what the films thinner than the boundary film carry: the boundary shear on their film
#: pressure, a confined film's viscous shear, or nothing
THIN_FILMS = ("boundary", "viscous", "none")
#: the largest fall of the boundary shear the temperature term may give before any heat
#: (the linear law is a local expansion about reference_temperature): the case parser's
#: limit at the hottest oil, :func:`temperature_factor`'s at its temperature
FADED = 0.5
#: the largest distance [K] of a temperature from reference_temperature the linear law
#: spans: farther, one of them is a kelvin value typed as Celsius (24 C is 24.0, not
#: 297.15); the case parser's limit from every oil, :func:`temperature_factor`'s
REFERENCE_REACH = 100.0


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

    def speed_factor(self, speed) -> np.ndarray:
        """``s(u) = 1 + c_u log10(u / u_ref)`` at the sliding ``speed`` [m/s] (1 where it
        is 0, and for the constant law)."""
        u = np.asarray(speed, float)
        if self.law == "constant" or self.speed_coefficient == 0:
            return np.ones_like(u)
        ratio = np.where(u > 0, u, self.reference_speed) / self.reference_speed
        return 1 + self.speed_coefficient * np.log10(ratio)

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
                      law: BoundaryLaw, boundary_friction: float) -> np.ndarray:
    """The boundary shear ``tau_b`` [Pa] of ``law`` (module docstring) at each node, its
    temperature factor apart (:func:`temperature_factor`), for spots of dry
    ``contact_fraction`` a_c [-] without thin films beside them (a_r = a_c);
    ``boundary_friction``: the constant law's C_f,b (a friction coefficient; unread by the
    shear law)."""
    if law.law == "constant":
        plausible("boundary_traction: boundary_friction", boundary_friction, "friction")
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
             boundary_friction: float) -> np.ndarray:
    """The boundary shear [Pa] on the asperities' ``load`` (:func:`asperity_load`) [Pa],
    tau_0 on the ``dry_fraction`` a_c [-] of the dry contact; :func:`boundary_traction`
    without its checks, for the macro scale's own fields (an error estimate's perturbed
    factors may step outside the physical ranges)."""
    if law.law == "constant":
        return boundary_friction * np.asarray(load, float)
    shear = law.shear_strength * np.asarray(dry_fraction, float)
    return (shear + law.pressure_coefficient * load) * law.speed_factor(sliding_speed)


@arguments(law=BoundaryLaw, temperature="number", rise_per_shear="number")
def temperature_factor(law: BoundaryLaw, temperature: float, rise_per_shear: float = 0.0) -> float:
    """The shear law's temperature factor ``t = 1 - c_T (T_c - T_ref)`` at the asperities'
    temperature ``T_c = temperature + dT`` [C], ``temperature`` the film's (the oil's plus
    the bulk rise and the face's flash) and dT the spots' flash of the tempered shear,
    ``dT = G tau t`` (the flash is linear in the flux): so ``t = (1 - c_T (temperature -
    T_ref)) / (1 + c_T G tau)``; ``rise_per_shear`` is ``G tau`` [K], the rise of the
    untempered shear (0: no spot flash).  Refused, naming the argument: a ``temperature``
    outside -40 to 300 C or more than :data:`REFERENCE_REACH` from T_ref (a kelvin
    ``reference_temperature``), a negative ``rise_per_shear``, and a temperature at which the
    linear law alone takes :data:`FADED` (half) of the shear or more, as the case parser
    refuses at the case's hottest oil (297.15, kelvin typed as C, with c_T = 0.002 about
    24 C); the film's own heat may take it further (:func:`heated_factor`)."""
    plausible("temperature_factor: temperature [C]", temperature, "temperature_C")
    if rise_per_shear < 0:
        raise InputError(f"temperature_factor: rise_per_shear = {rise_per_shear:g} K: the "
                         "spots' flash of the untempered shear, not negative (0: none)")
    fall = law.temperature_coefficient * (temperature - law.reference_temperature)
    if law.law == "shear" and law.temperature_coefficient and abs(
            temperature - law.reference_temperature) > REFERENCE_REACH:
        raise InputError(f"temperature_factor: temperature = {temperature:g} C lies more than "
                         f"{REFERENCE_REACH:g} K from reference_temperature = "
                         f"{law.reference_temperature:g} C, beyond the linear law; "
                         "temperatures are in degrees Celsius, not kelvin (24 C is 24.0, "
                         "not 297.15)")
    if law.law == "shear" and fall >= FADED:
        raise InputError(f"temperature_factor: temperature = {temperature:g} C lies "
                         f"{temperature - law.reference_temperature:g} K above "
                         f"reference_temperature = {law.reference_temperature:g} C, where "
                         f"c_T = {law.temperature_coefficient:g} takes {fall:.0%} of the shear "
                         "before any heat; temperatures are in degrees Celsius, not kelvin "
                         "(24 C is 24.0, not 297.15)")
    return heated_factor(law, temperature, rise_per_shear)


@arguments(law=BoundaryLaw, temperature="number", rise_per_shear="number")
def heated_factor(law: BoundaryLaw, temperature: float, rise_per_shear: float) -> float:
    """:func:`temperature_factor` without its range checks, at a film's own ``temperature`` [C]
    in the thermal loop (its heat may take the shear further): at least 0, a shear that
    would change sign is none."""
    c = law.temperature_coefficient
    if law.law == "constant" or c == 0:
        return 1.0
    base = 1.0 - c * (temperature - law.reference_temperature)
    return max(base, 0.0) / (1.0 + c * max(rise_per_shear, 0.0))
