"""Speed sweeps of the macro solver: warm-started, checkpointed, resumable."""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..checks import check
from ..io.checkpoint import check_made_for, load_or_none, made_for
from ..io.mesh import write_pvd
from ..macro import MixedResult
from ..macro.estimate import FILM, PARTS, friction_error, is_current, signed_total
from ..macro.laws.boundary_friction import temperature_factor
from ..macro.laws.thermal import tempered, thermal_point
from ..macro.nested import corrected, solve_nested
from ..numerics.threads import one_thread
from .curve import StribeckCurve, hersey_number
from .request import SweepRequest

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
#: the ``meta`` entry of a point solved as a task of its own, started from its guide's point
#: (``stages.sweeps.guided_points``): the guide's key, which the run's task graph reads
GUIDED_BY = "guided_by"


def point_file(folder, key: str, speed: float) -> Path:
    """The checkpoint of one Stribeck point: ``point_KEY_SPEED.npz`` in ``folder``."""
    return Path(folder) / f"point_{key}_{speed:.9e}.npz"


def point_files(folder, key: str = "*") -> list[Path]:
    """The Stribeck point checkpoints in ``folder`` (of the sweep ``key``, or all)."""
    return sorted(Path(folder).glob(f"point_{key}_*.npz"))


def load_point(path, key: str, speed: float):
    """The :class:`~fem_twin.macro.MixedResult` checkpointed at ``path`` for the sweep
    ``key`` at ``speed``, or None: missing, damaged, or made for another key or speed (set
    aside, :func:`fem_twin.io.checkpoint.check_made_for`)."""
    def loader(p):
        res = MixedResult.load(p)
        check_made_for(res.meta, key, speed, p)
        return res
    return load_or_none(path, loader)


def checkpointed(folder, key: str, speed: float) -> bool:
    """Whether the point of the sweep ``key`` at ``speed`` is checkpointed in ``folder``:
    its file exists and its metadata reads and names it; a damaged or foreign file is set
    aside (:func:`fem_twin.io.checkpoint.load_or_none`) and the point counts as missing."""
    def loader(path):
        check_made_for(point_meta(path)[1], key, speed, path)
        return True
    return bool(load_or_none(point_file(folder, key, speed), loader))


def readable_meta(path) -> tuple[dict, dict] | None:
    """:func:`point_meta` of ``path``, or None where the file is damaged (then set aside)."""
    return load_or_none(path, point_meta)


def point_key(path) -> str:
    """The sweep key of a point checkpoint (:func:`point_file`)."""
    return Path(path).name.split("_")[1]


def point_meta(path) -> tuple[dict, dict]:
    """``(scalars, meta)`` of a point checkpoint (:func:`point_file`) without its fields."""
    with np.load(path) as data:
        return json.loads(str(data["scalars"])), json.loads(str(data["meta"]))


@one_thread
def stribeck_sweep(request: SweepRequest, progress: bool = False) -> StribeckCurve:
    """C_f over the ``request``'s speeds [m/s] at its viscosity (paper 3.2: from 2 m/s down
    to 0.01 m/s), each point warm from the previous one (speeds fast to slow), or from its
    guide's (:class:`_Guide`).  Every finished point is checkpointed under the request's
    :attr:`~fem_twin.stribeck.request.SweepRequest.key`, so a rerun loads it; with
    ``fields``, a VTU per speed and a PVD; with ``error_estimate``, each point's C_f error
    (:func:`fem_twin.macro.estimate.friction_error`)."""
    check("stribeck_sweep: request", request, SweepRequest)
    r = request
    key = r.key
    folder = None if r.checkpoint is None else _folder(r.checkpoint)
    fields = None if r.fields is None else _folder(r.fields)
    kept = r.level_key(r.keep_level) if r.keep_level and folder else None
    point, guided = _Point(r), _Guide(folder, r.guide)
    # each point's numbers; its fields go to disk at once (a 2048^2 point holds 0.5 GB)
    records, entries, previous = [], [], ()
    mu = r.lubricant.viscosity
    for i, speed in enumerate(tqdm(r.speeds, desc=f"Stribeck mu0={mu:g}",
                                   disable=not progress, unit="speed")):
        path = None if folder is None else point_file(folder, key, speed)
        res = None if path is None else load_point(path, key, speed)
        coarser = []                        # the point on each coarsening of the grid
        if res is None:
            res, *coarser = point.solve(float(speed), guided.start(r.speeds, i, previous),
                                        path, (folder, kept, r.keep_level, key))
        if r.error_estimate and not is_current(res.meta, r.settings):
            res = point.estimated(float(speed), res, coarser, path)
        if fields is not None:
            vtu = res.write_vtu(fields / f"mu{mu:g}_{i:03d}.vtu", r.origin)
            entries.append((float(res.speed), vtu))            # ParaView time = U [m/s]
        records.append(point_record(res))
        previous = (res, *coarser)
    if fields is not None:
        write_pvd(fields / f"stribeck_mu{mu:g}.pvd", entries)
    return curve_of_records(records, r)


def _folder(path) -> Path:
    folder = Path(path)
    folder.mkdir(parents=True, exist_ok=True)
    return folder


class _Point:
    """One sweep point's solve (:func:`_solve_point`), with what the sweep keeps of it, and
    its C_f error estimate."""

    def __init__(self, request: SweepRequest):
        self.request = request

    def solve(self, speed, start, path, keep) -> tuple:
        """The levels of the point at ``speed`` warm from ``start``, checkpointed at
        ``path`` with its coarse C_f, and its level ``keep = (folder, key, level,
        sweep key)`` kept for a guided sweep."""
        r = self.request
        folder, kept, level, key = keep
        res, *coarser = _solve_point(r, speed, start)
        meta = {LOAD_BELOW: res.contact_load_below(r.factors.h0[0]), **made_for(key, speed)}
        if r.guide is not None and r.speeds.size == 1:          # a task of its own
            meta[GUIDED_BY] = r.guide
        if coarser:
            meta.update({COARSE_CF: [c.friction_coefficient for c in coarser],
                         "seconds_coarse": coarser[0].meta["seconds"]})
        res = replace(res, meta={**res.meta, **meta})
        if path is not None:
            res.save(path)
        if kept and len(coarser) >= level:
            replace(coarser[level - 1], meta={**coarser[level - 1].meta, LEVEL_OF: key,
                                              **made_for(kept, speed)}).save(
                point_file(folder, kept, speed))
        return (res, *coarser)

    def estimated(self, speed, res, coarser, path):
        """``res``, the point at the sweep ``speed``, with its C_f error estimate in
        ``meta`` (saved at ``path``)."""
        t0, r = time.perf_counter(), self.request
        point = replace(r.operating_point(speed), lubricant=film_lubricant(res, r.lubricant))
        estimate = friction_error(res, point, coarser)
        res = replace(res, meta={**res.meta, "error_estimate": estimate,
                                 "seconds_estimate": time.perf_counter() - t0})
        if path is not None:
            res.save(path)
        return res


def curve_of_records(records, request: SweepRequest) -> StribeckCurve:
    """The :class:`StribeckCurve` of a sweep's point ``records`` (:func:`point_record`, one
    per speed of ``request``), C_f, its error estimates and the Hersey number referred to
    the imposed load (each point's C_f is its face's, ``load_share`` of it).  The sweep
    builds it from its solved points, the stages from a checkpoint index's scalars."""
    get = lambda name: np.array([r[name] for r in records])  # noqa: E731
    share = request.load_share
    errors = ({part: share * np.array([r["error_estimate"][part] for r in records])
               for part in (*PARTS, FILM, "total")} if request.error_estimate else None)
    thermal = ({k: get(k) for k in ("contact_temperature", "asperity_temperature",
                                    "spot_rise")} if request.thermal is not None else {})
    speeds, mu, load = request.speeds, request.lubricant.viscosity, request.load
    return StribeckCurve(
        speed=speeds.copy(), **thermal, asperity_load=get("asperity_load"),
        real_contact_area=get("real_contact_area"),
        hersey=hersey_number(mu, speeds, request.hersey_length, load),
        friction_coefficient=share * get("friction_coefficient"), viscosity=mu,
        hydrodynamic_friction=get("hydrodynamic_friction"),
        boundary_force=get("boundary_force"),
        contact_load_fraction=get("contact_load") / request.face_load, h_d=get("h_d"),
        iterations=get("iterations"),
        friction_error=None if errors is None else errors.pop("total"),
        film_sensitivity=None if errors is None else errors.pop(FILM),
        friction_error_signed=None if errors is None else share * np.array(
            [signed_total(r["error_estimate"]) for r in records]),
        friction_error_parts=errors,
        coarse_friction_coefficient=share * _levels([r[COARSE_CF] for r in records]))


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
            self.read = {**last, speed: load_point(
                point_file(self.folder, self.guide, speed), self.guide, speed)}
        return self.read[speed]


def _solve_point(request: SweepRequest, speed: float, previous):
    """The levels ``(result, *coarser)`` of :func:`solve_nested` at the sweep ``speed``
    (sliding, or entrainment, by the request's motion), warm from ``previous``; with a
    ``thermal`` model at the film temperature of its own heat (the record in the result's
    ``meta["thermal"]``)."""
    r = request
    point = r.operating_point(speed)

    def solve(lub, start):
        return solve_nested(replace(point, lubricant=lub), start or previous)

    if r.thermal is None:
        levels = solve(r.lubricant, None)
        if r.oil_temperature is None:
            return levels
        t = temperature_factor(r.settings.boundary, r.oil_temperature)
        return (tempered(levels[0], t), *levels[1:])
    start = time.perf_counter()
    levels, film, record = thermal_point(solve, point, r.thermal,
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


def point_record(res: MixedResult) -> dict:
    """The numbers of a point ``res`` its curve keeps, by name (no fields): its C_f and
    force parts, film and iterations, coarsened C_f, error estimate and thermal readings
    (NaN without them), what :func:`curve_of_records` reads.  ``res`` may be anything
    with those attributes and a ``meta``: a checkpointed point's scalars."""
    return {**{name: getattr(res, name) for name in (
        "friction_coefficient", "hydrodynamic_friction", "boundary_force", "contact_load",
        "h_d", "iterations")}, COARSE_CF: np.atleast_1d(res.meta.get(COARSE_CF, np.nan)),
        "error_estimate": res.meta.get("error_estimate"),
        "asperity_load": res.asperity_load, "real_contact_area": res.real_contact_area,
        "contact_temperature": res.meta.get("thermal", {}).get("film_C", np.nan),
        "asperity_temperature": res.meta.get("thermal", {}).get("asperity_C", np.nan),
        "spot_rise": res.meta.get("thermal", {}).get("spot_rise_K_Pa", np.nan)}


def _levels(rows) -> np.ndarray:
    """C_f of each point on each coarsened grid as ``(levels, points)``, NaN where a point
    has no such level (a failed coarse solve leaves it and the coarser ones out)."""
    out = np.full((max(len(r) for r in rows), len(rows)), np.nan)
    for j, r in enumerate(rows):
        out[:len(r), j] = r
    return out
