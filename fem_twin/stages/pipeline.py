"""The main job: from a case file to a Stribeck curve in an output folder.

This module orders the stages (:mod:`fem_twin.stages`) and owns what surrounds them: the
output folder's lock, the log file, the process pool or Dask executor, and the cached
stages whose inputs changed.  Stages: virtual geometry reconstruction (pins, disks,
roughness patches) -> pin levelling by torque balance and set averaging -> homogenisation
of every patch pair and the patch average -> Stribeck sweeps (one per viscosity) -> CSV,
plots, VTU/PVD, JSON summary, log.
Every stage writes its results atomically; finished results (and the checkpoints inside
long stages) are reused when the job runs again, so an interrupted run resumes.
"""

from __future__ import annotations

import json
import logging
import os
import time
from contextlib import contextmanager

import numpy as np

from ..case import Case
from ..errors import InputError, RunLocked
from ..io.atomic import atomic_path, remove_debris
from ..io.layout import RunLayout
from ..io.writers import Writers
from ..numerics.threads import executor_for, one_thread, side_threads
from ..stribeck import read_measured_csv
from .curves import stribeck_curves
from .factors import homogenise_patches
from .geometry import level_pins, reconstruct_geometry
from .provenance import provenance, stage_keys

log = logging.getLogger("fem_twin")


@one_thread
def run(case: Case, outdir, *, progress: bool = True, estimated_s: float | None = None) -> dict:
    """Run the whole pipeline of ``case`` into ``outdir``; return the summary.
    ``estimated_s``, the run's estimated wall time [s] (``fem-twin run`` passes what it
    printed), is kept in the summary beside the measured one."""
    out = RunLayout(outdir)
    outdir = out.root
    if outdir.exists() and not outdir.is_dir():
        raise InputError(f"{outdir} is a file: give a folder for the results (-o)")
    sw = case.sweep
    for path in case.measured:                 # [validation] curves: checked before any work
        if path is not None:
            speed = read_measured_csv(path).speed
            if not np.any((speed >= sw.speed_min) & (speed <= sw.speed_max)):
                raise InputError(f"[validation] {path}: its speeds ({speed.min():.3g} to "
                                 f"{speed.max():.3g} m/s) lie outside the case's sweep "
                                 f"({sw.speed_min:g} to {sw.speed_max:g} m/s)")
    outdir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    summary = {"case": case.name, "provenance": provenance(case), "stages": {},
               "seconds": {}}
    with (_lock(out), _logfile(out.log),
          executor_for(case.run.workers, case.run.scheduler) as executor):
        log.info("case %s -> %s", case.source, outdir)
        writers = Writers(executor)         # files written beside the stages that follow
        _run_stages(case, out, executor, progress, summary,
                    ("stribeck", lambda: stribeck_curves(case, out, executor, progress,
                                                         writers)), writers)
        graph = None if executor is None else executor.submit(_task_graph, case, out)
        writers.wait()
        summary["task_graph"] = _task_graph(case, out) if graph is None else graph.result()
    summary["wall_time_s"] = time.perf_counter() - t0
    if estimated_s is not None:
        summary["estimated_s"] = float(estimated_s)
    with atomic_path(out.summary) as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    return summary


def _run_stages(case: Case, out: RunLayout, executor, progress, summary, last,
                writers: Writers | None = None) -> None:
    """The stages up to the flow factors, then ``last`` (name, callable), each timed and
    logged into ``summary``; the flow factors' figure on ``writers`` (else at once).  The
    levelling (the pins) runs in a thread beside the micro stage (the patches), its pins on
    the same workers: on the bundled case it took 1.5 s before the micro stage began."""
    invalidate_changed_stages(case, out)

    def stage(name, work):
        t = time.perf_counter()
        log.info("stage %s", name)
        try:
            summary["stages"][name] = work()
        except BaseException:
            log.exception("stage %s failed", name)    # run.log only (see cli)
            raise
        summary["seconds"][name] = round(time.perf_counter() - t, 2)
        log.info("stage %s done in %.1f s", name, summary["seconds"][name])

    stage("geometry", lambda: reconstruct_geometry(case, out, progress, executor))
    with side_threads() as beside:
        levelling = beside.submit(stage, "levelling",
                                  lambda: level_pins(case, out, progress, executor))
        stage("micro", lambda: homogenise_patches(case, out, executor, progress,
                                                  writers=writers))
        levelling.result()
    stage(*last)


@one_thread
def traction(case: Case, outdir, entrainment: float, ratios, *, progress: bool = True) -> dict:
    """Traction curves of the ball-on-disk ``case`` (C_f versus SRR at ``entrainment``
    [m/s], :mod:`fem_twin.stages.traction`) into ``outdir``, with the stages before them
    cached and resumed as in :func:`run`; returns the summary (not written: the folder's
    ``summary.json`` belongs to ``fem-twin run``)."""
    from .traction import traction_curves
    if not case.tribometer.ball:
        raise InputError("a traction curve needs a rolling-sliding contact: [tribometer] "
                         "kind = \"ball-on-disk\" (a pin on a disk only slides)")
    out = RunLayout(outdir)
    out.root.mkdir(parents=True, exist_ok=True)
    summary = {"case": case.name, "stages": {}, "seconds": {}}
    with (_lock(out), _logfile(out.log),
          executor_for(case.run.workers, case.run.scheduler) as executor):
        _run_stages(case, out, executor, progress, summary,
                    ("traction", lambda: traction_curves(case, out, entrainment, ratios,
                                                         executor, progress)))
    return summary


def _task_graph(case: Case, out: RunLayout) -> dict:
    """The run's task graph and its wall time on more workers
    (:func:`fem_twin.runtime.taskgraph.scaling`; on a worker beside the last files, 1.5 s of the
    bundled case); an empty dict, logged, if it cannot be read."""
    from ..runtime.taskgraph import scaling
    try:
        return scaling(case, out.root)
    except (OSError, ValueError, KeyError) as err:
        log.warning("the run's task graph could not be read back: %s", err)
        return {}


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
        gone = remove_debris(out.root)
        if gone:
            log.info("removed %d temporary file(s) an interrupted run left in %s", gone,
                     out.root)
        yield
    finally:
        f.close()


