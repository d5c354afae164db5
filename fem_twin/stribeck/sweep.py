"""Speed sweeps of the macro solver: warm-started, checkpointed, resumable."""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..checks import arguments
from ..errors import InputError
from ..io.checkpoint import input_key, load_or_none
from ..io.mesh import write_pvd
from ..macro import Lubricant, MacroSettings, MixedResult
from ..macro.estimate import PARTS, friction_error
from ..macro.nested import coarsened, corrected, solve_nested
from ..macro.thermal import thermal_point
from ..micro.flow_factors import FlowFactors
from ..numerics.threads import one_thread
from .curve import StribeckCurve, hersey_number

#: a point's ``meta`` entry for C_f on the grids coarsened by two, four, ... (its nested
#: coarse solves, finest first; a float in older checkpoints: by two only)
COARSE_CF = "coarse_friction_coefficient"
#: the ``meta`` entry of a nested level kept as a checkpoint (``keep_level``): the key of
#: the sweep whose point solved it (its time is that point's)
LEVEL_OF = "level_of"
#: the ``meta`` entry of a point's share of its load carried below its factors' smallest
#: separation (:meth:`~fem_twin.macro.MixedResult.contact_load_below`), read without the
#: point's fields by the run's range check
LOAD_BELOW = "load_share_below_h0_min"


def point_file(folder, key: str, speed: float) -> Path:
    """The checkpoint of one Stribeck point: ``point_KEY_SPEED.npz`` in ``folder``."""
    return Path(folder) / f"point_{key}_{speed:.9e}.npz"


def point_files(folder, key: str = "*") -> list[Path]:
    """The Stribeck point checkpoints in ``folder`` (of the sweep ``key``, or all)."""
    return sorted(Path(folder).glob(f"point_{key}_*.npz"))


def point_key(path) -> str:
    """The sweep key of a point checkpoint (:func:`point_file`)."""
    return Path(path).name.split("_")[1]


def point_meta(path) -> tuple[dict, dict]:
    """``(scalars, meta)`` of a point checkpoint (:func:`point_file`) without its fields."""
    with np.load(path) as data:
        return json.loads(str(data["scalars"])), json.loads(str(data["meta"]))


def point_speed(path) -> float:
    """The sweep speed [m/s] in the name of a point checkpoint (:func:`point_file`)."""
    return float(Path(path).stem.rsplit("_", 1)[1])


@one_thread
@arguments(gap="field", spacing="pair", factors=FlowFactors, speeds="numbers", load="number", lubricant=Lubricant)
def stribeck_sweep(gap, spacing, factors: FlowFactors, speeds, *, load: float,
                   lubricant: Lubricant, diameter: float = 8e-3, face=None,
                   settings: MacroSettings = MacroSettings(), checkpoint=None, fields=None,
                   origin=(0.0, 0.0), progress: bool = False,
                   factors_key: str | None = None,
                   slide_to_roll: float | None = None,
                   error_estimate: bool = False, keep_level: int = 0,
                   guide: str | None = None, thermal=None) -> StribeckCurve:
    """C_f over ``speeds`` [m/s] at one viscosity (paper 3.2: from 2 m/s down to 0.01 m/s),
    each point warm from the previous one (give speeds fast to slow).

    ``checkpoint``: folder keeping every finished point, keyed by a hash of all inputs (a
    rerun loads them; ``factors_key``: a key of the factors' inputs to hash instead of
    their bits).  ``fields``: a VTU per speed and a PVD there.  ``slide_to_roll``: a ball
    on a disk, ``speeds`` the entrainment speeds.  ``error_estimate``: each point's C_f
    error (:func:`fem_twin.macro.estimate.friction_error`).  ``keep_level``: also keep
    each point's nested solve that many coarsenings down (:func:`level_key`), which a
    ``guide`` sweep (the patch band) starts from: ``x(U) = x_g(U) + x(U_prev) -
    x_g(U_prev)`` (:class:`_Guide`).  ``thermal``: a
    :class:`~fem_twin.macro.thermal.ContactThermal`, each point at the film temperature of
    its own heat.
    """
    speeds = np.asarray(speeds, float)
    if speeds.ndim != 1 or speeds.size == 0 or np.any(~(speeds > 0)):
        raise InputError("speeds must be a non-empty list of positive values [m/s]")
    if slide_to_roll is not None and not (0 < slide_to_roll <= 2):
        raise InputError(f"slide_to_roll must be in (0, 2], got {slide_to_roll}")
    gap = np.asarray(gap, float)
    inputs = (gap, spacing, factors if factors_key is None else factors_key, load, lubricant,
              settings, face, slide_to_roll, thermal)
    key = sweep_key(*inputs)
    folder = None if checkpoint is None else _folder(checkpoint)
    fields = None if fields is None else _folder(fields)
    kept = level_key(keep_level, *inputs) if keep_level and folder else None
    point = _Point(gap, spacing, factors, load, slide_to_roll, lubricant, face, settings,
                   thermal)
    guided = _Guide(folder, guide)
    # each point's numbers; its fields go to disk at once (a 2048^2 point holds 0.5 GB)
    records, entries, previous = [], [], ()
    for i, speed in enumerate(tqdm(speeds, desc=f"Stribeck mu0={lubricant.viscosity:g}",
                                   disable=not progress, unit="speed")):
        path = None if folder is None else point_file(folder, key, speed)
        res = None if path is None else load_or_none(path, MixedResult.load)
        coarser = []                        # the point on each coarsening of the grid
        if res is None:
            res, *coarser = point.solve(float(speed), guided.start(speeds, i, previous), path,
                                        (folder, kept, keep_level, key))
        if error_estimate and "error_estimate" not in res.meta:
            res = point.estimated(res, coarser, path)
        if fields is not None:
            vtu = res.write_vtu(fields / f"mu{lubricant.viscosity:g}_{i:03d}.vtu", origin)
            entries.append((float(res.speed), vtu))            # ParaView time = U [m/s]
        records.append(_record(res))
        previous = (res, *coarser)
    if fields is not None:
        write_pvd(fields / f"stribeck_mu{lubricant.viscosity:g}.pvd", entries)
    return _curve(records, speeds, lubricant.viscosity, diameter, load, error_estimate,
                  thermal is not None)


def _folder(path) -> Path:
    folder = Path(path)
    folder.mkdir(parents=True, exist_ok=True)
    return folder


class _Point:
    """One sweep point's solve (:func:`_solve_point`), with what the sweep keeps of it, and
    its C_f error estimate."""

    def __init__(self, gap, spacing, factors, load, slide_to_roll, lubricant, face,
                 settings, thermal):
        self.gap, self.spacing, self.factors, self.load = gap, spacing, factors, load
        self.slide_to_roll, self.lubricant, self.face = slide_to_roll, lubricant, face
        self.settings, self.thermal = settings, thermal

    def solve(self, speed, start, path, keep) -> tuple:
        """The levels of the point at ``speed`` warm from ``start``, checkpointed at
        ``path`` with its coarse C_f, and its level ``keep = (folder, key, level,
        sweep key)`` kept for a guided sweep."""
        res, *coarser = _solve_point(self.gap, self.spacing, self.factors, self.load, speed,
                                     self.slide_to_roll, self.lubricant, self.face,
                                     self.settings, start, self.thermal)
        meta = {LOAD_BELOW: res.contact_load_below(self.factors.h0[0])}
        if coarser:
            meta.update({COARSE_CF: [c.friction_coefficient for c in coarser],
                         "seconds_coarse": coarser[0].meta["seconds"]})
        res = replace(res, meta={**res.meta, **meta})
        if path is not None:
            res.save(path)
        folder, kept, level, key = keep
        if kept and len(coarser) >= level:
            replace(coarser[level - 1], meta={**coarser[level - 1].meta, LEVEL_OF: key}).save(
                point_file(folder, kept, speed))
        return (res, *coarser)

    def estimated(self, res, coarser, path):
        """``res`` with its C_f error estimate in ``meta`` (saved at ``path``)."""
        t0 = time.perf_counter()
        estimate = friction_error(res, self.gap, self.spacing, self.factors, load=self.load,
                                  lubricant=film_lubricant(res, self.lubricant),
                                  face=self.face, settings=self.settings,
                                  entrainment=res.meta.get("entrainment"), levels=coarser)
        res = replace(res, meta={**res.meta, "error_estimate": estimate,
                                 "seconds_estimate": time.perf_counter() - t0})
        if path is not None:
            res.save(path)
        return res


def _curve(records, speeds, viscosity, diameter, load, error_estimate, thermal):
    """The :class:`StribeckCurve` of a sweep's point ``records`` (:func:`_record`)."""
    get = lambda name: np.array([r[name] for r in records])  # noqa: E731
    errors = ({part: np.array([r["error_estimate"][part] for r in records])
               for part in (*PARTS, "total")} if error_estimate else None)
    temperature = ({k: get(k) for k in ("contact_temperature", "asperity_temperature")}
                   if thermal else {})
    return StribeckCurve(
        speed=speeds.copy(), **temperature,
        hersey=hersey_number(viscosity, speeds, diameter, load),
        friction_coefficient=get("friction_coefficient"), viscosity=viscosity,
        hydrodynamic_friction=get("hydrodynamic_friction"),
        boundary_friction=get("boundary_friction"),
        contact_load_fraction=get("contact_load") / load, h_d=get("h_d"),
        iterations=get("iterations"),
        friction_error=None if errors is None else errors.pop("total"),
        friction_error_parts=errors,
        coarse_friction_coefficient=_levels([r[COARSE_CF] for r in records]))


class _Guide:
    """The starts of a guided sweep (``stribeck_sweep``'s ``guide``), reading the guide's
    checkpoints in ``folder`` under the key ``guide`` (None: no guide).  The guide, a sweep
    with other flow factors (the patch band's: the average factors), carries the speed
    change and the previous point the factors' difference (the bundled case's 12 band
    sweeps at 64^2: 3163 Newton steps against 4379, C_f the same to 6e-5 C_f,b); where a
    guide point is missing the point starts from the previous one."""

    def __init__(self, folder, guide: str | None):
        self.folder, self.guide = folder, guide
        self.read = {}                      # the guide's points last read, by speed

    def start(self, speeds, i: int, previous: tuple) -> tuple:
        """The ``previous`` levels :func:`solve_nested` starts the point at ``speeds[i]``
        from (``previous``: the sweep's point at ``speeds[i - 1]``)."""
        if self.guide is None or self.folder is None:
            return previous
        here = self._point(speeds[i])
        if here is None:
            return previous
        if not previous:                    # the first point: the guide's own
            return (here,)
        before, own = self._point(speeds[i - 1]), previous[0]
        if before is None or before.pressure.shape != own.pressure.shape:
            return previous
        return (replace(corrected(here, before, own), meta=own.meta),)

    def _point(self, speed: float):
        """The guide's point at ``speed`` or None; the two last read are kept (a point is
        read as ``here``, then as ``before`` of the next speed)."""
        if speed not in self.read:
            last = dict(list(self.read.items())[-1:])
            self.read = {**last, speed: load_or_none(
                point_file(self.folder, self.guide, speed), MixedResult.load)}
        return self.read[speed]


def level_key(level: int, gap, spacing, factors, load, lubricant, settings, face,
              slide_to_roll=None, thermal=None) -> str:
    """The sweep key (:func:`sweep_key`) of these inputs on the grid coarsened ``level``
    times (:func:`~fem_twin.macro.nested.coarsened`): where ``keep_level`` checkpoints a
    sweep's nested solves."""
    for _ in range(level):
        gap, spacing, face = coarsened(gap, spacing, face)
    return sweep_key(gap, spacing, factors, load, lubricant, settings, face, slide_to_roll,
                     thermal)


def _solve_point(gap, spacing, factors, load, speed, slide_to_roll, lubricant, face,
                 settings, previous, thermal):
    """The levels ``(result, *coarser)`` of :func:`solve_nested` at the sweep ``speed``
    (sliding, or entrainment at ``slide_to_roll``), warm from ``previous``; with a
    ``thermal`` model at the film temperature of its own heat (the record in the result's
    ``meta["thermal"]``)."""
    sliding = dict(speed=speed) if slide_to_roll is None else dict(
        speed=slide_to_roll * speed, entrainment=speed)

    def solve(lub, start):
        return solve_nested(gap, spacing, factors, load=load, **sliding, lubricant=lub,
                            face=face, settings=settings, previous=start or previous)

    if thermal is None:
        return solve(lubricant, None)
    u_m = sliding.get("entrainment", speed / 2)
    surfaces = (u_m - sliding["speed"] / 2, u_m + sliding["speed"] / 2)
    start = time.perf_counter()
    levels, film, record = thermal_point(solve, lubricant, thermal, factors, surfaces,
                                         previous[0].meta.get("thermal") if previous
                                         else None)
    record["viscosity_Pa_s"] = film.viscosity
    last = sum(level.meta["seconds"] for level in levels)     # the final iteration's solves
    return (replace(levels[0], meta={**levels[0].meta, "thermal": record,
                                     "seconds_thermal": time.perf_counter() - start - last}),
            *levels[1:])


def film_lubricant(res: MixedResult, lubricant):
    """The lubricant a point's film had: ``lubricant`` at the point's film viscosity when a
    thermal model set it (``meta["thermal"]``), else ``lubricant``."""
    record = res.meta.get("thermal")
    return lubricant if record is None else replace(lubricant,
                                                    viscosity=record["viscosity_Pa_s"])


def _record(res: MixedResult) -> dict:
    """The numbers of a point the curve keeps (no fields)."""
    return {**{name: getattr(res, name) for name in (
        "friction_coefficient", "hydrodynamic_friction", "boundary_friction", "contact_load",
        "h_d", "iterations")}, COARSE_CF: np.atleast_1d(res.meta.get(COARSE_CF, np.nan)),
        "error_estimate": res.meta.get("error_estimate"),
        "contact_temperature": res.meta.get("thermal", {}).get("film_C", np.nan),
        "asperity_temperature": res.meta.get("thermal", {}).get("asperity_C", np.nan)}


def _levels(rows) -> np.ndarray:
    """C_f of each point on each coarsened grid as ``(levels, points)``, NaN where a point
    has no such level (a failed coarse solve leaves it and the coarser ones out)."""
    out = np.full((max(len(r) for r in rows), len(rows)), np.nan)
    for j, r in enumerate(rows):
        out[:len(r), j] = r
    return out


def sweep_key(gap, spacing, factors, load, lubricant, settings, face,
              slide_to_roll=None, thermal=None) -> str:
    """Key of a sweep's checkpoints (``point_KEY_*.npz``): a hash of all its inputs, with
    ``factors`` a :class:`FlowFactors` or a key string of their inputs."""
    flow = ((factors.h0, factors.h_m, factors.p_con, factors.A, factors.b, factors.C,
             factors.d, factors.friction_factor, factors.pressure_friction)
            if isinstance(factors, FlowFactors) else (str(factors),))
    inputs = [load, lubricant.__dict__, settings.__dict__]
    if slide_to_roll is not None:
        inputs.append(slide_to_roll)
    if thermal is not None:
        inputs.append([thermal.settings.__dict__, thermal.law.__dict__,
                       thermal.boundary_friction])
    return input_key(np.asarray(gap, float), np.asarray(spacing, float), *flow,
                     None if face is None else np.asarray(face, bool), inputs, length=12)
