"""The main job: from a case file to a Stribeck curve in an output folder.

Stages: virtual geometry reconstruction (pins, disks, roughness patches) -> pin levelling
by torque balance and set averaging -> homogenisation of every patch pair and the patch
average -> Stribeck sweeps (one per viscosity) -> CSV, plots, VTU/PVD, JSON summary, log.
Every stage writes its results atomically; finished results (and the checkpoints inside
long stages) are reused when the job runs again, so an interrupted run resumes.
"""

from __future__ import annotations

import json
import logging
import os
import time
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .case import Case
from .contact.levelling import average_pins, level_pin
from .errors import InputError, RunLocked, SchedulerUnreachable
from .io.atomic import atomic_path
from .io.checkpoint import input_key, load_or_none
from .io.table import write_csv
from .io.files import read_topography, write_topography
from .io.layout import RunLayout
from .io.mesh import grid_mesh, write_vtu
from .macro import MacroSettings, MixedResult
from .macro.figures import plot_point_fields
from .macro.point_contact import PointContact, film_thickness
from .micro import FlowFactors, average, homogenise
from .micro.store import prune_checkpoints
from .micro.output import plot_flow_factors
from .stribeck import (deviation_from_measured, plot_stribeck,
                       read_measured_csv, stribeck_sweep, write_stribeck_csv)
from .stribeck.accuracy import error_summary
from .stribeck.analysis import hersey_collapse, patch_band, transition_speeds
from .stribeck.sweep import point_files, point_key, sweep_key
from .threads import one_thread, process_pool, stop_pool, worker_heap
from .topography import resample_cell
from .topography.plausibility import check_patch, check_pin
from .topography.prepare import flat_disk, prepare_disk, prepare_patch, prepare_pin

log = logging.getLogger("fem_twin")


@one_thread
def run(case: Case, outdir, *, progress: bool = True) -> dict:
    """Run the whole pipeline of ``case`` into ``outdir``; return the summary."""
    out = RunLayout(outdir)
    outdir = out.root
    if outdir.exists() and not outdir.is_dir():
        raise InputError(f"{outdir} is a file: give a folder for the results (-o)")
    for path in case.measured:                 # [validation] curves: checked before any work
        if path is not None:
            read_measured_csv(path)
    outdir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    summary = {"case": case.name, "provenance": provenance(case), "stages": {},
               "seconds": {}}
    with _lock(out), _logfile(out.log), executor_for(case) as executor:
        log.info("case %s -> %s", case.source, outdir)
        invalidate_changed_stages(case, out)
        stages = (("geometry", lambda: reconstruct_geometry(case, out, progress)),
                  ("levelling", lambda: level_pins(case, out, progress)),
                  ("micro", lambda: homogenise_patches(case, out, executor, progress)),
                  ("stribeck", lambda: stribeck_curves(case, out, executor, progress)))
        for name, stage in stages:
            t = time.perf_counter()
            log.info("stage %s", name)
            try:
                summary["stages"][name] = stage()
            except BaseException:
                log.exception("stage %s failed", name)    # run.log only (see cli)
                raise
            summary["seconds"][name] = round(time.perf_counter() - t, 2)
            log.info("stage %s done in %.1f s", name, summary["seconds"][name])
    summary["wall_time_s"] = time.perf_counter() - t0
    with atomic_path(out.summary) as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    return summary


def provenance(case: Case) -> dict:
    """fem_twin version, git commit of the source when it is a checkout, case file hash."""
    import hashlib
    import subprocess

    from . import __version__
    commit = None
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                                cwd=Path(__file__).parent, timeout=10).stdout.strip() or None
    except (OSError, subprocess.SubprocessError):
        pass
    digest = (hashlib.sha256(case.source.read_bytes()).hexdigest()[:16]
              if case.source is not None else None)
    return {"fem_twin_version": __version__, "git_commit": commit,
            "case_file": str(case.source), "case_sha256": digest,
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z")}


def stage_keys(case: Case) -> dict:
    """Hash of the case settings each cached stage depends on."""
    def key(*parts):
        return input_key(repr(parts))

    g = case.geometry
    files = [(str(p), p.stat().st_mtime_ns, p.stat().st_size)
             for p in (*g.pins, *g.disks, *(q for pair in g.patches for q in pair))]
    geometry = key(files, g, case.macro_geometry)
    return {"geometry": geometry,
            "levelling": key(geometry, case.materials, case.macro.pin),
            "micro": key(geometry, case.micro, case.materials)}


def invalidate_changed_stages(case: Case, out: RunLayout) -> None:
    """Remove cached stage results whose inputs changed since they were written (the
    Stribeck points and micro checkpoints are keyed by their inputs already)."""
    import shutil
    path = out.stage_keys
    old = {}
    if path.exists():
        try:
            old = json.loads(path.read_text())
        except (ValueError, UnicodeDecodeError):
            old = None
        if not isinstance(old, dict):
            log.warning("%s is damaged: every cached stage is recomputed", path)
            old = {stage: "damaged" for stage in ("geometry", "levelling", "micro")}
    new = stage_keys(case)
    for stage, key in new.items():
        if old.get(stage) not in (None, key):
            log.info("inputs of stage %s changed: recomputing it", stage)
            if stage == "micro":
                for f in out.micro.glob(f"patch_*/{out.flow_factors.name}"):
                    f.unlink()
            else:
                shutil.rmtree(out.stage(stage), ignore_errors=True)
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(new, indent=2))


@contextmanager
def _logfile(path):
    handler = logging.FileHandler(path)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"))
    log.addHandler(handler)
    level = log.level
    log.setLevel(logging.INFO)
    try:
        yield
    finally:
        log.removeHandler(handler)
        log.setLevel(level)
        handler.close()


@contextmanager
def _lock(out: RunLayout):
    """One run per output folder: an exclusive lock on ``OUT/.lock``, released when the run
    ends, however it ends (the system drops it with the process, also on kill -9)."""
    import fcntl
    f = open(out.lock, "a+")
    try:
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            f.seek(0)
            holder = f.read().strip() or "another process"
            raise RunLocked(f"{out.root} is in use by fem-twin run (pid {holder}); wait for it "
                            "to finish or choose another output folder (-o)") from None
        f.seek(0)
        f.truncate()
        f.write(str(os.getpid()))
        f.flush()
        yield
    finally:
        f.close()


@contextmanager
def executor_for(case: Case):
    """Local process pool (``[run] workers``, 0 = all cores) or a Dask cluster's executor
    (``[run] scheduler`` address); None for one worker.  ``executor.n_workers``: how many
    processes serve it (the micro stage cuts its h0 values into 4 tasks per worker)."""
    if case.run.scheduler:
        from distributed import Client
        try:
            client = Client(case.run.scheduler, timeout="5s")
        except (OSError, TimeoutError) as err:
            raise SchedulerUnreachable(f"could not reach the Dask scheduler "
                                       f"{case.run.scheduler} ([run] scheduler): {err}") from err
        with client:
            executor = client.get_executor()
            executor.n_workers = max(1, len(client.scheduler_info()["workers"]))
            yield executor
        return
    workers = case.run.workers or os.cpu_count() or 1
    if workers <= 1:
        yield None
        return
    pool = process_pool(workers)
    pool.n_workers = workers
    try:
        yield pool
    except BaseException:
        stop_pool(pool, failed=True)
        raise
    stop_pool(pool)


def reconstruct_geometry(case: Case, out: RunLayout, progress: bool = True) -> dict:
    """Prepare every pin (with its disk, or a flat one) and patch pair; write npz + VTU."""
    out.geometry.mkdir(parents=True, exist_ok=True)
    opts = case.macro_geometry
    jobs = [] if case.tribometer.ball else [("pin", i) for i in range(len(case.geometry.pins))]
    jobs += [("patch", i) for i in range(len(case.geometry.patches))]
    result = {"pins": [], "patches": []}
    for kind, i in tqdm(jobs, desc="geometry", disable=not progress, unit="surface"):
        if kind == "pin":
            pin_out, disk_out = out.pin(i + 1), out.disk(i + 1)
            if not all(load_or_none(f, read_topography) for f in (pin_out, disk_out)):
                raw = read_topography(case.geometry.pins[i])
                check_pin(raw, case.geometry.pins[i].name, case.tribometer.pin_diameter)
                pin = prepare_pin(raw, opts)
                disk = (prepare_disk(read_topography(case.geometry.disks[i]), opts)
                        if case.geometry.disks else flat_disk(pin))
                if disk.shape != pin.shape:
                    raise InputError(f"pin {i + 1} and its disk differ in resolution "
                                     f"{pin.shape} vs {disk.shape}")
                write_vtu(out.macro_vtu(i + 1),
                          grid_mesh(pin.shape, pin.spacing, pin.origin),
                          {"x3_low": pin.heights, "x3_up": disk.heights,
                           "pin_face": (pin.heights > opts.holder_height).astype(float)})
                write_topography(disk_out, disk)
                write_topography(pin_out, pin)
            pin = read_topography(pin_out)
            face = pin.heights > opts.holder_height
            result["pins"].append({"file": pin_out.name, "grid": list(pin.shape),
                                   "spacing_m": list(pin.spacing),
                                   "face_fraction": float(face.mean()),
                                   "face_range_m": [float(pin.heights[face].min()),
                                                    float(pin.heights[face].max())]})
        else:
            low_out, up_out = out.patch(i + 1, "low"), out.patch(i + 1, "up")
            if not all(load_or_none(f, read_topography) for f in (low_out, up_out)):
                src_pin, src_disk = case.geometry.patches[i]
                axis = case.macro_geometry.sliding_direction
                low = prepare_patch(read_topography(src_pin), case.geometry.patch_shape,
                                    case.geometry.patch_start, sliding_direction=axis)
                up = prepare_patch(read_topography(src_disk), case.geometry.patch_shape,
                                   case.geometry.patch_start, upper=True,
                                   sliding_direction=axis)
                for t, src in ((low, src_pin), (up, src_disk)):
                    for warning in check_patch(t, src.name, case.tribometer.pin_diameter):
                        log.warning("%s", warning)
                write_vtu(out.patch_vtu(i + 1),
                          grid_mesh(low.shape, low.spacing, periodic=True),
                          {"x3_low": low.heights, "x3_up": up.heights})
                write_topography(up_out, up)
                write_topography(low_out, low)
            sq_low = read_topography(low_out).rms_height()
            sq_up = read_topography(up_out).rms_height()
            result["patches"].append({"files": [low_out.name, up_out.name], "sq_low_m": sq_low,
                                      "sq_up_m": sq_up, "sq_m": float(np.hypot(sq_low, sq_up))})
    return result


def level_pins(case: Case, out: RunLayout, progress: bool = True) -> dict:
    """Level every pin against its disk (torque balance, Table 4 at 50 N); average the
    levelled set and level the average (paper 2.2.1).  Writes ``levelling/``."""
    if case.tribometer.ball:
        return {"skipped": "ball-on-disk: the macro gap is the ball's sphere"}
    out.levelling.mkdir(parents=True, exist_ok=True)
    m = case.materials
    e_red = m.e_reduced
    holder = case.macro_geometry.holder_height
    result = {"pins": []}
    levelled = []
    n = len(case.geometry.pins)
    for i in tqdm(range(n), desc="levelling", disable=not progress, unit="pin"):
        path = out.levelled_pin(i + 1)
        if load_or_none(path, read_topography) is None:
            lev = level_pin(read_topography(out.pin(i + 1)), read_topography(out.disk(i + 1)),
                            e_reduced=e_red, hardness=m.hardness, holder_height=holder)
            write_topography(path, lev.pin.with_heights(lev.pin.heights, meta={
                **lev.pin.meta, "tilt_rad": list(lev.tilt),
                "torque_residuals": list(lev.residuals)}))
        pin = read_topography(path)
        levelled.append(pin)
        result["pins"].append({"file": path.name, "tilt_rad": pin.meta.get("tilt_rad")})
    avg_out = out.levelled_pin("average")
    if n > 1 and load_or_none(avg_out, read_topography) is None:
        lev = level_pin(average_pins(levelled, radius=case.macro_geometry.level_radius,
                                     truncation=case.macro_geometry.truncation,
                                     holder_height=holder),
                        read_topography(out.disk(1)), e_reduced=e_red,
                        hardness=m.hardness, holder_height=holder)
        write_topography(avg_out, lev.pin)
    result["macro_pin"] = macro_pin_file(case, out).name
    return result


def homogenise_patches(case: Case, out: RunLayout, executor=None, progress: bool = True,
                       h0=None):
    """Flow factors of every patch pair (checkpointed per h0) and their average (``h0``:
    the case's range unless given).  With an executor the patches run side by side (a
    thread each hands its h0 tasks to the shared pool), so the pool is not left idle at
    the end of a patch or of a round of adaptive h0, and a cluster gets every patch's
    tasks at once."""
    out.micro.mkdir(parents=True, exist_ok=True)
    mc = case.micro
    h0 = np.geomspace(mc.h0_min, mc.h0_max, mc.h0_count) if h0 is None else np.asarray(h0)
    n = len(case.geometry.patches)
    bar = tqdm(total=n * len(h0), desc="flow factors", unit="h0", disable=not progress
               or os.environ.get("FEM_TWIN_NO_PROGRESS") == "1")
    try:
        if executor is None:
            factors = [_patch_factors(case, out, i, h0, None, bar) for i in range(n)]
        else:
            with ThreadPoolExecutor(n) as threads:
                factors = list(threads.map(
                    lambda i: _patch_factors(case, out, i, h0, executor, bar), range(n)))
    finally:
        bar.close()
    mean = average(factors)
    mean.save(out.flow_factors)
    mean.write_csv(out.flow_factors_csv)
    plot_flow_factors([*factors, mean], out.flow_factors_png,
                      labels=[f"patch {i + 1}" for i in range(len(factors))] + ["average"])
    estimate = mean.meta.get("error_estimate", {})
    return {"patches": len(factors), "h0_m": [float(h0[0]), float(h0[-1]), len(h0)],
            "h0_solved": [len(f) for f in factors], "h0_tol": mc.h0_tol,
            "grid": list(mc.resolution), "steps": mc.steps,
            "time_derivative": mc.time_derivative,
            "error_estimate": estimate,
            "p_con_max_Pa": float(mean.p_con.max()),
            "files": [out.flow_factors_csv.name, out.flow_factors_png.name]}


def _patch_factors(case: Case, out: RunLayout, i: int, h0, executor, bar) -> FlowFactors:
    """Flow factors of patch pair ``i`` (0-based): its file if present, else computed."""
    mc, m = case.micro, case.materials
    path, checkpoints = out.patch_factors(i + 1), out.patch_checkpoints(i + 1)
    ff = load_or_none(path, FlowFactors.load)
    if ff is not None:
        bar.update(len(h0))
        return ff
    low = read_topography(out.patch(i + 1, "low"))
    up = read_topography(out.patch(i + 1, "up"))
    if low.shape != tuple(mc.resolution):
        low, up = resample_cell(low, mc.resolution), resample_cell(up, mc.resolution)
    ff = homogenise(low, up, h0, n_steps=mc.steps, e_reduced=m.e_reduced,
                    hardness=m.hardness, method=mc.method,
                    time_derivative=mc.time_derivative, time_tol=mc.time_tol,
                    h0_tol=mc.h0_tol, executor=executor,
                    workers=getattr(executor, "n_workers", 1),
                    checkpoint=checkpoints, progress=bar,
                    patch_id=f"patch {i + 1}")
    ff.save(path)
    stale = prune_checkpoints(checkpoints, ff.meta["checkpoint_keys"])
    if stale:
        log.info("patch %d: %d stale h0 checkpoints removed", i + 1, stale)
    return ff


def macro_pin_number(case: Case) -> int | str:
    """The pin of the macro scale: ``"average"`` (the levelled set's average, when the set
    has more than one pin) or its number, counted from 1 (its disk serves the average)."""
    if case.macro.pin == "average":
        return "average" if len(case.geometry.pins) > 1 else 1
    return case.macro.pin


def macro_pin_file(case: Case, out: RunLayout) -> Path:
    """The levelled pin of the macro scale (:func:`macro_pin_number`)."""
    return out.levelled_pin(macro_pin_number(case))


def macro_geometry(case: Case, out: RunLayout):
    """Gap ``h_g = x3_up - x3_low``, spacing, pin-face mask and origin of the macro pin, or
    of the ball's sphere over [-4a, 2a] x [-3a, 3a] (a the Hertz radius; face: all)."""
    if case.tribometer.ball:
        gap, spacing, x1, x2 = ball_contact(case).grid(case.macro.grid)
        return gap, spacing, np.ones(gap.shape, bool), (float(x1[0]), float(x2[0]))
    pin = read_topography(macro_pin_file(case, out))
    k = macro_pin_number(case)
    disk = read_topography(out.disk(1 if k == "average" else k))
    face = pin.heights > case.macro_geometry.holder_height / 2
    return disk.heights - pin.heights, pin.spacing, face, pin.origin


def face_load(case: Case) -> float:
    """The load the macro scale balances (eq 28) [N]: ``[tribometer] load_share`` of the
    imposed load (C_f is referred to the imposed load, ``StribeckCurve.with_load_share``)."""
    return case.tribometer.load * case.tribometer.load_share


def ball_contact(case: Case) -> PointContact:
    """The smooth ball of a ball-on-disk case (Hertz radius, Hamrock-Dowson films) at the
    first viscosity and the sweep's fastest entrainment speed."""
    tr, lb = case.tribometer, case.lubricant
    return PointContact(tr.ball_radius, tr.load, case.materials.e_reduced, lb.viscosities[0],
                        lb.roelands_alpha, case.sweep.speed_max)


def _sweep_task(args):
    """One viscosity's sweep (a picklable unit of work for process pools and Dask)."""
    worker_heap()
    kwargs, lub = args
    return stribeck_sweep(lubricant=lub, **kwargs)


def macro_settings(case: Case, method: str | None = None) -> MacroSettings:
    """The macro solver settings of a case (``method`` overrides ``[macro] method``).

    A ball's contact cavitates at the ambient pressure: the 0.2 bar between p_amb and p_cav
    of Table 6 is nothing beside its GPa, and the thin pressurised layer it forces along
    the sides of the outlet cavity makes the Newton coupling cycle between two states."""
    settings = MacroSettings(e_reduced=case.materials.e_reduced,
                             boundary_friction=case.tribometer.boundary_friction,
                             method=method or case.macro.method, coupling=case.macro.coupling,
                             inner_steps=case.macro.inner_steps, couette=case.macro.couette)
    if case.tribometer.ball:
        settings = replace(settings, cavitation_pressure=settings.ambient_pressure)
    return settings


def stribeck_curves(case: Case, out: RunLayout, executor=None, progress: bool = True) -> dict:
    """One Stribeck sweep per viscosity (in parallel on ``executor``), the patch scatter band
    (``[run] patch_band``); CSV, plots, fields, ``results.nc`` and ``fields.nc``."""
    gap, spacing, face, origin = macro_geometry(case, out)
    factors = FlowFactors.load(out.flow_factors)
    lb, tr = case.lubricant, case.tribometer
    ball = dict(slide_to_roll=tr.slide_to_roll) if tr.ball else {}
    common = dict(gap=gap, spacing=spacing, factors=factors, speeds=case.sweep.speeds,
                  load=face_load(case), diameter=hersey_length(case), face=face, **ball,
                  settings=macro_settings(case),
                  checkpoint=out.points, fields=out.fields,
                  origin=origin, factors_key=stage_keys(case)["micro"])
    lubricants = lb.lubricants()
    speeds = case.sweep.speeds
    for level in range(case.sweep.refine + 1):
        curves = [c.with_load_share(tr.load_share) for c in run_sweeps(
            [(dict(common, speeds=speeds, error_estimate=True), lub) for lub in lubricants],
            executor, progress)]
        extra = transition_speeds(curves, case.sweep.refine_step * tr.boundary_friction)
        if level == case.sweep.refine or extra.size == 0:
            break
        log.info("sweep refinement %d: %d speeds added where C_f changes by more than "
                 "%.3g", level + 1, extra.size, case.sweep.refine_step * tr.boundary_friction)
        speeds = np.unique(np.r_[speeds, extra])[::-1]
    tasks = [(dict(common, speeds=speeds, error_estimate=True), lub) for lub in lubricants]
    band_tasks = [(kw, lub) for kw in band_sweeps(case, out, dict(common, speeds=speeds))
                  for lub in lubricants] if case.run.patch_band else []
    patch_curves = [c.with_load_share(tr.load_share) for c in run_sweeps(
        band_tasks, executor, progress, desc="patch band points")]
    patch_curves = [patch_curves[i:i + len(lubricants)]
                    for i in range(0, len(patch_curves), len(lubricants))]
    band = patch_band(patch_curves) if patch_curves else None
    _prune_points(common["checkpoint"], tasks + band_tasks)
    write_stribeck_csv(out.stribeck_csv, curves, band)
    summary = {"curves": [{"viscosity_Pa_s": c.viscosity,
                       "friction_coefficient_range": [float(c.friction_coefficient.min()),
                                                      float(c.friction_coefficient.max())]}
                      for c in curves],
           "files": [p.name for p in (out.stribeck_csv, out.stribeck_png("speed"),
                                      out.stribeck_png("hersey"), out.results, out.fields_nc,
                                      out.fields, *(out.fields_png(c.viscosity)
                                                    for c in curves))]}
    if band is not None:
        summary["patch_band_max_width"] = float(max(np.max(hi - lo) for lo, hi in band))
    summary["cf_error"] = error_summary(curves, tr.boundary_friction, case.sweep.error_tolerance)
    plot_curves(case, curves, band, out)
    points = sweep_points(common["checkpoint"], tasks)
    for mu in lb.viscosities:
        u = sorted((v for m, v in points if m == mu), reverse=True)      # fast to slow
        res = [points[mu, u[i]] for i in sorted({0, len(u) // 2, len(u) - 1})]
        plot_point_fields(res, out.fields_png(mu), titles=[
            f"$\\mu_0$ = {mu:g} Pa s, U = {r.speed:.3g} m/s, "
            f"$C_f$ = {r.friction_coefficient:.4f}" for r in res])
    for c in curves:
        for u, cf, it, share in zip(c.speed, c.friction_coefficient, c.iterations,
                                    c.contact_load_fraction):
            log.info("point mu_0 = %g Pa s, U = %.4g m/s: C_f = %.5f, contact share %.3f, "
                     "%d iterations", c.viscosity, u, cf, share, it)
    if len(curves) > 1:
        summary["hersey_collapse_max_abs_cf_dev"] = hersey_collapse(curves, tr.boundary_friction)
    if tr.ball:
        summary["ehl_film"] = ehl_film(case, points)
    if any(case.measured):
        summary["validation"] = validate(case, curves, out, curve_labels(case, curves))
    write_run_results(case, out, curves, patch_curves, points, origin)
    return summary


def band_sweeps(case: Case, out: RunLayout, common: dict) -> list[dict]:
    """Sweep arguments of every single patch's flow factors (the scatter band, Figure 13)."""
    n = len(case.geometry.patches)
    if n < 2:
        return []
    return [dict(common, factors=FlowFactors.load(out.patch_factors(i + 1)),
                 factors_key=f"{common['factors_key']}-patch{i + 1}", fields=None)
            for i in range(n)]


def curve_labels(case: Case, curves) -> list[str]:
    return [f"{t:g} °C, $\\mu_0$ = {c.viscosity:g} Pa s"
            for t, c in zip(case.lubricant.temperatures, curves)]


def ehl_film(case: Case, points) -> dict:
    """The film of a ball-on-disk sweep's fastest point (first viscosity) beside the
    Hamrock-Dowson films of the smooth ball at the same u_m: the full-film end of the curve."""
    mu = case.lubricant.viscosities[0]
    u_m = max(u for m, u in points if m == mu)
    _, _, x1, x2 = ball_contact(case).grid(case.macro.grid)
    h_c, h_min = film_thickness(points[mu, u_m], x1, x2)
    hd_c, hd_min = replace(ball_contact(case), viscosity=mu, entrainment=u_m).hamrock_dowson()
    log.info("EHL film at u_m = %g m/s: h_c %.4g m, h_min %.4g m; Hamrock-Dowson %.4g m, "
             "%.4g m", u_m, h_c, h_min, hd_c, hd_min)
    return {"entrainment_m_s": u_m, "h_c_m": h_c, "h_min_m": h_min,
            "hamrock_dowson_h_c_m": float(hd_c), "hamrock_dowson_h_min_m": float(hd_min)}


def hersey_length(case: Case) -> float:
    """D of the Hersey number (eq 46) [m]: the pin diameter, or a ball's Hertz diameter."""
    return (2 * ball_contact(case).hertz_radius if case.tribometer.ball
            else case.tribometer.pin_diameter)


def plot_curves(case: Case, curves, band, out: RunLayout) -> None:
    """C_f versus speed and versus Hersey number, with the band and measured curves."""
    measured = [read_measured_csv(m) if m is not None else None for m in case.measured]
    measured += [None] * (len(curves) - len(measured))
    tr = case.tribometer
    for x in ("speed", "hersey"):
        plot_stribeck(curves, out.stribeck_png(x), x=x,
                      labels=curve_labels(case, curves), boundary=tr.boundary_friction,
                      bands=band, measured=measured, diameter=hersey_length(case),
                      load=tr.load, speed_label=("entrainment speed $u_m$ [m/s], SRR "
                                                 f"{tr.slide_to_roll:g}" if tr.ball else
                                                 "sliding speed $U$ [m/s]"))


def sweep_points(folder: Path, tasks) -> dict:
    """{(viscosity, speed): MixedResult} of the checkpoints of the sweeps ``tasks``."""
    points = {}
    for kw, lub in tasks:
        for path in point_files(folder, _sweep_key(kw, lub)):
            res = MixedResult.load(path)
            speed = res.speed if kw.get("slide_to_roll") is None else res.meta["entrainment"]
            points[lub.viscosity, speed] = res
    return points


def write_run_results(case: Case, out: RunLayout, curves, patch_curves, points, origin) -> None:
    """``results.nc`` (flow factors per patch and average, Stribeck curves with the band,
    settings and error estimates) and ``fields.nc`` (the macro fields of ``points``)."""
    from dataclasses import asdict

    from .results import fields_dataset, flow_factor_dataset, stribeck_dataset, write_netcdf
    n = len(case.geometry.patches)
    factors = [FlowFactors.load(out.patch_factors(k)) for k in [*range(1, n + 1), None]]
    attrs = {"case": json.dumps(asdict(case), default=str), "case_name": case.name,
             "provenance": json.dumps(provenance(case))}
    write_netcdf(out.results,
                 {"flow_factors": flow_factor_dataset(factors, [str(i + 1) for i in range(n)]
                                                      + ["average"]),
                  "stribeck": stribeck_dataset(curves, patch_curves)}, attrs)
    write_netcdf(out.fields_nc, {None: fields_dataset(points, origin)}, attrs)


def validate(case: Case, curves, out: RunLayout, labels) -> list:
    """C_f,dev (eq 35) of each simulated curve against its measured CSV (paper 3.3)."""
    rows, result = [], []
    for curve, path, label in zip(curves, case.measured, labels):
        if path is None:
            continue
        measured = read_measured_csv(path)
        dev = deviation_from_measured(curve, measured, case.tribometer.boundary_friction)
        rows += [(curve.viscosity, u, cf, d) for u, cf, d in
                 zip(measured.speed, measured.friction_coefficient, dev)]
        band = None if measured.low is None else (measured.low, measured.high)
        plot_stribeck([curve], out.validation_png(curve.viscosity), labels=[label],
                      reference=(measured.speed, measured.friction_coefficient, band),
                      boundary=case.tribometer.boundary_friction)
        result.append({"viscosity_Pa_s": curve.viscosity, "measured": str(path),
                       "max_abs_cf_dev": float(np.nanmax(np.abs(dev)))})
    write_csv(out.validation_csv, dict(zip(
        ("viscosity_Pa_s", "speed_m_s", "measured_cf", "cf_dev"),
        zip(*rows) if rows else ((),) * 4)))
    return result


def run_sweeps(tasks, executor=None, progress: bool = True, desc: str = "Stribeck points"):
    """Sweeps ``tasks`` [(sweep kwargs, lubricant)]: serial, or one process task each on
    ``executor``.

    In parallel the bar counts the finished points of all sweeps (their checkpoint files,
    written as each point finishes in its worker)."""
    if executor is None or len(tasks) <= 1:
        return [_sweep_task((dict(kw, progress=progress), lub)) for kw, lub in tasks]
    futures = [executor.submit(_sweep_task, (dict(kw, progress=False), lub))
               for kw, lub in tasks]
    total = sum(len(kw["speeds"]) for kw, _ in tasks)
    keys = {_sweep_key(kw, lub) for kw, lub in tasks if kw.get("factors_key")}
    folder = tasks[0][0].get("checkpoint")
    with tqdm(total=total, desc=desc, unit="point", disable=not progress) as bar:
        while not all(f.done() for f in futures):
            if folder is not None and keys:                   # points finished so far
                bar.update(sum(point_key(p) in keys for p in point_files(folder)) - bar.n)
            time.sleep(0.5)
        bar.update(total - bar.n)
    return [f.result() for f in futures]


def _sweep_key(kwargs: dict, lubricant) -> str:
    """Checkpoint key of one sweep task (:func:`~fem_twin.stribeck.sweep.point_file`)."""
    return sweep_key(kwargs["gap"], kwargs["spacing"], kwargs["factors_key"], kwargs["load"],
                     lubricant, kwargs["settings"], kwargs["face"],
                     kwargs.get("slide_to_roll"))


def _prune_points(folder: Path, tasks) -> None:
    """Remove the Stribeck checkpoints of no current sweep (changed inputs)."""
    keys = {_sweep_key(kw, lub) for kw, lub in tasks}
    stale = [p for p in point_files(folder) if point_key(p) not in keys]
    for p in stale:
        p.unlink()
    if stale:
        log.info("%d stale Stribeck checkpoints removed", len(stale))
