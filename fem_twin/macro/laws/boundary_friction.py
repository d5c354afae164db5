"""Boundary friction: the ``[boundary]`` section and the boundary shear at the nodes.

The cell's dry contact at imposed h0 gives the asperities' pressure above the film's: a
film pressure uniform over a cell leaves the cell's gap unchanged, so the contact spots,
a fraction a_r of the area, carry ``p_con + p a_r`` (p the film's gauge pressure), the load
the section's law (:class:`BoundaryLaw`, one of :data:`.boundary_laws.LAWS`) shears.  The
films between the gap floor and the cell's boundary film (``thin_films``,
:data:`THIN_FILMS`) join a_r, the area whose film pressure the asperities' load takes
(``"boundary"``), or shear as confined viscous films (``"viscous"``,
:func:`.friction.confined_shear`), or carry nothing (``"none"``); tau_0 acts on the dry
contact alone.  The temperature factor follows the asperities' absolute temperature (the
oil's, the bulk rise, the face's and the spot's flash), :func:`temperature_factor`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...checks import arguments, check_choices, check_ranges, plausible, setting
from ...errors import InputError
from ...tables import BOUNDARY_FRICTION
from .boundary_laws import LAWS, Law, boundary_law

#: what the films thinner than the boundary film carry: the boundary shear on their film
#: pressure, a confined film's viscous shear, or nothing
THIN_FILMS = ("boundary", "viscous", "none")
#: the ``[boundary]`` keys every law reads: which law, and the asperities' load
COMMON_KEYS = ("law", "film_on_contacts", "thin_films")


def boundary_friction_setting(doc: str = "C_f,b of eq 32", **where):
    """The one declaration of C_f,b, eq 32's boundary friction coefficient: its default
    (:data:`BOUNDARY_FRICTION`, the paper's 1/(3 sqrt 3), exported as
    ``fem_twin.macro.BOUNDARY_FRICTION``) and its quantity (a friction coefficient); the
    case's ``[tribometer] boundary_friction``, :class:`~fem_twin.macro.MacroSettings` and
    :class:`~fem_twin.macro.DeterministicSettings` declare their field with it (their own
    ``doc``; ``where``: :func:`~fem_twin.checks.setting`'s ``section``)."""
    return setting(BOUNDARY_FRICTION, doc, "friction", **where)


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
        """The registered law of ``law`` (:data:`.boundary_laws.LAWS`)."""
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
    temperature term cannot span (the shear law: more than
    :data:`.boundary_laws.REFERENCE_REACH` from T_ref, a kelvin ``reference_temperature``,
    and a temperature at which the linear law alone takes :data:`.boundary_laws.FADED`
    (half) of the shear or more, as the case parser refuses at the case's hottest oil:
    297.15, kelvin typed as C, with c_T = 0.002 about 24 C); the film's own heat may take
    it further (:func:`heated_factor`)."""
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
