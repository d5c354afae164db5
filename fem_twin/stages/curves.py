"""The Stribeck side of the main job: one warm-started sweep per viscosity with the C_f
error estimates, refinement passes where the curve turns, the patch scatter band, and what
is written of them (CSV, plots, fields, ``results.nc``, ``fields.nc``, validation)."""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..case import Case
from ..io.layout import RunLayout
from ..io.mesh import write_pvd
from ..io.writers import Writers
from ..macro import MixedResult
from ..macro.figures import plot_point_fields
from ..macro.reference.point_contact import PointContact, film_against_hamrock_dowson
from ..micro import FlowFactors
from ..stribeck import plot_stribeck, read_measured_csv, write_stribeck_csv
from ..stribeck.accuracy import error_summary, range_summary
from ..stribeck.analysis import defect_corrected, hersey_collapse, patch_band, transition_speeds
from ..stribeck.curve import plot_temperatures
from ..stribeck.parts import plot_parts
from ..stribeck.request import SweepRequest
from ..stribeck.sweep import LOAD_BELOW, point_file, point_files, point_key
from ..stribeck.validation import validate_curves
from .geometry import ball_contact, ball_grid
from .provenance import provenance
from .requests import per_viscosity, sweep_request
from .sweeps import guide_of, run_sweeps

log = logging.getLogger("fem_twin")


@dataclass(frozen=True)
class CurveStage:
    """What the Stribeck stage reads of its ``case``, once (:meth:`of`): the main sweeps'
    ``request`` (the first viscosity over the sweep's speeds, checkpointed in ``out``), the
    band's grid ``band_level`` (the macro grid's coarsenings,
    :meth:`~fem_twin.case.Case.band_coarsening`; 0 without the band), the band's sweeps
    ``band`` (:func:`band_tasks`, over the request's speeds; none without the band) and a
    ball's ``contact`` (:func:`~fem_twin.stages.geometry.ball_contact`; None for a pin).
    C_f,b and the Hersey length are the request's."""

    case: Case
    out: RunLayout
    request: SweepRequest
    band_level: int
    band: tuple
    contact: PointContact | None

    @classmethod
    def of(cls, case: Case, out: RunLayout) -> CurveStage:
        request = sweep_request(case, out)
        level = case.band_coarsening(request.gap.shape) if case.run.patch_band else 0
        return cls(case, out, request, level, tuple(band_tasks(case, out, request, level)),
                   ball_contact(case) if case.tribometer.ball else None)

    @property
    def boundary_friction(self) -> float:
        """C_f,b of eq 32, the request's: the scale of C_f,dev (eq 35), of the refinement's
        step and of the C_f error summary."""
        return self.request.settings.boundary_friction

    def at(self, speeds) -> CurveStage:
        """This stage with its main and band sweeps over ``speeds`` [m/s]."""
        return replace(self, request=replace(self.request, speeds=speeds),
                       band=tuple(replace(task, speeds=speeds) for task in self.band))

    def main_tasks(self, **changes) -> list:
        """The main sweeps, one per viscosity, with their C_f error estimates; ``changes``:
        fields set otherwise (:func:`dataclasses.replace`)."""
        return per_viscosity(self.case, replace(self.request, error_estimate=True, **changes))


def stribeck_curves(case: Case, out: RunLayout, executor=None, progress: bool = True,
                    writers: Writers | None = None) -> dict:
    """One Stribeck sweep per viscosity (in parallel on ``executor``), refined where the
    curve turns, and the patch scatter band (``[run] patch_band``); CSV, plots, fields,
    ``results.nc`` and ``fields.nc``.  Returns the stage's summary.  The figures and
    NetCDF files are written on ``writers`` (the caller waits for them), or on the
    executor's workers and waited for here; the fields' as soon as the main curves are
    done, beside the band's sweeps."""
    own = writers is None
    writers = Writers(executor) if own else writers
    (curves, points), stage = refined_curves(CurveStage.of(case, out), executor, progress)
    tasks = stage.main_tasks()
    writers.write(write_fields, case, out, field_sweeps(tasks, points),   # beside the band
                  stage.request.origin)
    band_swept = run_sweeps(list(stage.band), executor, progress, desc="patch band points")
    patch_curves, extra = band_curves(stage, curves, band_swept.curves, executor, progress)
    band = patch_band(patch_curves) if patch_curves else None
    _prune_points(out.points, [*tasks, *stage.band, *(t for added, _ in extra for t in added)])
    write_stribeck_csv(out.stribeck_csv, curves, band, law=case.boundary)
    summary = _summary(stage, curves, band)
    writers.write(write_run_results, case, out, curves, patch_curves)
    plot_curves(stage, curves, band, writers)
    summary["h0_range"] = _range_check([(tasks, points), (stage.band, band_swept.points),
                                        *extra])
    _log_points(curves)
    if len(curves) > 1:
        summary["hersey_collapse_max_abs_cf_dev"] = hersey_collapse(curves,
                                                                    stage.boundary_friction)
    if stage.contact is not None:
        summary["ehl_film"] = ehl_film(stage, points)
    if any(case.measured):
        summary["validation"] = validate_curves(
            curves, case.measured, stage.boundary_friction, curve_labels(case, curves),
            out.validation_csv, out.validation_png)
    if own:
        writers.wait()
    return summary


def refined_curves(stage: CurveStage, executor=None, progress: bool = True):
    """The main curves (with their C_f error estimates) of the ``stage``'s sweeps, then
    ``[sweep] refine`` passes adding the midpoints where C_f jumps; ``(swept, stage)``,
    ``swept`` the last pass's (:class:`~fem_twin.stages.sweeps.Swept`: its curves, read
    from the index of their points) and ``stage`` over its speeds.  The last pass runs
    each sweep whole (``run_sweeps``' ``whole``).  With the patch band on, each point also
    keeps its solve on the band's grid (``keep_level``), which the band's sweeps start
    from; where that grid is the guides' (:meth:`~fem_twin.case.Case.band_after_guides`),
    each pass of the band runs beside the main points."""
    case, speeds = stage.case, stage.request.speeds
    step = case.sweep.refine_step * stage.boundary_friction
    beside = case.band_after_guides(stage.request.gap.shape)
    for level in range(case.sweep.refine + 1):
        last = level == case.sweep.refine
        here = stage.at(speeds)
        swept = run_sweeps(here.main_tasks(keep_level=stage.band_level), executor, progress,
                           followers=here.band if beside else (), whole=last)
        extra = transition_speeds(swept.curves, step)
        if last or extra.size == 0:
            return swept, here
        log.info("sweep refinement %d: %d speeds added where C_f changes by more than "
                 "%.3g", level + 1, extra.size, step)
        speeds = np.unique(np.r_[speeds, extra])[::-1]


def band_tasks(case: Case, out: RunLayout, request, level: int) -> list:
    """The sweep tasks of the scatter band (``[run] patch_band``): one per patch and
    viscosity, on the macro grid coarsened ``level`` times
    (:meth:`~fem_twin.case.Case.band_coarsening`), each guided by the average factors'
    points on that grid (the main sweeps' nested level, ``keep_level``;
    :func:`~fem_twin.stribeck.sweep.stribeck_sweep`), at the coupling tolerance
    ``[run] band_tol``."""
    sweeps = band_sweeps(case, out, request) if case.run.patch_band else []
    band = replace(request.settings, tol=case.run.band_tol)
    return [replace(task, settings=band, guide=replace(task, factors_key=request.factors_key,
                                                       factors=request.factors).key)
            for patch in sweeps for task in per_viscosity(case, patch.coarsened(level))]


def band_curves(stage: CurveStage, curves, swept, executor=None, progress: bool = True):
    """The single-patch curves of the scatter band, one list per patch over the
    viscosities, from the curves ``swept`` of the ``stage``'s band sweeps, and the sweeps
    added here as ``[(tasks, points)]`` (:func:`~fem_twin.stages.sweeps.point_index`).
    Swept on a coarsened grid, they are corrected by the main ``curves``' relative change
    to the full grid (:func:`~fem_twin.stribeck.analysis.defect_corrected`): the main
    sweeps' own points on that grid (their nested solves) give that change, or, where a
    point has none (a coarse solve that failed, checkpoints of an earlier version), the
    average factors are swept on the band's grid too."""
    n = len(stage.case.lubricant.viscosities)
    per_patch = [swept[i:i + n] for i in range(0, len(swept), n)]
    level = stage.band_level
    if not per_patch or level == 0:
        return per_patch, []
    coarse = [c.coarse_friction_coefficient for c in curves]
    if all(cf is not None and cf.shape[0] >= level and np.all(np.isfinite(cf[level - 1]))
           for cf in coarse):
        return defect_corrected(per_patch, curves, [
            replace(c, friction_coefficient=cf[level - 1])
            for c, cf in zip(curves, coarse)]), []
    average = per_viscosity(stage.case, stage.request.coarsened(level))
    coarse = run_sweeps(average, executor, progress, desc="patch band points")
    return defect_corrected(per_patch, curves, coarse.curves), [(average, coarse.points)]


def _summary(stage: CurveStage, curves, band) -> dict:
    case, out = stage.case, stage.out
    summary = {"curves": [{"viscosity_Pa_s": c.viscosity, "friction_coefficient_range": [
        float(c.friction_coefficient.min()), float(c.friction_coefficient.max())]}
        for c in curves], "friction": case.macro.friction, "load_N": case.tribometer.load,
        "files": [p.name for p in (out.stribeck_csv, out.stribeck_png("speed"),
                                   out.stribeck_png("hersey"), out.results, out.fields_nc,
                                   out.fields, *(out.fields_png(c.viscosity) for c in curves))]}
    if curves[0].contact_temperature is not None:
        summary["files"].append(out.temperature_png.name)
        for entry, c in zip(summary["curves"], curves):
            entry["contact_temperature_C_range"] = [float(np.min(c.contact_temperature)),
                                                    float(np.max(c.contact_temperature))]
    if band is not None:
        summary["patch_band_max_width"] = float(max(np.max(hi - lo) for lo, hi in band))
    summary["cf_error"] = error_summary(curves, stage.boundary_friction,
                                        case.sweep.error_tolerance, case.tribometer.ball)
    return summary


def _range_check(swept) -> dict:
    """:func:`~fem_twin.stribeck.accuracy.range_summary` over the points of the sweeps
    ``swept``, ``[(tasks, points)]`` (the main curves' and the band's, whose single patches
    reach lower separations; :func:`~fem_twin.stages.sweeps.point_index`), each share read
    from its checkpoint's meta (``LOAD_BELOW``; a checkpoint without it is loaded whole)."""
    h0_min = swept[0][0][0].factors.h0[0]

    def shares():
        for tasks, points in swept:
            for point in points:
                task = tasks[point.sweep]
                name = task.factors_key.rsplit("-", 1)[-1]
                factors = name if name.startswith("patch") else "average"
                share = point.meta.get(LOAD_BELOW)
                if share is None:
                    share = MixedResult.load(point.path).contact_load_below(h0_min)
                yield share, (f"{factors} factors, mu_0 = {task.lubricant.viscosity:g} Pa s, "
                              f"U = {point.speed:.3g} m/s")
    return range_summary(shares(), h0_min)


def _log_points(curves) -> None:
    for c in curves:
        for u, cf, it, share in zip(c.speed, c.friction_coefficient, c.iterations,
                                    c.contact_load_fraction):
            log.info("point mu_0 = %g Pa s, U = %.4g m/s: C_f = %.5f, contact share %.3f, "
                     "%d iterations", c.viscosity, u, cf, share, it)


def band_sweeps(case: Case, out: RunLayout, request) -> list:
    """``request`` with every single patch's flow factors (the scatter band, Figure 13)."""
    n = len(case.geometry.patches)
    if n < 2:
        return []
    return [replace(request, factors=FlowFactors.load(out.patch_factors(i + 1)),
                    factors_key=f"{request.factors_key}-patch{i + 1}", fields=None)
            for i in range(n)]


def curve_labels(case: Case, curves) -> list[str]:
    return [f"{t:g} °C, $\\mu_0$ = {c.viscosity:g} Pa s"
            for t, c in zip(case.lubricant.temperatures, curves)]


def ehl_film(stage: CurveStage, points) -> dict:
    """The film of a ball-on-disk sweep's fastest point (the first sweep's, of its
    ``points``, :func:`~fem_twin.stages.sweeps.point_index`) beside the Hamrock-Dowson films
    of the stage's smooth ball at the same u_m and the film's viscosity (the oil's, or a
    thermal run's at the film temperature): the full-film end of the curve."""
    fastest = next(p for p in points if p.sweep == 0)
    u_m, point = fastest.speed, MixedResult.load(fastest.path)
    film_mu = point.meta.get("thermal", {}).get("viscosity_Pa_s", stage.contact.viscosity)
    _, _, x1, x2 = ball_grid(stage.case, stage.contact)
    film = film_against_hamrock_dowson(replace(stage.contact, viscosity=film_mu,
                                               entrainment=u_m), point, x1, x2)
    log.info("EHL film at u_m = %g m/s: h_c %.4g m, h_min %.4g m; Hamrock-Dowson %.4g m, "
             "%.4g m", u_m, film["h_c_m"], film["h_min_m"], film["hamrock_dowson_h_c_m"],
             film["hamrock_dowson_h_min_m"])
    return film


def plot_curves(stage: CurveStage, curves, band, writers: Writers | None = None) -> None:
    """C_f versus speed and versus Hersey number, with the band and measured curves (on
    ``writers``, else at once)."""
    writers = writers or Writers()
    case, out = stage.case, stage.out
    measured = [read_measured_csv(m) if m is not None else None for m in case.measured]
    measured += [None] * (len(curves) - len(measured))
    tr = case.tribometer
    for x in ("speed", "hersey"):
        writers.write(plot_stribeck, curves, out.stribeck_png(x), x=x,
                      labels=curve_labels(case, curves),
                      boundary_friction=stage.boundary_friction, bands=band,
                      measured=measured, diameter=stage.request.hersey_length,
                      load=tr.load, speed_label=("entrainment speed $u_m$ [m/s], SRR "
                                                 f"{tr.slide_to_roll:g}" if tr.ball else
                                                 "sliding speed $U$ [m/s]"))
    writers.write(plot_parts, curves, out.parts_png, labels=curve_labels(case, curves),
                  bands=band, speed_label=("entrainment speed $u_m$ [m/s]" if tr.ball else
                                           "sliding speed $U$ [m/s]"))
    if curves[0].contact_temperature is not None:
        writers.write(plot_temperatures, curves, out.temperature_png,
                      labels=curve_labels(case, curves))


def write_run_results(case: Case, out: RunLayout, curves, patch_curves) -> None:
    """``results.nc``: flow factors per patch and average, Stribeck curves with the band,
    settings and error estimates."""
    from ..results import flow_factor_dataset, stribeck_dataset, write_netcdf
    n = len(case.geometry.patches)
    factors = [FlowFactors.load(out.patch_factors(k)) for k in [*range(1, n + 1), None]]
    write_netcdf(out.results,
                 {"flow_factors": flow_factor_dataset(factors, [str(i + 1) for i in range(n)]
                                                      + ["average"]),
                  "stribeck": stribeck_dataset(curves, patch_curves)}, _attributes(case))


def field_sweeps(tasks, points) -> list:
    """What :func:`write_fields` reads of the main sweeps ``tasks``, per sweep
    ``(viscosity, files, indexed)``: its checkpoints along its speeds (fast to slow) and
    the ``(speed, checkpoint)`` of its ``points`` in the index
    (:func:`~fem_twin.stages.sweeps.point_index`): files, not fields, for a worker."""
    return [(task.lubricant.viscosity,
             [point_file(task.checkpoint, task.key, u) for u in task.speeds],
             [(p.speed, p.path) for p in points if p.sweep == i])
            for i, task in enumerate(tasks)]


def write_fields(case: Case, out: RunLayout, sweeps, origin) -> None:
    """The macro fields of the main sweeps (:func:`field_sweeps`), each point's checkpoint
    read once: a VTU per point, numbered along its sweep, and a PVD per sweep in
    ``fields/`` (ParaView's time: the point's speed U [m/s]), the fastest, a middle and the
    slowest point of each sweep drawn (``fields_mu*.png``), and ``fields.nc``; the grid's
    ``origin`` [m].  Written beside the band's sweeps: they need only the main curves."""
    from ..results import fields_dataset, write_netcdf
    read = {}

    def point(path) -> MixedResult:
        if path not in read:
            read[path] = MixedResult.load(path)
        return read[path]

    folder = out.fields
    folder.mkdir(parents=True, exist_ok=True)
    every = []
    for mu, files, indexed in sweeps:
        write_pvd(folder / f"stribeck_mu{mu:g}.pvd", [
            (float(point(f).speed), point(f).write_vtu(folder / f"mu{mu:g}_{i:03d}.vtu", origin))
            for i, f in enumerate(files)])
        shown = [point(indexed[k][1]) for k in sorted({0, len(indexed) // 2, len(indexed) - 1})]
        plot_point_fields(shown, out.fields_png(mu), titles=[
            f"$\\mu_0$ = {mu:g} Pa s, U = {r.speed:.3g} m/s, $C_f$ = {r.friction_coefficient:.4f}"
            for r in shown])
        every.append((mu, {u: point(path) for u, path in indexed}))
    write_netcdf(out.fields_nc, {None: fields_dataset(every, origin)}, _attributes(case))


def _attributes(case: Case) -> dict:
    """The global attributes of a run's NetCDF files: the case and its provenance."""
    from dataclasses import asdict
    return {"case": json.dumps(asdict(case), default=str), "case_name": case.name,
            "provenance": json.dumps(provenance(case))}


def _prune_points(folder: Path, tasks) -> None:
    """Remove the Stribeck checkpoints of no current sweep or guide (changed inputs)."""
    guides = [guide_of(task) for task in tasks]
    keys = ({task.key for task in tasks} | {task.guide for task in tasks}
            | {guide.key for guide in guides if guide is not None})
    stale = [p for p in point_files(folder) if point_key(p) not in keys]
    for p in stale:
        p.unlink()
    if stale:
        log.info("%d stale Stribeck checkpoints removed", len(stale))
