"""The task graph of a finished run, and what it would take on more workers.

Each task is timed as it ran: per patch pair, rounds of separations h0 (the adaptive
sampler asks for a round only after the previous one; each h0 a task), then the coarsened
cell's pass of the grid-error estimate; after every patch, per viscosity, the sweep's guide
(one chain of warm-started points on the coarsest grid) and then each of its points (its
solve, nested coarse solve, error estimate and a thermal run's earlier iterations), the
refinement's guide and added points, and the patch band's sweeps (chains, which start from
the guide's points).  The rounds are replayed from the checkpoints (the sampler is
deterministic).  :func:`~fem_twin.runtime.schedule.makespan` schedules the graph greedily on
``workers`` processes, :func:`~fem_twin.runtime.schedule.critical_path` is the bound no number
of workers beats.  Left out: the geometry, levelling and result writing (serial), and what
one-h0 tasks lose against chunks of several h0, which warm-start contact along them
(docs/performance.md, "How many workers")."""

from __future__ import annotations

from collections import defaultdict

import numpy as np

from ..case import Case
from ..errors import FemTwinError, MissingFile
from ..io.layout import RunLayout
from ..micro import FlowFactors
from ..micro.sampling import adaptive_separations
from ..micro.sliding import factors_from_moments
from ..micro.store import point_path, read_point
from ..stribeck.sweep import GUIDED_BY, LEVEL_OF, point_files, point_key, readable_meta
from .schedule import Task, critical_path, makespan


def run_task_graph(case: Case, outdir) -> list[Task]:
    """The tasks of the finished run of ``case`` in ``outdir``, in submission order."""
    out = RunLayout(outdir)
    micro = [t for k in range(1, len(case.geometry.patches) + 1)
             for t in patch_tasks(case, out, k)]
    return micro + sweep_tasks(out.points, case.sweep.speeds, tuple(t.name for t in micro),
                               ball=case.tribometer.ball, refine=case.sweep.refine > 0,
                               band_beside=case.band_after_guides(case.macro_shape))


def patch_tasks(case: Case, out: RunLayout, k: int) -> list[Task]:
    """The h0 tasks of patch pair ``k``, round by round, then its coarse-cell pass."""
    ff = FlowFactors.load(out.patch_factors(k))
    if ff.screening:                                     # closed forms: no cell tasks
        return []
    folder, keys = out.patch_checkpoints(k), ff.meta["checkpoint_keys"]
    mc = case.micro
    h0 = mc.h0_candidates(ff.meta.get("h0_candidates"))
    rounds = _rounds(h0, folder, keys[0], ff.meta.get("h0_tol"))
    tasks, before = [], ()
    for r, indices in enumerate(rounds):
        new = [Task(f"patch {k} round {r + 1} h0 {h0[i]:.4e}{name}", seconds, before)
               for i in indices for name, seconds in _halves(_moments(folder, keys[0], h0[i]))]
        tasks += new
        before = tuple(t.name for t in new)
    if len(keys) > 1:                                    # the coarse cell (grid estimate)
        tasks += [Task(f"patch {k} coarse h0 {h:.4e}",
                       _seconds(_moments(folder / "coarse", keys[1], h)), before)
                  for h in ff.h0]
    return tasks


def _rounds(h0, folder, key, h0_tol) -> list[list[int]]:
    """The h0 indices each round of the sampler asked for (one round without it)."""
    if not h0_tol:
        return [list(range(len(h0)))]
    rounds, seen = [], set()

    def factors_at(indices):
        rounds.append(sorted(set(indices) - seen))
        seen.update(indices)
        moments = [_moments(folder, key, h0[i]) for i in indices]
        half = (factors_from_moments(h0[indices], moments, {}, prefix="half_")
                if all("half_h" in m for m in moments) else None)
        return factors_from_moments(h0[indices], moments, {}), half
    adaptive_separations(h0, factors_at, h0_tol)
    return [r for r in rounds if r]


def _moments(folder, key, h0) -> dict:
    """A checkpoint's moments as they are (an earlier fem_twin's set too: the task graph
    reads its times and the factors of its adaptive rounds), never set aside."""
    try:
        return read_point(point_path(folder, key, h0), key, h0, required=("h",))
    except (OSError, ValueError, KeyError, FemTwinError):
        raise MissingFile(f"{folder}: the run's h0 checkpoint at {h0:.4e} m is missing or "
                          "unreadable") from None


def _seconds(moments) -> float:
    return float(moments.get("seconds_contact", 0.0) + moments.get("seconds_cell", 0.0))


def _halves(moments) -> list:
    """``[(name, seconds)]`` of one separation's tasks: its even and odd instants where it
    ran them apart (:func:`~fem_twin.micro.schedule.halves`), else one."""
    if "seconds_halves" in moments:
        return [(f" {half} instants", float(s)) for half, s in
                zip(("even", "odd"), moments["seconds_halves"])]
    return [("", _seconds(moments))]


def sweep_tasks(folder, first, micro: tuple[str, ...], *, ball: bool = False,
                refine: bool = True, band_beside: bool = False) -> list[Task]:
    """The sweeps checkpointed in ``folder``, after the tasks ``micro``: the first passes
    over the speeds ``first`` (all speeds where None; a guide's chain of points, each of its
    guided points a task after the guide's point there; or a sweep as one chain), then the
    refinement's, then the band's (the nested levels the main points kept for the band are
    part of those points), after the main points or, with ``band_beside``, beside them
    (:meth:`~fem_twin.case.Case.band_after_guides`)."""
    chains, points = defaultdict(list), []
    for path in point_files(folder):
        if (read := readable_meta(path)) is None:          # set aside: the next run redoes it
            continue
        scalars, meta = read
        if LEVEL_OF in meta:
            continue
        speed = meta.get("entrainment") if ball else scalars["speed"]
        seconds = sum(meta.get(k, 0.0) for k in ("seconds", "seconds_coarse",
                                                   "seconds_estimate", "seconds_thermal"))
        if GUIDED_BY in meta:
            points.append((point_key(path), speed, seconds, meta[GUIDED_BY]))
        else:
            chains[point_key(path)].append((speed, seconds, "error_estimate" in meta))
    guides = {g for *_, g in points}
    main = {k: v for k, v in chains.items() if k in guides or any(e for _, _, e in v)}
    first = None if first is None else np.asarray(first, float)

    def in_first(u) -> bool:
        return first is None or bool(np.isclose(u, first, rtol=1e-9).any())

    passes, ends = [], {}
    for k, v in main.items():
        first_pass = [(u, s) for u, s, _ in v if in_first(u)]
        passes += (_guide_chain(k, first_pass, micro) if k in guides else
                   [Task(f"sweep {k}", sum(s for _, s in first_pass), micro)])
        ends[k] = passes[-1].name
    names = {t.name for t in passes}
    ahead = [Task(f"point {k} {u:.9e}", s, (f"sweep {g} {u:.9e}"
                                            if f"sweep {g} {u:.9e}" in names else ends[g],))
             for k, u, s, g in points if in_first(u)]
    done = tuple(t.name for t in passes + ahead)
    refined = [Task(f"refinement {k}", sum(s for u, s, _ in v if not in_first(u)), done)
               for k, v in main.items() if k not in guides]
    refined += [Task(f"refinement {k} {u:.9e}", s, done)              # side by side
                for k, v in main.items() if k in guides for u, s, _ in v if not in_first(u)]
    later = [Task(f"point {k} {u:.9e}", s, (f"refinement {g} {u:.9e}",))
             for k, u, s, g in points if not in_first(u)]
    band = {k: v for k, v in chains.items() if k not in main}
    if band_beside:
        return passes + ahead + refined + later + _band_beside(
            band, guides, in_first, {t.name for t in refined}, ends)
    band_after = tuple(t.name for t in refined + later) if refine else done
    return passes + ahead + refined + later + [
        Task(f"band sweep {k}", sum(s for _, s, _ in v), band_after) for k, v in band.items()]


def _guide_chain(key: str, speeds, after: tuple[str, ...]) -> list[Task]:
    """A guide's first pass ``[(speed, seconds)]`` as a chain of point tasks, fast to slow
    (each guided point starts once its guide's point is checkpointed)."""
    tasks = []
    for u, s in sorted(speeds, key=lambda p: -p[0]):
        tasks.append(Task(f"sweep {key} {u:.9e}", s, (tasks[-1].name,) if tasks else after))
    return tasks


def _band_beside(band: dict, guides: set, in_first, refined: set, ends: dict) -> list[Task]:
    """The band's chains where they start from the guides: each first pass after the
    guides' first passes (their last tasks, ``ends``), each refined speed after the band's
    first pass and the guides' points there (among the ``refined`` task names).  The
    curves of all viscosities share their speeds, so a band sweep waits for every guide,
    not only its viscosity's."""
    tasks = [Task(f"band sweep {k}", sum(s for u, s, _ in v if in_first(u)),
                  tuple(ends[g] for g in guides)) for k, v in band.items()]
    return tasks + [Task(f"band refinement {k} {u:.9e}", s, (f"band sweep {k}", *(
        name for g in guides if (name := f"refinement {g} {u:.9e}") in refined)))
                    for k, v in band.items() for u, s, _ in v if not in_first(u)]


#: worker counts of :func:`scaling`'s estimates
WORKERS = (1, 2, 4, 8, 16, 64)


def scaling(case: Case, outdir) -> dict:
    """The run's task graph in numbers (``summary.json`` ``"task_graph"``): task count, CPU
    seconds, critical path and the wall time of its tasks on each of :data:`WORKERS`
    processes [s] (the serial stages and the writing of results not included)."""
    return in_numbers(run_task_graph(case, outdir))


def fit_scaling(case: Case, outdir) -> dict:
    """The task graph of a fit's own sweeps (``OUT/fit/checkpoints``: load shares, thermal
    resistances; each a guide, then its points) in numbers (``fit.json`` ``"task_graph"``),
    as :func:`scaling`'s.  Every speed of a fit's sweep runs in one pass."""
    return in_numbers(sweep_tasks(RunLayout(outdir).fit_points, None, (),
                                  ball=case.tribometer.ball))


def in_numbers(tasks) -> dict:
    """Task count, CPU seconds, critical path and wall on :data:`WORKERS` workers [s]."""
    return {"tasks": len(tasks), "cpu_s": round(sum(t.seconds for t in tasks), 1),
            "critical_path_s": round(critical_path(tasks), 1),
            "wall_s": {str(w): round(makespan(tasks, w), 1) for w in WORKERS}}
