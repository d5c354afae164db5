"""The mixed regime against a deterministic solution on the same roughness (docs/accuracy.md,
"The mixed regime against a deterministic solution").

A crowned square pad carries a roughness cell (the composite ``disk - pin`` of a patch pair,
on the pin at rest; the disk smooth and sliding along +x1) tiled ``n`` times per side, so the
wavelength ratio is ``eps = 1/n``.
:func:`fem_twin.macro.reference.deterministic.solve_deterministic` solves it resolved; the
twin solves the same pad with the flow factors of that cell
(:func:`fem_twin.micro.homogenise`) on a macro grid.  With both bodies rough (``RoughPad.disk``,
the configuration of every run) the pin carries its cell tiled and the disk's cell slides
over it, :func:`fem_twin.macro.reference.time_resolved.solve_time_resolved` resolves it in
time and the twin takes the unsteady cells of the pair (eq 8 with its time term, one pixel a
step).
The pad grows with ``n`` at a fixed mean pressure and crown, and the speed falls as
``1/n``: ``mu U L / (p h^2)`` and the load share are then the same problem at every
``eps`` (the macro deformation, ``p L / E'``, is below a picometre), and the film's
friction coefficient scales as ``h / L``."""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from ..checks import arguments, check, plausible, whole
from ..errors import InputError
from ..io.files import read_topography
from ..macro import Lubricant, MacroSettings, MixedResult, solve_mixed
from ..macro.laws.boundary_friction import temperature_factor
from ..macro.laws.thermal import tempered
from ..macro.reference.deterministic import (
    DeterministicResult,
    DeterministicSettings,
    solve_deterministic,
)
from ..macro.reference.time_resolved import solve_time_resolved
from ..micro import FlowFactors, homogenise
from ..peers import average_flow_factors
from ..topography import Topography, resample_cell
from ..topography.prepare import prepare_patch

#: the pads' tile counts of ``benchmarks/run.py deterministic`` (eps = 1/2 .. 1/16)
TILES = (2, 4, 8, 16)
#: the pad's forms (``RoughPad.profile``)
PROFILES = ("crown", "wedge")


@dataclass(frozen=True)
class RoughPad:
    """A crowned square pad with a tiled roughness cell (SI units).

    Attributes
    ----------
    roughness : (m, m) periodic ``disk - pin`` heights of the cell [m], zero mean
    pitch : its pixel pitch [m]
    lubricant : both solvers' oil
    settings : the deterministic solver's materials, cut-off and C_f,b
        which the twin's cells and macro scale take too
    crown : the form's rise from the centre to the edges' middle [m] (a paraboloid)
    mean_pressure : load over the pad's area [Pa]
    macro_nodes : the twin's macro grid per side
    disk : (m, m) the disk's cell [m], zero mean, or None (the disk smooth); the pin's is
        then ``disk - roughness``
    profile : the form, ``"crown"`` (a paraboloid, its outlet half cavitates) or
        ``"wedge"`` (a plane converging along x1 from ``2 crown`` to 0: no macro cavity)
    """

    roughness: np.ndarray
    pitch: float
    lubricant: Lubricant
    settings: DeterministicSettings = field(default_factory=DeterministicSettings)
    crown: float = 1e-6
    mean_pressure: float = 1e6
    macro_nodes: int = 65
    disk: np.ndarray | None = None
    profile: str = "crown"

    def __post_init__(self):
        if self.profile not in PROFILES:
            raise InputError(f"profile must be one of {PROFILES}, got {self.profile!r}")
        if not isinstance(self.lubricant, Lubricant) or not isinstance(
                self.settings, DeterministicSettings):
            raise InputError("RoughPad: lubricant must be a Lubricant and settings "
                             "DeterministicSettings")
        plausible("RoughPad.pitch [m]", self.pitch, "pitch")
        plausible("RoughPad.crown [m]", self.crown, "height")
        plausible("RoughPad.mean_pressure [Pa]", self.mean_pressure, "pressure_scale")
        whole("RoughPad.macro_nodes", self.macro_nodes, "nodes")
        for name in ("roughness", "disk"):
            r = getattr(self, name)
            if r is None and name == "disk":
                continue
            check(f"RoughPad.{name} [m]", r, "numbers")
            r = np.asarray(r, float)
            if r.ndim != 2 or r.shape[0] != r.shape[1] or not np.all(np.isfinite(r)):
                raise InputError(f"{name} must be a finite square (m, m) cell [m]")
            plausible(f"RoughPad.{name} [m] (its height range)", float(np.ptp(r)) or 1e-8,
                      "height")
            object.__setattr__(self, name, r - r.mean())
        if self.disk is not None and self.disk.shape != self.roughness.shape:
            raise InputError("disk and roughness must be cells of one shape")

    def length(self, tiles: int) -> float:
        """The side of the pad of ``tiles`` cells a side [m]."""
        return whole("tiles", tiles, "samples") * self.roughness.shape[0] * self.pitch

    def load(self, tiles: int) -> float:
        """The load [N] of the pad of ``tiles`` cells a side."""
        return self.mean_pressure * self.length(tiles) ** 2

    def form(self, nodes: int) -> np.ndarray:
        """The form on ``nodes`` x ``nodes`` nodes spanning the pad [m]: the crown, 0 at
        its centre, or the wedge, 0 at its outlet."""
        xi = np.linspace(-1.0, 1.0, nodes)
        if self.profile == "wedge":
            return np.tile(self.crown * (1 - xi), (nodes, 1))
        return self.crown * (xi[None, :] ** 2 + xi[:, None] ** 2)

    def resolved(self, tiles: int):
        """``(shape, spacing)`` of the deterministic pad: the crown plus the tiled cell on
        ``tiles m + 1`` nodes a side (the cell's period closed)."""
        tiles = whole("tiles", tiles, "samples")
        tiled = np.pad(np.tile(self.roughness, (tiles, tiles)), ((0, 1), (0, 1)), mode="wrap")
        return self.form(tiled.shape[0]) + tiled, (self.pitch, self.pitch)

    def moving(self, tiles: int):
        """``(shape, strip, spacing)`` of the time-resolved pad (both bodies rough): the
        crown less the pin's tiled cell on ``tiles m + 1`` nodes a side, and the disk's cell
        tiled across x2 as one period along x1
        (:func:`~fem_twin.macro.reference.time_resolved.disk_at`)."""
        if self.disk is None:
            raise InputError("the pad's disk is smooth: RoughPad.resolved is its pad")
        tiles = whole("tiles", tiles, "samples")
        pin = np.tile(self.disk - self.roughness, (tiles, tiles))
        pin = np.pad(pin, ((0, 1), (0, 1)), mode="wrap")
        strip = np.pad(np.tile(self.disk, (tiles, 1)), ((0, 1), (0, 0)), mode="wrap")
        return self.form(pin.shape[0]) - pin, strip, (self.pitch, self.pitch)

    def macro(self, tiles: int):
        """``(gap, spacing)`` of the twin's pad: the crown on ``macro_nodes`` a side."""
        step = self.length(tiles) / (self.macro_nodes - 1)
        return self.form(self.macro_nodes), (step, step)


@arguments(pin=Topography, disk=Topography, lubricant=Lubricant)
def patch_pad(pin: Topography, disk: Topography, pixels: int, lubricant: Lubricant,
              moving: bool = False, **options) -> RoughPad:
    """The :class:`RoughPad` of a prepared patch pair (``disk`` flipped over ``pin``,
    :func:`fem_twin.topography.prepare.prepare_patch`) resampled periodically to ``pixels``
    a side (:func:`fem_twin.topography.resample_cell`, as the micro stage does); ``moving``:
    both bodies rough, the disk's roughness sliding (``RoughPad.disk``)."""
    pixels = whole("pixels", pixels, "pixels")
    low, up = resample_cell(pin, (pixels, pixels)), resample_cell(disk, (pixels, pixels))
    return RoughPad(up.heights - low.heights, float(low.spacing[0]), lubricant,
                    disk=up.heights if moving else None, **options)


@arguments(folder="path", lubricant=Lubricant)
def sample_pad(folder, pixels: int = 32, pair: int = 1, lubricant: Lubricant | None = None,
               **options) -> RoughPad:
    """The :class:`RoughPad` of patch pair ``pair`` of the bundled sample (``folder``: the
    repository's ``meshes/sample``), cut at 256 px as the bundled case does; ``lubricant``
    default: the bundled case's oil at 24 C (0.066 Pa s, eqs 23-24 of Table 6); ``moving``
    (an option of :func:`patch_pad`): both bodies rough."""
    folder = Path(folder)
    pin = prepare_patch(read_topography(folder / f"patch_{pair}_pin.npz"))
    disk = prepare_patch(read_topography(folder / f"patch_{pair}_disk.npz"), upper=True)
    return patch_pad(pin, disk, pixels, lubricant or Lubricant(0.066), **options)


@arguments(pad=RoughPad, h0="numbers")
def pad_factors(pad: RoughPad, h0, **cell):
    """The twin's flow factors of the pad's cell at the separations ``h0`` [m], with the
    pad's materials and film cut-off: the roughness on the pin at rest, the disk smooth
    (one instant: a steady cell), or, with ``pad.disk``, both rough and the disk's sliding
    one pixel a step (eq 8 unsteady); ``cell``: other :class:`~fem_twin.micro.CellSettings`."""
    s, dx = pad.settings, (pad.pitch, pad.pitch)
    if pad.disk is None:
        pin, disk, steps = -pad.roughness, np.zeros_like(pad.roughness), 1
    else:
        pin, disk, steps = pad.disk - pad.roughness, pad.disk, pad.roughness.shape[1]
    return homogenise(Topography(pin, dx), Topography(disk, dx), h0,
                      **{"steps": steps, **cell}, e_reduced=s.e_reduced,
                      hardness=s.hardness, boundary_film=s.boundary_film,
                      gap_floor=s.gap_floor, error_estimate=False)


@arguments(pad=RoughPad)
def pad_average_flow(pad: RoughPad):
    """The statistical peer's flow factors of the pad's cell
    (:func:`fem_twin.peers.average_flow_factors`): the same bodies as :func:`pad_factors`
    (the roughness on the pin, or both rough with ``pad.disk``), the pad's E'."""
    dx = (pad.pitch, pad.pitch)
    pin, disk = ((-pad.roughness, np.zeros_like(pad.roughness)) if pad.disk is None
                 else (pad.disk - pad.roughness, pad.disk))
    return average_flow_factors(Topography(pin, dx), Topography(disk, dx),
                                pad.settings.e_reduced)


def pad_speeds(speeds, tiles: int) -> np.ndarray:
    """The speeds [m/s] of the pad of ``tiles`` cells a side for ``speeds`` given at two
    tiles: ``U 2 / tiles``, the same ``mu U L`` at every eps."""
    plausible("speeds [m/s]", speeds, "speed")
    return np.atleast_1d(np.asarray(speeds, float)) * 2.0 / whole("tiles", tiles, "samples")


@arguments(pad=RoughPad, settings=DeterministicSettings)
def deterministic_sweep(pad: RoughPad, tiles: int, speeds, settings=None) -> list:
    """:func:`solve_deterministic` at each of ``speeds`` (given at two tiles,
    :func:`pad_speeds`), each started from the one before; ``settings`` replace the pad's."""
    shape, dx = pad.resolved(tiles)
    out, last = [], None
    for u in pad_speeds(speeds, tiles):
        last = solve_deterministic(shape, dx, load=pad.load(tiles), speed=u,
                                   lubricant=pad.lubricant,
                                   settings=settings or pad.settings, initial=last)
        out.append(last)
    return out


@arguments(pad=RoughPad, settings=DeterministicSettings)
def time_resolved_sweep(pad: RoughPad, tiles: int, speeds, settings=None, time=None) -> list:
    """:func:`~fem_twin.macro.reference.time_resolved.solve_time_resolved` on the pad of ``tiles``
    (both bodies rough) at each of ``speeds`` (given at two tiles), each started from the
    one before; ``settings`` replace the pad's, ``time``: its
    :class:`~fem_twin.macro.reference.time_resolved.TimeSettings`."""
    shape, strip, dx = pad.moving(tiles)
    out, last = [], None
    for u in pad_speeds(speeds, tiles):
        last = solve_time_resolved((shape, strip), dx, load=pad.load(tiles), speed=u,
                                   lubricant=pad.lubricant, settings=settings or pad.settings,
                                   time=time, initial=last)
        out.append(last)
    return out


@arguments(pad=RoughPad, factors=FlowFactors)
def twin_sweep(pad: RoughPad, tiles: int, speeds, factors) -> list:
    """The twin's points (:func:`fem_twin.macro.solve_mixed`) on the same pad, loads and
    speeds, with ``factors`` of the pad's cell (:func:`pad_factors`); the face is the pad."""
    gap, dx = pad.macro(tiles)
    s = pad.settings
    settings = MacroSettings(e_reduced=s.e_reduced, boundary_friction=s.boundary_friction,
                             boundary=s.boundary, ambient_pressure=0.0,
                             cavitation_pressure=0.0, tol=1e-7)
    out, last = [], None
    t = temperature_factor(s.boundary, s.temperature)       # the oil's, as the pad's
    for u in pad_speeds(speeds, tiles):
        last = tempered(solve_mixed(gap, dx, factors, load=pad.load(tiles), speed=u,
                                    lubricant=pad.lubricant, settings=settings,
                                    initial=last), t)
        out.append(last)
    return out


@dataclass(frozen=True)
class Pair:
    """One compared point: ``tiles``, ``speed`` [m/s], the load share [-], the separation
    h_d [m], the film friction [N] and C_f [-] of the deterministic solution (``*_det``)
    and of the twin."""

    tiles: int
    speed: float
    share_det: float
    share: float
    separation_det: float
    separation: float
    film_det: float
    film: float
    cf_det: float
    cf: float

    def cf_gap(self, boundary_friction: float) -> float:
        """C_f - C_f,det in units of C_f,b [-]."""
        return (self.cf - self.cf_det) / boundary_friction


@arguments(det=list, twin=list, tiles="number")
def compared(det: list, twin: list, tiles: int) -> list:
    """The :class:`Pair` of each speed of two sweeps on the pad of ``tiles``: ``det`` the
    deterministic results (:func:`deterministic_sweep`), ``twin`` the twin's
    (:func:`twin_sweep`), a whole number of ``tiles``."""
    tiles = whole("compared: tiles", tiles, "samples")
    for name, results, kind in (("det", det, DeterministicResult), ("twin", twin, MixedResult)):
        check(f"compared: {name}", results, list)
        for r in results:
            check(f"compared: {name}", r, kind)
    return [Pair(tiles, d.speed, d.load_share, t.contact_load / t.normal_load, d.separation,
                 t.h_d, d.film_friction, t.hydrodynamic_friction, d.friction_coefficient,
                 t.friction_coefficient) for d, t in zip(det, twin)]


@arguments(pairs=[Pair], boundary_friction="number")
def summary(pairs, boundary_friction: float, label: str = "mixed regime",
            order: float | None | bool = False) -> str:
    """The one line of a benchmark group (``deterministic``: ``label`` "mixed regime";
    ``unsteady``): the largest C_f gap [% C_f,b] and load-share gap over ``pairs``
    (:class:`Pair`), the largest resolved share [%], and with ``order`` (not False) the
    observed eps -> 0 order (:func:`order_text`); ``boundary_friction`` C_f,b, a friction
    coefficient."""
    plausible("summary: boundary_friction", boundary_friction, "friction")
    cf = max(abs(p.cf_gap(boundary_friction)) for p in pairs)
    share = max(abs(p.share - p.share_det) for p in pairs)
    line = (f"{label}: worst |C_f - C_f,det| = {100 * cf:.2f} % C_f,b, worst |share - "
            f"share,det| = {share:.3f}, at {100 * max(p.share_det for p in pairs):.0f} % "
            "asperity load")
    return line if order is False else f"{line}, eps -> 0 {order_text(order)}"


def order_text(order: float | None) -> str:
    """``"order 1.52"``, or ``"order none observed"`` for :func:`to_zero`'s None."""
    if order is not None:
        check("order_text: order", order, "number")
    return "order none observed" if order is None else f"order {order:.2f}"


@arguments(eps="numbers", values="numbers")
def to_zero(eps, values) -> tuple[float, float | None]:
    """``(value at eps -> 0, observed order)`` from the values at the three finest ``eps``:
    Richardson with the order their differences show where they shrink monotonically;
    where they do not (a sign change, growth) or only two values are given, no order is
    observed: ``(the finest value, None)``, nothing extrapolated (an assumed order is not a
    measurement)."""
    e, v = np.asarray(eps, float), np.asarray(values, float)
    if e.ndim != 1 or e.size < 1 or e.shape != v.shape:
        raise InputError("to_zero: give as many values as eps, at least one")
    order = np.argsort(e)
    e, v = e[order], v[order]
    if len(e) >= 3:
        d1, d2 = v[1] - v[0], v[2] - v[1]
        if d1 * d2 > 0 and abs(d2) > abs(d1):
            p = np.log(abs(d2 / d1)) / np.log(e[2] / e[1])
            return float(v[0] - d1 / ((e[1] / e[0]) ** p - 1)), float(p)
    return float(v[0]), None


@arguments(pad=RoughPad)
def with_settings(pad: RoughPad, **changes) -> RoughPad:
    """The pad with its deterministic settings changed (``film_deforms``, ``boundary_film``,
    any field of :class:`~fem_twin.macro.reference.deterministic.DeterministicSettings`)."""
    unknown = sorted(set(changes) - {f.name for f in fields(DeterministicSettings)})
    if unknown:
        raise InputError(f"with_settings: {', '.join(unknown)}: not a setting of "
                         "DeterministicSettings ("
                         f"{', '.join(f.name for f in fields(DeterministicSettings))})")
    return replace(pad, settings=replace(pad.settings, **changes))
