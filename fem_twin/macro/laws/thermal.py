"""The contact's temperature from its own frictional heat (beyond the paper).

The frictional power ``Q = F_T U`` [W] enters pin and disk through the face as the flux
``q = tau U`` (the point's traction times the local sliding speed).  Three rises add to the
oil's temperature (docs/thermal.md has the model and its checks): the **bulk** rise
``R_b Q``, the rig's lumped resistance ``R_b`` [K/W] to its oil bath, a parameter to fit;
the **face flash**, Blok's partition of ``q`` between the pin, a half-space at rest, and the
disk, a half-space moving at ``U`` (Jaeger 1942; Carslaw and Jaeger 1959, 10.7), the share
that makes the two face-mean temperatures equal; the **asperity flash** of one contact
spot of radius ``a`` carrying ``C_f,b p_spot U`` (Archard 1959), reported, not fed back.
The film sees the oil temperature plus bulk and face flash, its viscosity by the case's
Walther law (:mod:`.viscosity`); each operating point is iterated to that temperature
(:func:`thermal_point`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
import scipy.fft as fft

from ...checks import arguments, as_pair, check_ranges, plausible, setting
from ...contact.elastic import love_rectangle
from ...errors import InputError, NotConverged
from ...numerics.graded_mesh import Mesh
from .boundary_friction import heated_factor

#: sub-samples a side of a cell for the moving part of the kernel (it varies over 2 kappa / U)
SUBSAMPLES = 8


class ThermalNotConverged(NotConverged):
    """The temperature of an operating point did not settle; ``history``: the film
    temperature's change ``abs(dT)`` [K] per iteration (a :class:`NotConverged`: the CLI's
    exit 3)."""


@dataclass(frozen=True)
class ThermalSettings:
    """``[thermal]``: the contact's temperature model (SI units; steel on steel defaults)."""

    model: str = setting("flash", "the film's temperature from its own heat: bulk rise plus "
                         "the face's flash temperature; none: isothermal at the oil's "
                         "temperature (the paper)", choices=("flash", "none"))
    bulk_resistance: float = setting(1.0, "the rig's thermal resistance R_b from the contact "
                                     "to the oil bath (a parameter to fit)",
                                     "thermal_resistance")
    conductivity: float = setting(46.0, "thermal conductivity k of pin and disk (steel)",
                                  "conductivity")
    diffusivity: float = setting(1.2e-5, "thermal diffusivity kappa of pin and disk (steel)",
                                 "diffusivity")
    spot_radius: float = setting(5e-6, "radius a of an asperity contact for its flash "
                                 "temperature (a parameter to fit; reported only)",
                                 "spot_radius")
    tol: float = setting(0.01, "the film temperature's iteration stops when it moves by "
                         "less", "temperature_tol")
    max_iter: int = setting(30, "iterations before the temperature gives up",
                           "iterations")
    grid: int = setting(64, "nodes a side of the face's heat-flux grid at most",
                       "nodes")

    def __post_init__(self):
        if self.model not in ("flash", "none"):
            raise InputError(f"model must be 'flash' or 'none', got {self.model!r}")
        check_ranges(self)


@arguments(flux="field", spacing="pair", speed="number", conductivity="number",
           diffusivity="number")
def surface_temperature(flux, spacing, speed: float, conductivity: float,
                        diffusivity: float) -> np.ndarray:
    """The surface temperature rise [K] of a half-space under the surface heat ``flux``
    (ny, nx) [W/m^2] on a grid of pitch ``spacing`` [m], the body moving at ``speed``
    [m/s] along +x1 under the flux (0: at rest).  Linear convolution (zero padding, FFT)
    with the moving point source's kernel ``exp(-U (R - dx1) / (2 kappa)) / (2 pi k R)``
    averaged over each pixel: its 1/R part exactly (Love's integral), the rest on a grid
    of sub-samples (:data:`SUBSAMPLES` a side)."""
    q = np.asarray(flux, float)
    ny, nx = q.shape
    spacing = plausible("surface_temperature: spacing [m]", as_pair("spacing", spacing), "pitch")
    plausible("surface_temperature: |speed| [m/s]", abs(speed) or 1.0, "speed")
    if not (conductivity > 0 and diffusivity > 0):      # an ideal sink's 1e12 W/(m K) too
        raise InputError(f"surface_temperature: conductivity {conductivity} W/(m K) and "
                         f"diffusivity {diffusivity} m^2/s must be positive")
    k_hat = _kernel_hat((ny, nx), spacing, float(speed), float(diffusivity))
    theta = fft.irfft2(fft.rfft2(q, s=(2 * ny, 2 * nx)) * k_hat, s=(2 * ny, 2 * nx))
    return theta[:ny, :nx] / conductivity


@lru_cache(maxsize=64)
def _kernel_hat(shape, spacing, speed, diffusivity):
    """FFT of the pixel-averaged kernel times the pixel area, for k = 1, on the padded grid."""
    ny, nx = shape
    dx1, dx2 = spacing
    off1 = np.r_[0:nx, -nx:0] * dx1                  # wrapped offsets of the padded grid
    off2 = np.r_[0:ny, -ny:0] * dx2
    # 1/R over the source pixel (love_rectangle with E' = 2/pi is the plain integral)
    kernel = love_rectangle(off1[None, :], off2[:, None], dx1 / 2, dx2 / 2, 2 / np.pi)
    if speed:
        s = (np.arange(SUBSAMPLES) + 0.5) / SUBSAMPLES - 0.5
        moving = np.zeros_like(kernel)
        for a in s * dx1:
            for b in s * dx2:
                d1, d2 = off1[None, :] - a, off2[:, None] - b
                r = np.hypot(d1, d2)
                with np.errstate(invalid="ignore", divide="ignore"):
                    term = np.expm1(-speed * (r - d1) / (2 * diffusivity)) / r
                moving += np.where(r > 0, term, 0.0)
        kernel = kernel + moving * (dx1 * dx2 / SUBSAMPLES ** 2)
    return fft.rfft2(kernel / (2 * np.pi))


@arguments(flux="field", face="field", spacing="pair", speeds="pair",
           settings=ThermalSettings)
def face_flash(flux, face, spacing, speeds, settings: ThermalSettings) -> tuple:
    """``(theta, pin_share)``: the face-mean flash temperature [K] of the heat ``flux``
    [W/m^2] over the ``face`` (bool grid), shared between the pin (or ball) and the disk
    whose surfaces pass the contact at ``speeds`` = (pin, disk) [m/s] so that both face
    means agree (Blok), and the pin's share of the heat."""
    if np.shape(flux) != np.shape(face):
        raise InputError(f"face_flash: flux {np.shape(flux)} and face {np.shape(face)} must "
                         "share their grid")
    if np.ndim(speeds) != 1 or np.size(speeds) != 2:
        raise InputError(f"face_flash: speeds is the pair (pin, disk) [m/s], got {speeds!r}")
    if not np.any(np.asarray(face, bool)):
        raise InputError("face_flash: face has no node: the face is where the heat enters "
                         "(True on the contact's nodes)")
    if np.any(np.asarray(flux)[np.asarray(face, bool)] < 0):
        raise InputError("face_flash: flux [W/m^2] is the frictional heat entering the face, "
                         "not negative")
    speeds = as_pair("face_flash: speeds [m/s]", speeds)
    q, f, dx = _coarse(np.where(face, flux, 0.0), face, spacing, settings.grid)
    pin, disk = (surface_temperature(q, dx, abs(u), settings.conductivity,
                                     settings.diffusivity)[f].mean() for u in speeds)
    if pin + disk <= 0:
        return 0.0, 0.5
    return float(pin * disk / (pin + disk)), float(disk / (pin + disk))


@arguments(flux="number", speeds="pair", settings=ThermalSettings)
def spot_flash(flux: float, speeds, settings: ThermalSettings, n: int = 24) -> float:
    """The mean flash temperature [K] of a circular asperity contact of radius
    ``settings.spot_radius`` carrying ``flux`` [W/m^2], shared as in :func:`face_flash`,
    on ``n`` x ``n`` nodes (8 to 4096)."""
    plausible("spot_flash: n [nodes a side]", n, "nodes")
    if n != int(n):
        raise InputError(f"spot_flash: n: nodes a side, a whole number, got {n!r}")
    a = settings.spot_radius
    if a == 0 or flux <= 0:
        return 0.0
    x = (np.arange(n) - (n - 1) / 2) * (2 * a / n)
    disc = np.hypot(x[None, :], x[:, None]) <= a
    return face_flash(np.where(disc, flux, 0.0), disc, (2 * a / n, 2 * a / n), speeds,
                      replace(settings, grid=n))[0]


def _coarse(flux, face, spacing, most: int):
    """The flux (summed, as power) and face (any node) on blocks of k x k nodes, k the
    smallest that leaves at most ``most`` a side."""
    k = int(np.ceil(max(flux.shape) / most))
    if k <= 1:
        return flux, np.asarray(face, bool), tuple(spacing)
    ny, nx = (-(-n // k) * k for n in flux.shape)
    pad = lambda a: np.pad(a, ((0, ny - a.shape[0]), (0, nx - a.shape[1])))  # noqa: E731
    blocks = lambda a: pad(a).reshape(ny // k, k, nx // k, k)  # noqa: E731
    return (blocks(flux).mean(axis=(1, 3)), blocks(np.asarray(face, bool)).any(axis=(1, 3)),
            (k * spacing[0], k * spacing[1]))



@dataclass(frozen=True)
class ContactThermal:
    """A run's thermal model: its ``settings``, the oil's viscosity-temperature ``law``
    (:class:`~.viscosity.WaltherLaw`; a curve's oil is at the temperature where the law
    gives the curve's mu_0); a point's boundary law (its settings') reads the film
    temperature and the asperity spots' flash in its temperature term (:meth:`tempered`).
    Its methods take the converged ``result`` of an operating ``point``
    (:class:`~fem_twin.macro.point.OperatingPoint`), whose surfaces' speeds share the heat
    (:attr:`~fem_twin.macro.point.OperatingPoint.surface_speeds`), whose flow factors give
    the contact fraction and whose settings give the boundary law."""

    settings: ThermalSettings
    law: object

    def heat(self, result, point) -> dict:
        """The heat of a converged point ``result``: ``power`` F_T U [W], the face's
        ``flash`` [K] and the pin's share ``pin_share`` of the heat, shared between the
        ``point``'s surfaces (:func:`face_flash`)."""
        power = max(float(result.friction_force * result.speed), 0.0)
        face = np.asarray(result.face, bool)
        flux = np.where(face, np.maximum(result.shear_stress, 0.0), 0.0)
        mesh, spacing = result.spacing, result.spacing
        if isinstance(mesh, Mesh):                   # on the mesh's grid
            total = float(np.sum(mesh.area * flux))
            flux, face, spacing = mesh.to_grid(flux), mesh.to_grid(face) > 0.5, mesh.pitch
        else:
            total = flux.sum() * result.spacing[0] * result.spacing[1]
        flux = flux * (power / total) if total > 0 else flux
        flash, share = face_flash(flux, face, spacing, point.surface_speeds, self.settings)
        return {"power": power, "flash": flash, "pin_share": share}

    def spot(self, result, point) -> float:
        """An asperity spot's flash temperature [K] at the point ``result``: the flux of the
        boundary shear over the real contact area (the ``point``'s flow factors give the
        contact fraction) at the sliding speed."""
        face = np.asarray(result.face, bool)
        w = result.spacing.area[face] if isinstance(result.spacing, Mesh) else 1.0
        fraction = (w * point.factors.at(result.h0).contact_fraction[face]).sum()
        flux = (max((w * result.boundary_shear[face]).sum(), 0.0) / fraction
                * abs(result.speed) if fraction > 0 else 0.0)
        return spot_flash(flux, point.surface_speeds, self.settings)

    def tempered(self, result, point, temperature: float):
        """``result`` with its boundary shear times the ``point``'s boundary law's
        temperature factor at the film ``temperature`` [C] and the spots' flash
        (:func:`~.boundary_friction.temperature_factor`; unchanged without a temperature term)."""
        return tempered(result, heated_factor(point.settings.boundary, temperature,
                                              self.spot(result, point)))


@arguments(t="number")
def tempered(result, t: float):
    """``result`` (a MixedResult) with its boundary shear and force times the temperature
    factor ``t`` [-] (:func:`~.boundary_friction.temperature_factor`), its friction with them;
    ``result`` itself where ``t`` is 1."""
    if t == 1.0:
        return result
    lost = (1 - t) * result.boundary_force
    return replace(result, boundary_force=t * result.boundary_force,
                   friction_force=result.friction_force - lost,
                   friction_coefficient=(result.friction_force - lost) / result.normal_load,
                   shear_stress=result.shear_stress - (1 - t) * result.boundary_shear,
                   boundary_shear=t * result.boundary_shear,
                   meta={**result.meta, "boundary_temperature_factor": t})


@arguments(solve=Callable)
def thermal_point(solve, point, thermal: ContactThermal, near: dict | None = None) -> tuple:
    """The operating ``point`` (:class:`~fem_twin.macro.point.OperatingPoint`, its
    ``lubricant`` the oil) at the film temperature its own heat gives it.

    ``solve(lubricant, previous)`` returns the point's levels ``(result, *coarser)`` with
    the film's ``lubricant``, warm from ``previous`` (None first).  The film temperature
    ``T = T_oil + R_b Q + theta_face`` is iterated by secant steps on ``g(T) - T``, from the
    film temperature of ``near`` (a neighbouring point's record on the same oil, the first
    step along its ``residual_slope`` if it has one; else the oil's), until it moves by
    less than ``settings.tol``; returns ``(levels, lubricant, record)`` with the record's
    temperatures [C] (``oil``, ``film``, ``asperity``), rises [K], power [W], iterations
    and ``residual_slope`` (d(g - T)/dT [-], for the next point), or raises
    :class:`ThermalNotConverged` with the history."""
    s, law, lubricant = thermal.settings, thermal.law, point_lubricant(point)
    oil = float(law.temperature(lubricant.viscosity))
    same = bool(near) and near["oil_C"] == oil
    T = near["film_C"] if same else oil
    slope = near.get("residual_slope") if same else None
    previous, history, pairs = None, [], []
    for _ in range(s.max_iter):
        heated = replace(lubricant, viscosity=float(law.viscosity(T)))   # at the film's T
        levels = solve(heated, previous)
        levels = (thermal.tempered(levels[0], point, T), *levels[1:])
        heat = thermal.heat(levels[0], point)
        target = oil + s.bulk_resistance * heat["power"] + heat["flash"]
        history.append(abs(target - T))
        if history[-1] < s.tol:
            spot = thermal.spot(levels[0], point)               # reported: once, at the end
            record = {"oil_C": oil, "film_C": T, "asperity_C": T + spot,
                      "bulk_rise_K": s.bulk_resistance * heat["power"],
                      "face_flash_K": heat["flash"], "spot_flash_K": spot,
                      "power_W": heat["power"], "pin_share": heat["pin_share"],
                      "spot_rise_K_Pa": spot_flash(abs(levels[0].speed),
                                                   point.surface_speeds, s),
                      "iterations": len(history),
                      "residual_slope": _slope([*pairs, (T, target - T)], slope)}
            return levels, heated, record
        pairs.append((T, target - T))
        T, previous = _next_temperature(pairs, slope), levels
    raise ThermalNotConverged(f"the film temperature did not settle within {s.tol:g} K in "
                              f"{s.max_iter} iterations (last change {history[-1]:.3g} K)",
                              history)


def point_lubricant(point):
    """The oil of an operating ``point`` (its ``lubricant``), or
    :class:`~fem_twin.errors.InputError` for anything without one."""
    lubricant = getattr(point, "lubricant", None)
    if not hasattr(lubricant, "viscosity") or not hasattr(point, "surface_speeds"):
        raise InputError("thermal_point: point: expected an OperatingPoint (its lubricant "
                         f"and surface speeds), got {type(point).__name__}")
    return lubricant


#: the slopes of ``g(T) - T`` a first step may take from a neighbour's record (``g'`` from
#: -4 to 0.8: a thinner oil heats less)
SLOPES = (-5.0, -0.2)


def _next_temperature(pairs, slope=None) -> float:
    """The secant root of ``r(T) = g(T) - T`` through the last two ``(T, r)`` pairs; first,
    the Newton step along a neighbour's ``slope`` (within :data:`SLOPES`), else the plain
    step ``T + r``, which is also taken where the secant is flat."""
    T, r = pairs[-1]
    if len(pairs) < 2:
        ok = slope is not None and SLOPES[0] <= slope <= SLOPES[1]
        return T - r / slope if ok else T + r
    T0, r0 = pairs[-2]
    return T + r if r == r0 else T - r * (T - T0) / (r - r0)


def _slope(pairs, previous=None):
    """``dr/dT`` of the last two ``(T, r)`` pairs, or ``previous`` with fewer."""
    if len(pairs) < 2 or pairs[-1][0] == pairs[-2][0]:
        return previous
    (T0, r0), (T, r) = pairs[-2:]
    return float((r - r0) / (T - T0))
