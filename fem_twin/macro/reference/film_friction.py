"""The resolved film's friction on the pin (the deterministic references, :mod:`.deterministic`
and :mod:`.time_resolved`): the wall shear of the films thicker than the boundary film and
the film pressure on the pin's surface, by the trapezoidal rule (:func:`pad_friction`)."""

from __future__ import annotations

import numpy as np

from ...checks import arguments, check, plausible
from ...errors import InputError
from ..film.reynolds import trapezoid_weights
from ..laws.friction import film_fields

__all__ = ["pad_friction"]


@arguments(spacing="pair", speed="number", boundary_film="number")
def pad_friction(film, spacing, speed: float, boundary_film: float) -> float:
    """The ``film``'s force on the pin along +x1 [N] (:class:`~.friction.FilmFields`: its
    ``mean_gap`` the pad's resolved gap h): ``int mu U / h (1 - theta) dA`` over the films
    thicker than ``boundary_film`` [m] plus ``int (h / 2) dp/dx1 dA``, which is the pin's
    wall shear and the film pressure on its surface (``-(h/2) dp/dx1 - p dh/dx1``)
    integrated by parts with ``p = 0`` on the edge; trapezoidal rule, central differences;
    ``cavity_fraction`` theta [-] in [0, 1] and ``viscosity`` [Pa s] numbers or fields of the
    pressure's grid, the ``spacing`` [m] a plausible pitch."""
    film = film_fields("pad_friction", film)
    h, p = np.asarray(film.mean_gap, float), np.asarray(film.pressure, float)
    cavity_fraction, viscosity = film.cavity_fraction, film.viscosity
    for name, value in (("gap", h), ("cavity_fraction", cavity_fraction),
                        ("viscosity", viscosity)):
        check(f"pad_friction: {name}", value, "numbers")
        if np.ndim(value) and np.shape(value) != p.shape:
            raise InputError(f"pad_friction: {name} {np.shape(value)} and pressure {p.shape} "
                             "must share one grid")
    if np.any(np.abs(np.asarray(cavity_fraction) - 0.5) > 0.5 + 1e-9):
        raise InputError("pad_friction: cavity_fraction is theta, a fraction in [0, 1]")
    if not np.all(np.asarray(viscosity) > 0):
        raise InputError("pad_friction: viscosity [Pa s] is positive (66 mPa s is 0.066)")
    plausible("pad_friction: spacing [m]", spacing, "pitch")
    plausible("pad_friction: boundary_film [m]", boundary_film, "boundary_film")
    return film_force(film, spacing, speed, boundary_film)


def film_force(film, spacing, speed: float, boundary_film: float) -> float:
    """:func:`pad_friction` without its checks, for the solvers' own fields [N]."""
    h = np.asarray(film.mean_gap, float)
    dp1 = np.gradient(np.asarray(film.pressure, float), spacing[0], axis=1)
    shear = np.where(h > boundary_film, film.viscosity * speed / h, 0.0) * (
        1 - film.cavity_fraction)
    return float(np.sum(trapezoid_weights(h.shape, spacing) * (shear + h / 2 * dp1)))
