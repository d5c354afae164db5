"""The Stribeck side of the main job: one warm-started sweep per viscosity with the C_f
error estimates, refinement passes where the curve turns, the patch scatter band, and what
is written of them (CSV, plots, fields, ``results.nc``, ``fields.nc``, validation)."""

from __future__ import annotations

import json
import logging
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..case import Case
from ..io.layout import RunLayout
from ..io.writers import Writers
from ..macro import MixedResult
from ..macro.figures import plot_point_files
from ..macro.reference.point_contact import film_against_hamrock_dowson
from ..micro import FlowFactors
from ..stribeck import plot_stribeck, read_measured_csv, write_stribeck_csv
from ..stribeck.accuracy import error_summary, range_summary
from ..stribeck.analysis import defect_corrected, hersey_collapse, patch_band, transition_speeds
from ..stribeck.curve import plot_temperatures
from ..stribeck.parts import plot_parts
from ..stribeck.sweep import LOAD_BELOW, point_files, point_key
from ..stribeck.validation import validate_curves
from .geometry import ball_contact, ball_grid, hersey_length
from .provenance import provenance
from .requests import per_viscosity, sweep_request
from .sweeps import guide_of, run_sweeps

log = logging.getLogger("fem_twin")


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
    tr = case.tribometer
    request = sweep_request(case, out)
    (curves, points), speeds = refined_curves(case, out, request, executor, progress)
    request = replace(request, speeds=speeds)
    tasks = per_viscosity(case, replace(request, error_estimate=True))
    _plot_fields(out, points, curves, writers)                    # beside the band's sweeps
    writers.write(write_run_fields, case, out, points, curves, request.origin)
    band_run = band_tasks(case, out, request)
    band_swept = run_sweeps(band_run, executor, progress, desc="patch band points")
    patch_curves, extra = band_curves(case, request, curves, band_run, band_swept.curves,
                                      executor, progress)
    band = patch_band(patch_curves) if patch_curves else None
    patch_tasks = band_run + [task for added, _ in extra for task in added]
    _prune_points(out.points, tasks + patch_tasks)
    write_stribeck_csv(out.stribeck_csv, curves, band, law=case.boundary)
    summary = _summary(case, out, curves, band)
    writers.write(write_run_results, case, out, curves, patch_curves)
    plot_curves(case, curves, band, out, writers)
    summary["h0_range"] = _range_check([(tasks, points), (band_run, band_swept.points),
                                        *extra])
    _log_points(curves)
    if len(curves) > 1:
        summary["hersey_collapse_max_abs_cf_dev"] = hersey_collapse(curves, tr.boundary_friction)
    if tr.ball:
        summary["ehl_film"] = ehl_film(case, points)
    if any(case.measured):
        summary["validation"] = validate_curves(
            curves, case.measured, tr.boundary_friction, curve_labels(case, curves),
            out.validation_csv, out.validation_png)
    if own:
        writers.wait()
    return summary


def refined_curves(case: Case, out: RunLayout, request, executor=None,
                   progress: bool = True):
    """The main curves (with their C_f error estimates) of the sweep ``request`` over the
    case's viscosities, then ``[sweep] refine`` passes adding the midpoints where C_f
    jumps; ``(swept, speeds)``, ``swept`` the last pass's
    (:class:`~fem_twin.stages.sweeps.Swept`: its curves and the index of their points).
    With the patch band on, each point also keeps its solve on the band's grid
    (``keep_level``), which the band's sweeps start from; where that grid is the guides'
    (:meth:`~fem_twin.case.Case.band_after_guides`), each pass of the band runs beside the
    main points."""
    step = case.sweep.refine_step * case.tribometer.boundary_friction
    speeds = request.speeds
    keep = case.band_coarsening(request.gap.shape) if case.run.patch_band else 0
    band = (band_tasks(case, out, request) if case.band_after_guides(request.gap.shape)
            else [])

    def sweeps(final):                                    # the fields with the final pass
        tasks = per_viscosity(case, replace(request, speeds=speeds, error_estimate=True,
                                            keep_level=keep,
                                            fields=out.fields if final else None))
        followers = [replace(b, speeds=speeds) for b in band]
        return run_sweeps(tasks, executor, progress, followers=followers)

    for level in range(case.sweep.refine + 1):
        final = level == case.sweep.refine
        swept = sweeps(final)
        extra = transition_speeds(swept.curves, step)
        if final or extra.size == 0:
            break
        log.info("sweep refinement %d: %d speeds added where C_f changes by more than "
                 "%.3g", level + 1, extra.size, step)
        speeds = np.unique(np.r_[speeds, extra])[::-1]
    if not final:                          # every main point checkpointed: the fields
        swept = sweeps(True)
    return swept, speeds


def band_tasks(case: Case, out: RunLayout, request) -> list:
    """The sweep tasks of the scatter band (``[run] patch_band``): one per patch and
    viscosity, on the macro grid coarsened :meth:`~fem_twin.case.Case.band_coarsening`
    times, each guided by the average factors' points on that grid (the main sweeps'
    nested level, ``keep_level``; :func:`~fem_twin.stribeck.sweep.stribeck_sweep`), at the
    coupling tolerance ``[run] band_tol``."""
    sweeps = band_sweeps(case, out, request) if case.run.patch_band else []
    level = case.band_coarsening(request.gap.shape)
    band = replace(request.settings, tol=case.run.band_tol)
    return [replace(task, settings=band, guide=replace(task, factors_key=request.factors_key,
                                                       factors=request.factors).key)
            for patch in sweeps for task in per_viscosity(case, patch.coarsened(level))]


def band_curves(case: Case, request, curves, tasks, swept, executor=None,
                progress: bool = True):
    """The single-patch curves of the scatter band, one list per patch over the
    viscosities, from the curves ``swept`` of :func:`band_tasks`' ``tasks``, and the sweeps
    added here as ``[(tasks, points)]`` (:func:`~fem_twin.stages.sweeps.point_index`).
    Swept on a coarsened grid, they are corrected by the main ``curves``' relative change
    to the full grid (:func:`~fem_twin.stribeck.analysis.defect_corrected`): the main
    sweeps' own points on that grid (their nested solves) give that change, or, where a
    point has none (a coarse solve that failed, checkpoints of an earlier version), the
    average factors are swept on the band's grid too."""
    n = len(case.lubricant.lubricants())
    per_patch = [swept[i:i + n] for i in range(0, len(swept), n)]
    level = case.band_coarsening(request.gap.shape)
    if not per_patch or level == 0:
        return per_patch, []
    coarse = [c.coarse_friction_coefficient for c in curves]
    if all(cf is not None and cf.shape[0] >= level and np.all(np.isfinite(cf[level - 1]))
           for cf in coarse):
        return defect_corrected(per_patch, curves, [
            replace(c, friction_coefficient=cf[level - 1])
            for c, cf in zip(curves, coarse)]), []
    average = per_viscosity(case, request.coarsened(level))
    coarse = run_sweeps(average, executor, progress, desc="patch band points")
    return defect_corrected(per_patch, curves, coarse.curves), [(average, coarse.points)]


def _summary(case: Case, out: RunLayout, curves, band) -> dict:
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
    summary["cf_error"] = error_summary(curves, case.tribometer.boundary_friction,
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


def _plot_fields(out: RunLayout, points, curves, writers: Writers) -> None:
    """The fields of the fastest, a middle and the slowest point of each main sweep (its
    ``curves``), from their checkpoints (``points``,
    :func:`~fem_twin.stages.sweeps.point_index`)."""
    for i, curve in enumerate(curves):
        files = [p.path for p in points if p.sweep == i]                  # fast to slow
        chosen = [files[k] for k in sorted({0, len(files) // 2, len(files) - 1})]
        mu = curve.viscosity
        writers.write(plot_point_files, chosen, out.fields_png(mu), mu)


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


def ehl_film(case: Case, points) -> dict:
    """The film of a ball-on-disk sweep's fastest point (the first sweep's, of its
    ``points``, :func:`~fem_twin.stages.sweeps.point_index`) beside the Hamrock-Dowson films
    of the smooth ball at the same u_m and the film's viscosity (the oil's, or a thermal
    run's at the film temperature): the full-film end of the curve."""
    mu = case.lubricant.viscosities[0]
    fastest = next(p for p in points if p.sweep == 0)
    u_m, point = fastest.speed, MixedResult.load(fastest.path)
    film_mu = point.meta.get("thermal", {}).get("viscosity_Pa_s", mu)
    _, _, x1, x2 = ball_grid(case)
    film = film_against_hamrock_dowson(replace(ball_contact(case), viscosity=film_mu,
                                               entrainment=u_m), point, x1, x2)
    log.info("EHL film at u_m = %g m/s: h_c %.4g m, h_min %.4g m; Hamrock-Dowson %.4g m, "
             "%.4g m", u_m, film["h_c_m"], film["h_min_m"], film["hamrock_dowson_h_c_m"],
             film["hamrock_dowson_h_min_m"])
    return film


def plot_curves(case: Case, curves, band, out: RunLayout,
                writers: Writers | None = None) -> None:
    """C_f versus speed and versus Hersey number, with the band and measured curves (on
    ``writers``, else at once)."""
    writers = writers or Writers()
    measured = [read_measured_csv(m) if m is not None else None for m in case.measured]
    measured += [None] * (len(curves) - len(measured))
    tr = case.tribometer
    for x in ("speed", "hersey"):
        writers.write(plot_stribeck, curves, out.stribeck_png(x), x=x,
                     labels=curve_labels(case, curves), boundary_friction=tr.boundary_friction,
                     bands=band, measured=measured, diameter=hersey_length(case),
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


def write_run_fields(case: Case, out: RunLayout, points, curves, origin) -> None:
    """``fields.nc``: the macro fields of the main sweeps' ``points``
    (:func:`~fem_twin.stages.sweeps.point_index`; ``curves`` give each sweep's viscosity),
    read from their checkpoints (written beside the band's sweeps: they need only the main
    curves)."""
    from ..results import fields_dataset, write_netcdf
    sweeps = [(c.viscosity, {p.speed: MixedResult.load(p.path) for p in points
                             if p.sweep == i}) for i, c in enumerate(curves)]
    write_netcdf(out.fields_nc, {None: fields_dataset(sweeps, origin)}, _attributes(case))


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
