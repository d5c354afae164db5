"""Friction on the pin: the tangential force of the film (eqs 31, 33-34); the contacts'
(eq 32) is :mod:`.boundary_friction`'s.

The default law (``"pin"``) is the force a load cell on the pin holder reads: the wall
shear plus the film pressure on the pin's asperity flanks (the micro scale's friction
factors ``friction_factor`` s_C and ``pressure_friction`` ``2 e1 - b``) plus the film
pressure on the face's own slope.  Its integral equals the force on the disk and the
film's dissipation over the sliding speed (docs/model.md, "Friction on the pin").
``"paper"`` is eq 31, the pin's wall shear with ``<1/h>`` read as ``1/h_m``.  The laws are
classes in the registry :data:`LAWS` (``[macro] friction``), each its film traction's parts
and what it reads: :func:`hydrodynamic_shear` asks the law.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...checks import arguments, as_field, check, registered
from ...errors import InputError
from ...numerics.graded_mesh import Mesh
from .kinematics import rotate_tensor, rotations

#: the nodes of the probabilists' Gauss-Hermite rule over the log-normal spread of the
#: local shear (:func:`eyring_shear`); with 8 a deep cosine film (a = 0.8 h) reads its exact
#: cell mean within 0.8 % at every shear (tests/test_friction.py)
SPREAD_NODES = 8
_NODES, _WEIGHTS = np.polynomial.hermite_e.hermegauss(SPREAD_NODES)
_WEIGHTS = _WEIGHTS / _WEIGHTS.sum()
#: what a rig reads: a tangential load cell on the pin holder, or the disk's reaction
#: torque over the track radius
READINGS = ("force", "torque")


@dataclass(frozen=True, eq=False)
class FilmFields:
    """The lubricant film's fields its friction reads, each on the grid (ny, nx) or a
    number: its ``pressure`` [Pa] (absolute), ``mean_gap`` h_m [m] (a resolved pad's own
    gap), ``cavity_fraction`` theta [-] and ``viscosity`` [Pa s].  A converged point
    (:class:`~fem_twin.macro.MixedResult`) has the same names and serves as well."""

    pressure: np.ndarray
    mean_gap: np.ndarray
    cavity_fraction: np.ndarray
    viscosity: np.ndarray


def film_fields(name: str, film) -> FilmFields:
    """``film`` checked for the fields :class:`FilmFields` names (pressure and gap as
    fields), or :class:`~fem_twin.errors.InputError` naming the function ``name``."""
    if not all(hasattr(film, f) for f in ("pressure", "mean_gap", "cavity_fraction",
                                           "viscosity")):
        check(f"{name}: film", film, FilmFields)
    as_field(f"{name}: film pressure [Pa]", film.pressure)
    as_field(f"{name}: film mean_gap [m]", film.mean_gap)
    return film


class PinForce:
    """The force on the pin, the default law; its traction ``(mu u_r / h_m) s_C (1 - theta)
    - (h_m/2) (2 e1 - b)·grad p - (p - p_amb) dh_m/dx1``, the last term the film pressure on the
    slope of the pin's face; its Eyring shear spread over the cell's local shear
    (:func:`eyring_shear`); the disk's drag (``reading = "torque"``) is its force too."""

    name = "pin"
    description = ("the force on the pin: wall shear and the film pressure on the asperity "
                   "flanks and the face's slope")
    #: whether the disk's drag, a torque reading's, is this law's force (:func:`disk_shear`)
    drag = True
    #: whether the traction reads the entrainment speed u_m
    reads_entrainment = False

    def parts(self, grad, film, shear, speeds, turn):
        """``(poiseuille, couette, across)`` [Pa]: the pressure-driven traction along x1,
        the Couette traction along the sliding before the cavity and Eyring, and the
        Couette traction across it (0 here), of the ``film`` (:class:`FilmFields`) at
        ``grad`` ``(dp/dx2, dp/dx1)``, ``speeds`` ``(u_r, u_m)`` and the sliding's ``turn``
        ``(cos, sin, |v|)``."""
        dp2, dp1 = grad
        mean_gap, viscosity = film.mean_gap, film.viscosity
        f = shear.pressure_friction
        poiseuille = -mean_gap / 2 * (f[..., 0] * dp1 + f[..., 1] * dp2)
        return poiseuille, viscosity / mean_gap * (speeds[0] * shear.friction_factor) * turn[2], 0.0

    def spread(self, shear):
        """The factors whose local shear spreads the Eyring shear (:func:`eyring_shear`)."""
        return shear

    def face_term(self, pressure, ambient_pressure, mean_gap, face, spacing):
        """The film pressure on the face's slope [Pa] (None: not read)."""
        return (pressure - ambient_pressure) * face_slope(mean_gap, face, spacing)


class PaperShear(PinForce):
    """Eq 31, the pin's wall shear: ``-(h_m/2) (C grad p)_1 + (mu / h_m) (-6 u_m d_1 + u_r)
    (1 - theta)`` with ``d`` at the slide-to-roll ratio; its Eyring shear on the cell mean;
    no force on the face's slope, and not the disk's drag."""

    name = "paper"
    description = "eq 31, the pin's wall shear (the paper's)"
    drag = False
    reads_entrainment = True

    def parts(self, grad, film, shear, speeds, turn):
        dp2, dp1 = grad
        mean_gap, viscosity = film.mean_gap, film.viscosity
        (speed, u_m), (c, s, v) = speeds, turn
        C = shear.C if turn is UNIFORM else rotate_tensor(shear.C, c, s)
        poiseuille = -mean_gap / 2 * (C[..., 0, 0] * dp1 + C[..., 0, 1] * dp2)
        couette = viscosity / mean_gap * (-6 * u_m * shear.d[..., 0] + speed) * v
        across = 0.0
        if turn is not UNIFORM:
            across = viscosity / mean_gap * (-6 * u_m * shear.d[..., 1]) * v * s
        return poiseuille, couette, across

    def spread(self, shear):
        return None

    def face_term(self, pressure, ambient_pressure, mean_gap, face, spacing):
        return None


#: the friction laws by name (``[macro] friction``): the force on the pin, or the paper's
#: eq 31
LAWS = {law.name: law() for law in (PinForce, PaperShear)}
#: the turn ``(cos, sin, |v|)`` of uniform sliding along x1
UNIFORM = (1.0, 0.0, 1.0)


@arguments(name=str)
def friction_law(name: str):
    """The registered friction law called ``name`` (:data:`LAWS`)."""
    return registered("friction", LAWS, name)


@arguments(spacing="spacing", speed="number", entrainment="number")
def hydrodynamic_shear(film, shear, spacing, speed, *, entrainment=None, eyring_stress=None,
                       law: str = "pin", ambient_pressure: float = 0.0, face=None,
                       velocity=None) -> np.ndarray:
    """The ``film``'s (:class:`FilmFields`) tangential traction on the pin along +x1 [Pa]
    by the friction ``law`` of :data:`LAWS` (:class:`PinForce`, :class:`PaperShear`), the
    disk sliding at ``speed`` u_r along +x1, or at ``speed`` times ``velocity`` (ny, nx, 2),
    a rotating disk's (:mod:`.kinematics`), the surfaces entraining the oil at
    ``entrainment`` u_m (the operating point's, :attr:`~fem_twin.macro.OperatingPoint.u_m`;
    eq 31 reads it); the pin's ``face`` (bool grid, default all; one-sided at its edge:
    not the rim's drop) for the film pressure on its slope.  ``shear``: the
    :class:`~fem_twin.micro.LocalFactors` at the point's h0; ``spacing`` (dx1, dx2) [m] or
    a graded mesh; gradients by central differences; ``eyring_stress`` tau_0 [Pa]: the
    Couette part becomes ``tau_0 asinh(tau / tau_0)`` (Eyring) along the sliding.  On a
    rotating disk the cell-frame factors turn with the sliding (``C``, ``d``; ``2 e1 - b``
    completed isotropically commutes with the turn) and the traction is its x1 component.
    """
    model = friction_law(law)
    film = film_fields("hydrodynamic_shear", film)
    if entrainment is None and model.reads_entrainment:
        raise InputError(f"hydrodynamic_shear: law = {law!r} reads the entrainment speed u_m "
                         "[m/s] (entrainment=, the operating point's u_m)")
    p, theta = np.asarray(film.pressure, float), film.cavity_fraction
    turn = UNIFORM if velocity is None else rotations(velocity)
    poiseuille, couette, across = model.parts(gradient(p, spacing), film, shear,
                                              (speed, entrainment), turn)
    couette = couette * (1 - theta)
    if eyring_stress is not None:
        couette = eyring_shear(couette, eyring_stress, model.spread(shear))
    couette = couette * turn[0] - across * (1 - theta)
    on_face = model.face_term(p, ambient_pressure, film.mean_gap, face, spacing)
    if on_face is None:
        return poiseuille + couette
    return poiseuille + couette - on_face


@arguments(spacing="spacing", speed="number")
def disk_shear(film, shear, spacing, speed, *, eyring_stress=None,
               velocity=None) -> np.ndarray:
    """The ``film``'s (:class:`FilmFields`) drag on the disk along its local sliding [Pa].

    ``(mu u_r s / h_m) s_C (1 - theta) + (h_m / 2) b . grad p``, with ``s`` the local speed
    over u_r, ``b`` from the shear factors' ``2 e1 - b`` and ``grad p`` in the sliding
    frame; the disk at ``speed`` times ``velocity`` (None: along x1; Eyring as in
    :func:`hydrodynamic_shear`).  Under uniform sliding its integral along x1 is the force
    on the pin (docs/model.md, "Friction on the pin"); times ``s`` it is the disk's torque
    over the track radius."""
    film = film_fields("disk_shear", film)
    p, mean_gap = np.asarray(film.pressure, float), film.mean_gap
    dp2, dp1 = gradient(p, spacing)
    c, s, v = UNIFORM if velocity is None else rotations(velocity)
    f = shear.pressure_friction                                 # 2 e1 - b
    couette = (film.viscosity / mean_gap * speed * v * shear.friction_factor
               * (1 - film.cavity_fraction))
    if eyring_stress is not None:
        couette = eyring_shear(couette, eyring_stress, shear)
    return couette + mean_gap / 2 * ((2 - f[..., 0]) * (c * dp1 + s * dp2)
                                     - f[..., 1] * (c * dp2 - s * dp1))


def eyring_shear(newtonian, eyring_stress: float, shear=None) -> np.ndarray:
    """The Couette traction of an Eyring film [Pa]: the cell mean of ``tau_0 asinh(tau /
    tau_0)`` over its local Newtonian shear ``tau``, whose mean is ``newtonian``
    (``mu u_r s_C (1 - theta) / h_m``) [Pa].  ``shear`` (LocalFactors) spreads ``tau``
    log-normally over the film fraction ``w`` with the cell's mean and log mean
    (``film_fraction``, ``friction_factor``, ``log_friction``): exact when the film is
    Newtonian and, for the log mean, when it is deeply Eyring, where thin films no longer
    dominate.  None (eq 31's law): ``tau_0 asinh(newtonian / tau_0)``."""
    if shear is None or shear.film_fraction is None:
        return eyring_stress * np.arcsinh(newtonian / eyring_stress)
    w = np.maximum(shear.film_fraction, 1e-12)
    mean = np.maximum(shear.friction_factor, 1e-300) / w
    sigma = np.sqrt(np.maximum(2 * (np.log(mean) - shear.log_friction / w), 0.0))
    levels = np.exp(sigma[..., None] * _NODES)
    levels = levels / (levels @ _WEIGHTS)[..., None]          # mean 1: the Newtonian limit
    local = np.asarray(newtonian)[..., None] / w[..., None] * levels
    return w * ((eyring_stress * np.arcsinh(local / eyring_stress)) @ _WEIGHTS)


def confined_shear(viscosity, speed, shear, mean_gap, cavity_fraction,
                   eyring_stress=None) -> np.ndarray:
    """The Couette shear of the confined films between the gap floor and the boundary film
    [Pa] (``[boundary] thin_films = "viscous"``): ``mu u <1/h>`` over them, ``mu u
    thin_friction / h_m (1 - theta)`` with the factors ``shear`` (LocalFactors) at the
    local sliding ``speed`` [m/s] and ``viscosity`` [Pa s] (the film's: no confinement
    enhancement), Eyring-limited as ``tau_0 asinh(tau / tau_0)`` on the band's mean
    (:func:`eyring_shear` without a spread; ``eyring_stress`` tau_0 [Pa] or None)."""
    tau = viscosity * speed * shear.thin_friction / mean_gap * (1 - cavity_fraction)
    return tau if eyring_stress is None else eyring_shear(tau, eyring_stress)


def face_slope(gap, face, spacing) -> np.ndarray:
    """``d gap / dx1`` [-] on the pin ``face`` (bool grid; None: all), by central
    differences inside it (the mean of the two one-sided slopes on a graded
    ``Mesh``) and one-sided ones at its edge, zero off it; ``spacing``
    (dx1, dx2) [m], dx1 alone, or a mesh."""
    h = np.asarray(gap, float)
    face = np.ones(h.shape, bool) if face is None else np.asarray(face, bool)
    left, right = np.zeros_like(face), np.zeros_like(face)
    left[:, 1:], right[:, :-1] = face[:, :-1], face[:, 1:]
    step, dx1 = np.diff(h, axis=1), 1.0
    if isinstance(spacing, Mesh):
        step = step / spacing.sizes[0]
    else:
        dx1 = float(np.ravel(spacing)[0])
    back, ahead = np.zeros_like(h), np.zeros_like(h)
    back[:, 1:], ahead[:, :-1] = step, step
    both = left & right
    slope = np.where(both, (back + ahead) / 2, np.where(left, back, np.where(right, ahead, 0.0)))
    return np.where(face, slope / dx1, 0.0)


def gradient(field, spacing) -> tuple[np.ndarray, np.ndarray]:
    """``(d/dx2, d/dx1)`` of a nodal field on a grid of ``spacing`` (dx1, dx2) [m] or a
    graded :class:`~fem_twin.numerics.graded_mesh.Mesh` (second order, one-sided at the edges)."""
    if isinstance(spacing, Mesh):
        x1, x2 = spacing.coordinates
        return tuple(np.gradient(field, x2, x1))
    return tuple(np.gradient(field, spacing[1], spacing[0]))
