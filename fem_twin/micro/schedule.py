"""Which separations of a patch pair run where: resumed from the checkpoints, in this
process, or as chunks on a process pool or a Dask executor (each chunk warm-starts contact
along its own h0 values, large to small)."""

from __future__ import annotations

import os
from concurrent.futures import as_completed
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..numerics.threads import one_thread, process_pool, stop_pool, worker_heap
from .sliding import (
    cell_solver,
    factors_from_moments,
    half_pass_moments,
    instants,
    refine_instants,
    sliding_pass,
    time_average,
)
from .store import cell_key, load_point, save_point


class Separations:
    """The moments at the separations ``h0[i]`` of one run: resumed from the checkpoint
    folder or computed (in this process, or as ``4 workers`` jobs on a pool or
    ``executor``: chunks of h0, each large to small so that contact warm-starts along h0,
    and each in its two halves of instants, :func:`halves`)."""

    def __init__(self, h0, args, workers, executor, bar):
        self.h0, self.args, self.workers, self.executor, self.bar = (h0, args, workers,
                                                                     executor, bar)
        self.done, self.computed, self.own = {}, [], False

    def factors(self, indices):
        """Eqs 11-16 at ``h0[indices]`` (sorted), and over every other instant (None
        without the time-error estimate)."""
        moments = self.moments(indices)
        half = (factors_from_moments(self.h0[indices], moments, {}, prefix="half_")
                if all("half_h" in m for m in moments) else None)
        return factors_from_moments(self.h0[indices], moments, {}), half

    def moments(self, indices) -> list:
        todo = [i for i in sorted(indices, reverse=True) if i not in self.done]
        folder = self.args["folder"]
        for i in todo:
            m = None if folder is None else load_point(Path(folder), self.args["key"],
                                                        self.h0[i])
            if m is not None:
                self.done[i] = m
                self.bar.update(1)
        todo = [i for i in todo if i not in self.done]
        serial = self.workers <= 1 and self.executor is None
        parts = halves(self.args["settings"], self.args.get("half_pass", True))
        chunks = [[(i, self.h0[i]) for i in c] for c in split_chunks(
            todo, 1 if serial else max(1, 4 * max(self.workers, 2) // parts))]
        jobs = [(c, part) for c in chunks for part in range(parts)]
        parts = {}
        for i, m in (self._serial(jobs) if serial else self._parallel(jobs)):
            if "part" in m:                              # a half of the instants
                parts.setdefault(i, {})[m["part"]] = m
                if len(parts[i]) < 2:
                    continue
                m = joined_halves(parts.pop(i), self.args, self.h0[i])
            self.done[i] = m
            self.computed.append(i)
            self.bar.update(1)
        return [self.done[i] for i in indices]

    def _serial(self, jobs):
        for chunk, part in jobs:
            yield from run_chunk(chunk, **self.args, part=part)

    def _parallel(self, jobs):
        if self.executor is None:            # one own pool for all the calls of a run
            self.executor, self.own = process_pool(self.workers), True
        futures = [self.executor.submit(chunk_task, (c, {**self.args, "part": part}))
                   for c, part in jobs]
        try:
            for fut in as_completed(futures):
                yield from fut.result()
        except BaseException:
            for fut in futures:
                fut.cancel()
            raise

    def close(self, failed: bool = False):
        if self.own:
            stop_pool(self.executor, failed)

    def seconds(self) -> dict:
        """CPU seconds of contact and cells over the computed (not resumed) separations."""
        done = [self.done[i] for i in self.computed]
        return {"contact": sum(m.get("seconds_contact", 0.0) for m in done),
                "cell": sum(m.get("seconds_cell", 0.0) for m in done),
                "computed_h0": len(done)}


@one_thread
def chunk_task(job):
    """``run_chunk`` as one positional argument: executors may own keywords (Dask's
    ``submit`` takes ``key`` for itself)."""
    worker_heap()
    points, args = job
    return run_chunk(points, **args)


def halves(settings, half_pass: bool = True) -> int:
    """How many tasks each separation's instants take under ``settings``: two, the even and
    the odd ones, where they are independent of each other and the even ones are the half
    pass of the time-error estimate (``half_pass``; the exact squeeze term, an even number
    of fixed instants); else one."""
    return 2 if (half_pass and settings.time_derivative == "exact"
                 and settings.time_tol is None and settings.steps % 2 == 0) else 1


def joined_halves(parts: dict, args: dict, h0: float) -> dict:
    """The moments of one separation from its two halves of instants (:func:`halves`):
    the mean over all instants, the even ones' as the half pass; checkpointed."""
    even, odd = parts[0], parts[1]
    n = even["n"] + odd["n"]
    moments = {k: (even["sum"][k] + odd["sum"][k]) / n for k in even["sum"]}
    moments.update({"half_" + k: v / even["n"] for k, v in even["sum"].items()})
    moments["n_steps"] = n
    moments["seconds_contact"] = even["seconds"][0] + odd["seconds"][0]
    moments["seconds_cell"] = even["seconds"][1] + odd["seconds"][1]
    moments["seconds_halves"] = [sum(even["seconds"]), sum(odd["seconds"])]
    if args["folder"] is not None:
        save_point(Path(args["folder"]), args["key"], h0, moments)
    return moments


def run_chunk(points, *, z_low, z_up, spacing, settings, folder, key, half_pass=True,
              part=0):
    """Moments for ``points = [(index, h0), ...]`` in order, warm-starting contact; with
    :func:`halves` two, only the even (``part`` 0) or the odd instants, their sums."""
    solver = cell_solver(z_low.shape, spacing, settings.method)
    sliding = sliding_pass(z_low, z_up, spacing, settings)
    split = halves(settings, half_pass) == 2
    if split:
        sliding = replace(sliding, shapes=sliding.shapes[part::2],
                          moving=sliding.moving[part::2],
                          rigid_rate=sliding.rigid_rate[part::2])
    warm, midpoints = [None] * len(sliding.shapes), {}
    out = []
    for i, h0 in points:
        contacts, steps, seconds = instants(sliding, h0, warm, solver, spacing, settings)
        if split:
            out.append((i, {"part": part, "n": len(steps), "seconds": seconds,
                            "sum": {k: sum(m[k] for m in steps) for k in steps[0]}}))
            continue
        if settings.time_tol is not None:
            contacts, steps, more = refine_instants(contacts, steps, h0, z_low, z_up, solver,
                                                    spacing, settings, midpoints)
            seconds = [a + b for a, b in zip(seconds, more)]
        moments = time_average(steps)
        moments["n_steps"] = len(steps)
        if half_pass and settings.steps % 2 == 0:   # N_t / 2 instants: time-error estimate
            half = half_pass_moments(steps, contacts, sliding, solver, spacing, settings)
            moments.update({"half_" + k: v for k, v in time_average(half).items()})
        moments["seconds_contact"], moments["seconds_cell"] = seconds
        if folder is not None:
            save_point(Path(folder), key, h0, moments)
        out.append((i, moments))
    return out


def split_chunks(indices, n):
    n = max(1, min(n, len(indices)))
    return [list(c) for c in np.array_split(np.asarray(indices, dtype=int), n) if len(c)]


def progress_bar(total, enabled, patch_id=None, adaptive=False):
    """Bar over the h0 values (adaptive: over the candidates, of which a part is solved)."""
    from tqdm.auto import tqdm
    desc = f"homogenise {patch_id or 'h0'}" + (" (adaptive h0)" if adaptive else "")
    return tqdm(total=total, desc=desc, unit="h0",
                disable=not enabled or os.environ.get("FEM_TWIN_NO_PROGRESS") == "1")


def coarse_moments(points, indices, z_low, z_up, spacing, settings, checkpoint):
    """``(moments, settings, key, shape)`` of the cell coarsened by two (every other pixel) at the
    separations ``h0[indices]``, with half the instants when the run has its half pass
    (the same pixels per step), on the run's workers; None for a small or odd cell."""
    if min(z_low.shape) < 16 or z_low.shape[0] % 2 or z_low.shape[1] % 2:
        return None
    low, up = z_low[::2, ::2].copy(), z_up[::2, ::2].copy()
    wide = (2 * spacing[0], 2 * spacing[1])
    if settings.steps % 2 == 0:
        settings = replace(settings, steps=settings.steps // 2)
    key = cell_key(low, up, wide, settings)
    args = dict(z_low=low, z_up=up, spacing=wide, settings=settings, key=key,
                folder=None if checkpoint is None else str(Path(checkpoint) / "coarse"),
                half_pass=False)
    runner = Separations(points.h0, args, points.workers, points.executor,
                          progress_bar(len(indices), False))
    try:
        out = runner.moments(indices), settings, key, list(low.shape)
    except BaseException:
        runner.close(failed=True)            # only a pool of its own (the run's stays)
        raise
    runner.close()
    return out
