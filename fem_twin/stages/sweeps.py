"""The Stribeck sweeps of a stage as tasks: serial, or on a pool of workers (local processes
or Dask), largest first: a sweep's points each a task after its guide, or chains of speeds."""

from __future__ import annotations

from concurrent.futures import wait
from dataclasses import dataclass, replace
from pathlib import Path
from types import SimpleNamespace
from typing import NamedTuple

import numpy as np
from tqdm import tqdm

from ..errors import ForeignCheckpoint
from ..io.checkpoint import check_made_for
from ..macro.estimate import is_current
from ..macro.nested import nested_levels
from ..numerics.threads import worker_heap
from ..runtime.cost import sweep_cost
from ..stribeck import stribeck_sweep
from ..stribeck.curve import joined
from ..stribeck.sweep import (
    checkpointed,
    curve_of_records,
    point_file,
    point_files,
    point_key,
    point_record,
    readable_meta,
)


@dataclass(frozen=True)
class SweptPoint:
    """A checkpointed point of a sweep: the ``sweep`` (the request's index in the tasks),
    its sweep ``speed`` [m/s] (sliding, or entrainment, by the request's motion), its
    checkpoint ``path``, and its ``meta`` and ``scalars`` (those of
    :meth:`~fem_twin.macro.MixedResult.scalars`), read once without the fields."""

    sweep: int
    speed: float
    path: Path
    meta: dict
    scalars: dict


class Swept(NamedTuple):
    """What :func:`run_sweeps` returns: the ``curves`` in the order of the tasks, and the
    ``points`` of the checkpointed ones (:func:`point_index`)."""

    curves: list
    points: tuple[SweptPoint, ...]


def point_index(tasks) -> tuple[SweptPoint, ...]:
    """The checkpointed points of the sweeps ``tasks``, each sweep's fast to slow, each
    checkpoint read once without its fields (the writers and checks take this index)."""
    out = []
    for i, task in enumerate(tasks):
        if task.checkpoint is None:
            continue
        found = []
        for path in point_files(task.checkpoint, task.key):
            if (read := readable_meta(path)) is None:
                continue
            scalars, meta = read
            found.append(SweptPoint(i, task.motion.sweep_speed(scalars["speed"], meta), path,
                                    meta, scalars))
        out += sorted(found, key=lambda p: -p.speed)
    return tuple(out)


class Plan(NamedTuple):
    """The work of :func:`run_sweeps`' tasks (:func:`plan`), in the order it runs: the
    ``guides``' chains of their missing points, first; the unguided sweeps as ``chains``,
    each ``(sweep, request)`` (the sweep: its task's index), beside them; then the guided
    sweeps' missing ``points``, each a task after its guide's point there, and the
    ``followers``' chains (:func:`missing_chains`), each after the guides' points at its
    speeds."""

    guides: list
    chains: list
    points: list
    followers: list


def plan(tasks, workers: int, followers=(), whole: bool = False) -> Plan:
    """The :class:`Plan` of the sweeps ``tasks`` and ``followers`` on ``workers`` workers
    (``whole``: each unguided sweep one chain, :func:`chains`)."""
    guides = [guide_of(task) for task in tasks]
    unguided = [i for i, guide in enumerate(guides) if guide is None]
    pieces = chains([tasks[i] for i in unguided], workers, whole)
    return Plan(guides=[chain for guide in guides if guide is not None
                        for chain in missing_chains(guide)],
                chains=[(unguided[j], piece) for j, piece in pieces],
                points=[point for task, guide in zip(tasks, guides) if guide is not None
                        for point in guided_points(task, guide.key)],
                followers=[chain for sweep in followers for chain in missing_chains(sweep)])


def run_sweeps(tasks, executor=None, progress: bool = True, desc: str = "Stribeck points",
               followers=(), whole: bool = False) -> Swept:
    """The sweep requests ``tasks``, serial or as process tasks on ``executor``: their curves
    in the order of ``tasks`` and the index of their checkpointed points (:class:`Swept`).
    ``followers``: sweeps that start from the guides' points (the patch band), run beside
    the guided points as chains of their missing speeds (:func:`missing_chains`) and left
    in their checkpoints.  On a pool each guided sweep starts as soon as its guide's points
    at its speeds are checkpointed, not after every guide (:func:`_run`).  ``whole``: each
    sweep without a guide runs as one chain, each missing point warm from the one before
    (a refinement's last pass), however many the workers.

    A checkpointed sweep without a guide runs as guided points: first its guide
    (:func:`guide_of`, a chain on the coarsest nested grid), then every speed a task of its
    own, started from the guide's point there (``solve_nested``'s guide), then its curve
    read from the index's scalars, without the points' fields (:func:`indexed_curve`).  The
    others run as chains of speeds (:func:`chains`): a band sweep, each point warm from its
    previous one and its guide's change (a band point from its guide alone can take ten
    times as long in the mixed regime), a sweep without checkpoints or coarser levels.
    Tasks go largest first; the work is the same whatever the workers, so the curves do
    not depend on them."""
    workers = 1 if executor is None else getattr(executor, "n_workers", 1)
    work = plan(tasks, workers, followers, whole)
    ran = _run([*work.guides, *(chain for _, chain in work.chains)], executor, progress,
               desc, [*work.points, *work.followers])
    own = {}
    for (sweep, _), curve in zip(work.chains, ran[len(work.guides):]):  # not the guides'
        own.setdefault(sweep, []).append(curve)
    points = point_index(tasks)
    curves = [joined(own[i]) if i in own else indexed_curve(task, i, points)
              for i, task in enumerate(tasks)]
    if any(curve is None for curve in curves):      # read whole, which may add estimates
        curves = [stribeck_sweep(task) if curve is None else curve
                  for task, curve in zip(tasks, curves)]
        points = point_index(tasks)
    return Swept(curves, points)


def indexed_curve(task, sweep: int, points):
    """The curve of the checkpointed ``task`` from the scalars and meta of its points in
    ``points`` (:func:`point_index`; ``sweep``: its index there), without their fields; or
    None where :func:`~fem_twin.stribeck.stribeck_sweep` must read them whole: a speed
    without a point made for it, a point without the error estimate the task asks for, or a
    task that writes fields."""
    if task.checkpoint is None or task.fields is not None:
        return None
    own = {p.path: p for p in points if p.sweep == sweep}
    found = [own.get(point_file(task.checkpoint, task.key, u)) for u in task.speeds]
    try:
        for point, u in zip(found, task.speeds):
            if point is None or (task.error_estimate and not is_current(point.meta, task.settings)):
                return None
            check_made_for(point.meta, task.key, u, point.path)
    except ForeignCheckpoint:
        return None
    return curve_of_records([point_record(SimpleNamespace(**p.scalars, meta=p.meta))
                             for p in found], task)


def guide_of(request):
    """The guide of a checkpointed ``request`` without one: the same sweep on the coarsest
    nested grid (:func:`~fem_twin.macro.nested.nested_levels`), a chain of warm-started
    points, without estimates or fields; None where the grid has no coarser level."""
    levels = nested_levels(request.gap.shape)
    if request.checkpoint is None or request.guide is not None or levels == 0:
        return None
    return replace(request.coarsened(levels), error_estimate=False, fields=None,
                   keep_level=0)


def missing_chains(sweep) -> list:
    """The checkpointed ``sweep`` as chains: whole while none of its points is checkpointed
    (a first pass), else each run of missing speeds after the checkpointed point before it
    (a refinement's midpoints, side by side)."""
    key = sweep.key
    have = [checkpointed(sweep.checkpoint, key, u) for u in sweep.speeds]
    if all(have):
        return []
    if not any(have):
        return [sweep]
    starts = [i for i in range(len(have)) if not have[i] and (i == 0 or have[i - 1])]
    ends = [next((j for j in range(i, len(have)) if have[j]), len(have)) for i in starts]
    return [replace(sweep, speeds=sweep.speeds[max(i - 1, 0):j]) for i, j in zip(starts, ends)]


def guided_points(request, guide: str) -> list:
    """Each speed of ``request`` not yet checkpointed as a sweep of its own, started from
    the point there of the sweep ``guide`` (its key); a kept level that is the guide's is
    the guide's own point."""
    key = request.key
    kept = request.level_key(request.keep_level) if request.keep_level else key
    keep = 0 if kept == guide else request.keep_level
    return [replace(request, speeds=request.speeds[i:i + 1], guide=guide, fields=None,
                    keep_level=keep) for i in range(request.speeds.size)
            if not checkpointed(request.checkpoint, key, request.speeds[i])]


def _run(requests, executor, progress: bool, desc: str, guided=()) -> list:
    """The sweeps ``requests``, serial or on ``executor`` largest first (:func:`_cost`), and
    the ``guided`` ones after them, each submitted once its guide's points are checkpointed
    (:func:`_guide_done`) or nothing else runs, none after a failure; the results of
    ``requests``.  The bar counts their finished points (checkpoint files, written as each
    point finishes)."""
    every = [*requests, *guided]
    if executor is None or len(every) <= 1:
        single = len(every) == 1                      # its own bar, by points
        bar = tqdm(every, desc=desc, unit="task", disable=not progress or single)
        return [_sweep_task((r, progress and single)) for r in bar][:len(requests)]
    order = sorted(range(len(requests)), key=lambda j: -sweep_cost(requests[j]))
    submitted = {j: executor.submit(_sweep_task, (requests[j], False)) for j in order}
    futures = [submitted[j] for j in range(len(requests))]
    running, waiting = list(futures), list(guided)
    total = sum(r.speeds.size for r in every)
    keys = {r.key for r in every if r.factors_key and r.checkpoint is not None}
    folders = {r.checkpoint for r in every if r.checkpoint is not None}
    with tqdm(total=total, desc=desc, unit="point", disable=not progress) as bar:
        while (busy := wait(running, timeout=0.5).not_done) or waiting:
            if any(f.done() and f.exception() is not None for f in running):
                waiting = []                                  # raised below
            ready = [not busy or _guide_done(r) for r in waiting]
            running += [executor.submit(_sweep_task, (r, False))
                        for r, go in zip(waiting, ready) if go]
            waiting = [r for r, go in zip(waiting, ready) if not go]
            done = sum(point_key(p) in keys for f in folders for p in point_files(f))
            bar.update(min(done, total) - bar.n)
        bar.update(total - bar.n)
    for future in running:
        future.result()
    return [f.result() for f in futures]


def _guide_done(request) -> bool:
    """Whether the points of ``request``'s guide at its speeds are all checkpointed."""
    guide, folder = request.guide, request.checkpoint
    return guide is None or all(point_file(folder, guide, u).exists() for u in request.speeds)


def chains(tasks, workers: int, whole: bool = False) -> list:
    """``[(task, request)]``: each sweep of ``tasks`` as chains of consecutive speeds, in
    order.  Unless ``whole``, a sweep that writes no fields and costs (:func:`_cost`) more
    than an even share of the total over ``workers`` is cut into chains of about equal
    length, each costing at most half such a share (one point at least), so that a
    largest-first schedule keeps every worker busy to the end.  A chain's first point
    starts cold (from the coarsest nested level), about as fast as a warm one on fine grids
    and with the same C_f to 2e-6 (the resolution study's 999^2 sweep, ``fem-twin
    calibrate --study resolution``; the cutting: ``tests/test_scaleout.py::
    test_a_sweep_longer_than_a_workers_share_runs_as_chains``).  A sweep that writes fields
    stays whole (one VTU per speed, numbered along the sweep, and one PVD)."""
    share = sum(map(sweep_cost, tasks)) / max(workers, 1)
    out = []
    for i, task in enumerate(tasks):
        n = task.speeds.size
        one = whole or workers <= 1 or task.fields is not None or sweep_cost(task) <= share
        count = 1 if one else min(n, int(np.ceil(2 * sweep_cost(task) / share)))
        out += [(i, replace(task, speeds=task.speeds[part]))
                for part in np.array_split(np.arange(n), count)]
    return out


def _sweep_task(args):
    """One sweep ``(request, progress)`` (a picklable unit of work for pools and Dask)."""
    worker_heap()
    return stribeck_sweep(*args)
