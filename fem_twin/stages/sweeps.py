"""The Stribeck sweeps of a stage as tasks: serial, or chains of speeds on a pool of
workers (local processes or Dask), largest first."""

from __future__ import annotations

from concurrent.futures import wait
from dataclasses import replace

import numpy as np
from tqdm import tqdm

from ..stribeck import stribeck_sweep
from ..stribeck.curve import joined
from ..stribeck.sweep import point_files, point_key
from ..numerics.threads import worker_heap

#: how a sweep point's time grows with the grid's nodes N, as N^COST_GROWTH (the resolution
#: study's points grow as N^1.39 from 500^2 to 1997^2, benchmarks/README.md), so that the
#: largest-first schedule starts the finest grids' points first
COST_GROWTH = 1.35


def run_sweeps(tasks, executor=None, progress: bool = True, desc: str = "Stribeck points"):
    """The sweep requests ``tasks``: serial, or in process tasks on ``executor``.

    In parallel a sweep that costs more than a worker's even share (:func:`chains`) is cut
    into chains of consecutive speeds, each started cold, so that the resolution study's
    1997^2 sweep runs on both cores instead of alone on one; the chains are submitted
    largest first, and the bar counts the finished points of all sweeps (their checkpoint
    files, written as each point finishes in its worker).  The curves come back in the
    order of ``tasks``, each one's chains joined."""
    pieces = [] if executor is None else chains(tasks, getattr(executor, "n_workers", 1))
    if len(pieces) <= 1:
        return [_sweep_task((task, progress)) for task in tasks]
    order = sorted(range(len(pieces)), key=lambda j: -_cost(pieces[j][1]))
    submitted = {j: executor.submit(_sweep_task, (pieces[j][1], False)) for j in order}
    futures = [submitted[j] for j in range(len(pieces))]
    total = sum(task.speeds.size for task in tasks)
    keys = {task.key for task in tasks if task.factors_key}
    folder = tasks[0].checkpoint
    with tqdm(total=total, desc=desc, unit="point", disable=not progress) as bar:
        while wait(futures, timeout=0.5).not_done:            # the bar, twice a second
            if folder is not None and keys:                   # points finished so far
                bar.update(sum(point_key(p) in keys for p in point_files(folder)) - bar.n)
        bar.update(total - bar.n)
    return [joined([f.result() for (i, _), f in zip(pieces, futures) if i == task])
            for task in range(len(tasks))]


def chains(tasks, workers: int) -> list:
    """``[(task, request)]``: each sweep of ``tasks`` as chains of consecutive speeds, in
    order.  A sweep that writes no fields and costs (:func:`_cost`) more than an even
    share of the total over ``workers`` is cut into chains of about equal length, each
    costing at most half such a share (one point at least), so that a largest-first
    schedule keeps every worker busy to the end.  A chain's first point starts cold (from
    the coarsest nested level), about as fast as a warm one on fine grids and with the same
    C_f to 2e-6 (benchmarks/README.md).  A sweep that writes fields stays whole (one VTU per speed,
    numbered along the sweep, and one PVD)."""
    share = sum(map(_cost, tasks)) / max(workers, 1)
    out = []
    for i, task in enumerate(tasks):
        n = task.speeds.size
        whole = workers <= 1 or task.fields is not None or _cost(task) <= share
        count = 1 if whole else min(n, int(np.ceil(2 * _cost(task) / share)))
        out += [(i, replace(task, speeds=task.speeds[part]))
                for part in np.array_split(np.arange(n), count)]
    return out


def _cost(request) -> float:
    """A sweep's cost: speeds times nodes to the power :data:`COST_GROWTH`."""
    return float(request.gap.size) ** COST_GROWTH * request.speeds.size


def _sweep_task(args):
    """One sweep ``(request, progress)`` (a picklable unit of work for pools and Dask)."""
    worker_heap()
    return stribeck_sweep(*args)
