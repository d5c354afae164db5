"""The run-time cost model: a case's wall time on the calibration machine, before it runs.

``fem-twin run`` prints it scaled to this machine by :func:`fem_twin.runtime.machine.slowdown` and
asks for ``--yes`` above four times the bundled case's.  The constants were fitted to the
bundled, paper and ball cases on the calibration machine (``python benchmarks/run.py
estimates`` sets each example's estimate beside its run and checks 0.8-1.25x);
``tests/test_cli.py::test_run_time_estimates_hold`` holds the estimate within 0.8-1.25x of
those runs.
"""

from __future__ import annotations

import math
from dataclasses import replace

from ..macro.nested import nested_levels
from ..macro.reference.point_contact import EXTENT
from ..micro.schedule import halves
from ..numerics.graded_mesh import point_contact_mesh
from .schedule import Task, makespan

#: a guided Stribeck point of a pin at 128^2 [s], its growth with the nodes, and the cost
#: of a main-curve point with its C_f error estimate in plain points
POINT_SECONDS, POINT_GROWTH, ESTIMATE_COST = 0.48, 0.91, 1.28
#: a ball's point at 73^2, started from its 37^2 guide (Newton coupling) [s], and its
#: growth with the grid's side (with the square root of a mesh's nodes)
BALL_POINT_SECONDS, BALL_POINT_GROWTH = 2.4, 2.4
#: a band point in main-curve points, by ``[run] band_grid`` (the band's sweeps converge to
#: ``[run] band_tol`` and carry no error estimate; "coarse" runs them on the coarsened grid)
BAND_POINT_COST = {"coarse": 0.22, "full": 0.54}
#: a band point on a grid coarsened once more, against one on the grid before
BAND_LEVEL_COST = 0.24
#: the Stribeck stage of the thermal twin (``[thermal] model = "flash"``) against the
#: isothermal one: each point iterates its film temperature (from its guide's)
THERMAL_COST = 1.25
#: a pin's guide point (the sweep on its coarsest nested grid, 36-71 px a side, warm-started)
#: [s]; a ball's in its points
GUIDE_SECONDS, GUIDE_COST = 0.21, 0.15
#: the speeds a refinement pass adds to a curve, a pin's and a ball's, at most the curve's
#: count: where C_f jumps, in the mixed regime, whatever the count of speeds (the bundled
#: pin adds 6 to 12, the paper case 7 to 25, the bundled ball 1 to 12)
REFINED_SPEEDS = {False: 7, True: 1}
#: what the main process does alone at a 128^2 macro grid (geometry, levelling, reading
#: the curves back, writing the results) [s], and its growth with the nodes
SERIAL_SECONDS, SERIAL_GROWTH = 16.7, 0.66
#: the name of every micro-stage task begins so (the others are the macro stage's)
MICRO = "patch"
#: rounds of the adaptive h0 sampler per patch pair (a start, bisection, refinement)
H0_ROUNDS = 3
#: micro stage cost per cell pixel, time step and separation on one core [s] (the cell
#: problems, the periodic contact and the coarsened cell of the error estimate)
MICRO_SECONDS = 2.6e-6
#: separations an adaptive h0 sample solves per patch pair: ``a + k / sqrt(h0_tol)`` (at
#: most the candidates)
ADAPTIVE_H0 = (5.5, 2.7)

#: how a sweep point's time grows with the grid's nodes N, as N^COST_GROWTH (the resolution
#: study's points grow as N^1.39 from 500^2 to 1997^2, ``fem-twin calibrate --study
#: resolution``; ``python benchmarks/run.py scale`` times single points), so that the
#: largest-first schedule starts the finest grids' points first
COST_GROWTH = 1.35


def estimated_seconds(case, cores: int = 2, slowdown=None) -> float:
    """Rough wall time of ``fem-twin run`` of ``case`` (a :class:`~fem_twin.case.Case`) on
    ``cores`` workers [s]: its work as tasks (:func:`cost_tasks`) scheduled on them
    (:func:`~fem_twin.runtime.schedule.makespan`), on the calibration machine, or on one
    ``slowdown`` times slower (a :class:`~fem_twin.runtime.machine.Slowdown`: the cells'
    tasks by its ``micro``, the rest by its ``macro`` part)."""
    tasks = cost_tasks(case)
    if slowdown is not None:
        tasks = [replace(t, seconds=t.seconds * (slowdown.micro if t.name.startswith(MICRO)
                                                 else slowdown.macro)) for t in tasks]
    return makespan(tasks, max(cores, 1))


def cost_tasks(case) -> list[Task]:
    """The run's work as tasks with their seconds on one core of the calibration machine,
    as the run's own task graph has them (:mod:`fem_twin.runtime.taskgraph`): per patch pair the
    h0 of each of :data:`H0_ROUNDS` rounds at ``MICRO_SECONDS`` per cell pixel, step and
    separation; per viscosity the sweep's guide, a chain of points, each point after its
    guide's point there (a warm point of ``POINT_SECONDS``, a ball's of
    ``BALL_POINT_SECONDS``, with its error estimate), each
    refined speed's guide point and point (:data:`REFINED_SPEEDS` per pass),
    then the band's chains (:func:`_band_tasks`); last what the main process does alone."""
    micro = _micro_tasks(case)
    thermal = THERMAL_COST if case.thermal.model != "none" else 1.0
    point = _point_seconds(case) * thermal
    guide = GUIDE_COST * point if case.tribometer.ball else GUIDE_SECONDS * thermal
    estimate = (1.0 if case.tribometer.ball or case.micro.model == "average-flow"
                else ESTIMATE_COST)                     # a screening run has no estimate
    count = case.sweep.count
    added = min(count, REFINED_SPEEDS[case.tribometer.ball]) * case.sweep.refine
    after, tasks, guides, again = tuple(t.name for t in micro), [], [], []
    if nested_levels(case.macro_shape) == 0:            # no coarser grid: chains of speeds
        tasks = [Task(f"sweep {v}", estimate * point * (count + added), after)
                 for v in range(len(case.lubricant.viscosities))]
        return micro + tasks + _serial(case, micro + tasks)
    for v in range(len(case.lubricant.viscosities)):
        chain = []                                  # the guide's points, fast to slow
        for i in range(count):
            chain.append(Task(f"guide {v} point {i}", guide,
                              (chain[-1].name,) if chain else after))
        guides.append(chain[-1])
        first = [Task(f"point {v} {i}", estimate * point, (chain[i].name,))
                 for i in range(count)]
        tasks += [*chain, *first]
        for i in range(added):                 # a refined speed: its guide point, then it
            again.append(Task(f"guide {v} {count + i}", guide,
                              tuple(t.name for t in first)))
            tasks += [again[-1], Task(f"point {v} {count + i}", estimate * point,
                                      (again[-1].name,))]
    tasks += _band_tasks(case, point, added, tasks, guides, again)
    return micro + tasks + _serial(case, micro + tasks)


def _serial(case, before) -> list[Task]:
    """What the main process does alone (:data:`SERIAL_SECONDS`), after ``before``."""
    nodes = case.macro_shape[0] * case.macro_shape[1] / 128 ** 2
    return [Task("serial", SERIAL_SECONDS * nodes ** SERIAL_GROWTH,
                 tuple(t.name for t in before))]


def _band_tasks(case, point: float, added: int, tasks, guides, again) -> list[Task]:
    """The band's chains, one per patch and viscosity: after the main points, or, where
    the band starts from the guides, its first pass after theirs and each refined speed
    after the guides' refined points."""
    patches, count = len(case.geometry.patches), case.sweep.count
    if not case.run.patch_band or patches < 2:
        return []
    band = _band_point_cost(case) * point
    pairs = [(v, k) for v in range(len(guides)) for k in range(patches)]
    if not case.band_after_guides(case.macro_shape):
        done = tuple(t.name for t in tasks)
        return [Task(f"band {v} {k}", band * (count + added), done) for v, k in pairs]
    first = [Task(f"band {v} {k}", band * count, tuple(g.name for g in guides))
             for v, k in pairs]
    after = tuple(t.name for t in again + first)
    return first + [Task(f"band {v} {k} {i}", band, after) for v, k in pairs
                    for i in range(added)]


def _micro_tasks(case) -> list[Task]:
    """Per patch pair, its separations in :data:`H0_ROUNDS` rounds, each one task or two
    (its even and odd instants, :func:`~fem_twin.micro.schedule.halves`)."""
    mc = case.micro
    if mc.model == "average-flow":                      # closed forms: no cells to solve
        return []
    h0 = mc.h0_count
    if mc.h0_tol:
        a, k = ADAPTIVE_H0
        h0 = min(h0, a + k / math.sqrt(mc.h0_tol))
    parts, total = halves(mc), max(H0_ROUNDS, int(round(h0)))
    seconds = MICRO_SECONDS * mc.resolution[0] * mc.resolution[1] * mc.steps / parts
    per_round = [(total // H0_ROUNDS + (r < total % H0_ROUNDS)) * parts
                 for r in range(H0_ROUNDS)]
    tasks = []
    for k in range(len(case.geometry.patches)):
        before = ()
        for r in range(H0_ROUNDS):
            new = [Task(f"{MICRO} {k} round {r} h0 {i}", seconds, before)
                   for i in range(per_round[r])]
            tasks += new
            before = tuple(t.name for t in new)
    return tasks


def _point_seconds(case) -> float:
    """A warm Stribeck point on one core [s]: a pin's by its macro grid, a ball's (Newton
    coupling) by its mesh's nodes (a uniform grid's side squared, or the graded mesh's)."""
    if case.tribometer.ball:
        nodes = case.macro.grid ** 2
        if case.macro.mesh == "graded":
            shape = point_contact_mesh(case.macro.grid, EXTENT, (1.0, 1.0)).shape
            nodes = shape[0] * shape[1]
        return BALL_POINT_SECONDS * (nodes / 73 ** 2) ** (BALL_POINT_GROWTH / 2)
    res = case.macro_shape
    return POINT_SECONDS * ((res[0] * res[1]) / 128 ** 2) ** POINT_GROWTH


def _band_point_cost(case) -> float:
    """A band point in main-curve points, by ``[run] band_grid`` and the macro grid
    (``BAND_LEVEL_COST`` for each coarsening beyond the first)."""
    if case.run.band_grid != "coarsest":
        return BAND_POINT_COST[case.run.band_grid]
    return (BAND_POINT_COST["coarse"]
            * BAND_LEVEL_COST ** (case.band_coarsening(case.macro_shape) - 1))


def sweep_cost(request) -> float:
    """A sweep request's relative cost, to schedule the largest first: its speeds times its
    nodes to the power :data:`COST_GROWTH` [-]."""
    return float(request.gap.size) ** COST_GROWTH * request.speeds.size
