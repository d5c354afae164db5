"""How fast this machine runs fem_twin now, against the machine and hour the run-time
estimates were measured on (:func:`fem_twin.runtime.cost.estimated_seconds`).

Costs measured on one machine say little about another (a laptop, SuperLU instead of
PARDISO), and a shared machine runs the same work up to about 2x slower from one hour to
the next.  The two stages' kernels need not move together (a processor's single-precision
factorisations, a missing MKL), so before a run :func:`slowdown` times a miniature of each:
of the micro stage (a 64^2 roughness patch pair, two separations, four instants: periodic
contact and the three cell problems) and of a Stribeck point (a cold mixed point of a
crowned 64^2 pin: the Reynolds Newton steps, the FFT half-space and the coupling), both
with the sparse backend and the heap the run's workers will use, and divides each by its
time at the calibration.  Each miniature runs in as many processes at once as the run has
local workers (at most one a core), so a load on another core slows the probes as it will
slow the workers.  It sees the machine for about two seconds, so the estimate carries the
scatter of the machine's speed within a minute (``python benchmarks/run.py estimates``).
"""

from __future__ import annotations

import multiprocessing
import os
import time
from dataclasses import dataclass
from queue import Empty

import numpy as np

from .. import tables as T
from ..errors import InputError, SolverError
from ..macro import Lubricant, MacroSettings, solve_mixed
from ..macro.reference.point_contact import PointContact
from ..micro import FlowFactors, homogenise
from ..numerics.linalg import default_backend
from ..numerics.threads import one_thread, quiet_worker, worker_heap, workers_ignore_ctrl_c
from ..topography.synthetic import self_affine

#: the miniatures' times on the calibration machine, the hour the estimate's costs were
#: measured (best of five, PARDISO) [s]: the cells' was timed then; the macro point's is
#: the cells' times their ratio on that machine, timed back to back (``python
#: benchmarks/run.py estimates`` checks the estimate against the run)
REFERENCE_SECONDS = {"micro": 0.18, "macro": 0.84, "ball": 0.88}
#: the run's cells over the cells' miniature with SuperLU, against the same with PARDISO:
#: the miniature (64^2, 4 steps, no error estimate) reads SuperLU's share of a run's cells
#: (128^2, the coarsened cells) short.  Measured 1.46, 1.46 and 1.47 on the bundled pin,
#: ball and paper cases (``benchmarks/run.py estimates``, its tasks over its probes, with
#: and without ``FEM_TWIN_SPARSE=superlu``); the cells' slowdown takes it with SuperLU
SUPERLU_CELLS = 1.45
#: timed repeats of each miniature (the best counts: the machine's speed, not a hiccup)
REPEATS = {"micro": 5, "macro": 3, "ball": 3}
#: how long a probe process may take to report [s]
PROBE_TIMEOUT = 120.0
#: the slowdown is kept within these bounds (a probe sees about a second and can misjudge;
#: an estimate off by more than 4x says more about the machine than about the case)
BOUNDS = (0.25, 4.0)


@dataclass(frozen=True)
class Slowdown:
    """This machine's time over the calibration machine's for the cells (``micro``) and
    for the macro points (``macro``) [-]."""

    micro: float
    macro: float

    def __str__(self) -> str:
        if f"{self.micro:.2g}" == f"{self.macro:.2g}":
            return f"{self.micro:.2g}x"
        return f"{self.micro:.2g}x for the cells and {self.macro:.2g}x for the macro points"


@one_thread
def probe_seconds(kind: str = "micro", repeats: int | None = None) -> float:
    """The best of ``repeats`` timings of the ``kind`` miniature (``"micro"``, ``"macro"``
    or ``"ball"``; one thread, as the workers; ``repeats`` None: :data:`REPEATS`) [s]."""
    if not isinstance(kind, str) or kind not in REPEATS:
        raise InputError(f"probe_seconds: kind is one of {sorted(REPEATS)}, got {kind!r}")
    if repeats is not None and (isinstance(repeats, bool) or not isinstance(
            repeats, (int, np.integer)) or repeats < 1):
        raise InputError(f"probe_seconds: repeats is a whole number >= 1, got {repeats!r}")
    return min(_timings(kind, REPEATS[kind] if repeats is None else repeats))


def _timings(kind: str, repeats: int, before=None) -> list[float]:
    """The times [s] of ``repeats`` runs of the ``kind`` miniature, each after ``before()``
    if given (built once, untimed), on the workers' heap (:func:`worker_heap`: with glibc's
    default one, grid-sized temporaries are fresh pages each time, and the pin's point ran
    1.2x slower than in a worker)."""
    worker_heap()
    work, times = _MINIATURES[kind](), []
    for _ in range(repeats):
        if before is not None:
            before()
        t = time.perf_counter()
        work()
        times.append(time.perf_counter() - t)
    return times


def _cells():
    rng = np.random.default_rng(0)
    pin, disk = (self_affine((64, 64), 1e-6, 0.8, 0.3e-6, rng=rng) for _ in range(2))
    h0 = np.array([0.2e-6, 0.5e-6])
    return lambda: homogenise(pin, disk, h0, steps=4, error_estimate=False)


def _ball_point():
    """The bundled ball's kind of point, smaller: a 3/4 inch steel ball under 20 N on a
    37^2 grid over the Hertz zone, u_m 0.5 m/s at SRR 2, the Newton coupling, asperities
    ``1e10 exp(-h0 / 40 nm)`` Pa (29 % of the load on them, 25 Newton iterations)."""
    contact = PointContact(9.525e-3, 20.0, T.E_REDUCED, 0.066, T.ROELANDS_ALPHA, 0.5)
    gap, spacing, _, _ = contact.grid(37)
    settings = MacroSettings(coupling="newton", cavitation_pressure=T.AMBIENT_PRESSURE)
    factors = _asperities()
    return lambda: solve_mixed(gap, spacing, factors, load=20.0, speed=1.0,
                               entrainment=0.5, lubricant=Lubricant(0.066), settings=settings)


def _asperities() -> FlowFactors:
    """Smooth flow factors with the contact pressure ``1e10 exp(-h0 / 40 nm)`` [Pa]."""
    h0 = np.geomspace(1e-8, 3e-6, 200)
    k = h0.size
    return FlowFactors(h0=h0, h_m=h0.copy(), p_con=1e10 * np.exp(-h0 / 40e-9),
                       A=np.tile(np.eye(2), (k, 1, 1)), b=np.tile([1.0, 0.0], (k, 1)),
                       C=np.tile(np.eye(2), (k, 1, 1)), d=np.zeros((k, 2)),
                       friction_factor=np.ones(k),
                       pressure_friction=np.tile([1.0, 0.0], (k, 1)),
                       contact_fraction=np.zeros(k))


def _macro_point():
    """A crowned 7 mm face (2 um at its rim) on a 64^2 grid over the paper's 8 mm pin, the
    holder 1 mm below, the paper's 150 N at 0.02 m/s, asperities ``1e10 exp(-h0 / 40 nm)``
    Pa: mixed lubrication (42 % of the load on the asperities, 75 coupling iterations)."""
    n, size, rim = 64, T.PIN_DIAMETER, 3.5e-3
    x = (np.arange(n) - (n - 1) / 2) * size / (n - 1)
    r2 = x[None, :] ** 2 + x[:, None] ** 2
    face = r2 <= rim ** 2
    gap = np.where(face, 2e-6 * r2 / rim ** 2, -T.HOLDER_HEIGHT)
    spacing, factors = (size / (n - 1),) * 2, _asperities()
    return lambda: solve_mixed(gap, spacing, factors, load=T.LOAD, speed=0.02,
                               lubricant=Lubricant(0.066), face=face)


#: each kind of probe's miniature: a function that builds it and returns its timed work
_MINIATURES = {"micro": _cells, "macro": _macro_point, "ball": _ball_point}


def probe_together(kind: str, processes: int) -> float:
    """:func:`probe_seconds` of ``kind`` in ``processes`` processes at once, each repeat
    started together (a barrier), as the run's workers will share the machine: a load on
    another core then slows the probes as it slows the run [s] (the mean over processes
    of their repeats' median; one process: :func:`probe_seconds` itself)."""
    if not isinstance(kind, str) or kind not in REPEATS:
        raise InputError(f"probe_together: kind is one of {sorted(REPEATS)}, got {kind!r}")
    if (isinstance(processes, bool) or not isinstance(processes, (int, np.integer))
            or processes < 1):
        raise InputError(f"probe_together: processes is a whole number >= 1, got "
                         f"{processes!r}")
    if processes == 1:
        return probe_seconds(kind)
    ctx = multiprocessing.get_context()
    barrier, queue = ctx.Barrier(processes), ctx.Queue()
    jobs = [ctx.Process(target=_probe_in_step, args=(kind, barrier, queue), daemon=True)
            for _ in range(processes)]
    with workers_ignore_ctrl_c():                 # Ctrl-C reaches the run alone
        for job in jobs:
            job.start()
    try:
        times = [queue.get(timeout=PROBE_TIMEOUT) for _ in jobs]
    except Empty:
        raise SolverError(f"the {kind} probe's {processes} processes did not report within "
                          f"{PROBE_TIMEOUT:.0f} s") from None
    finally:
        for job in jobs:
            job.join(timeout=1.0)
            if job.is_alive():
                job.terminate()
    return float(np.mean(times))


@one_thread
def _probe_in_step(kind, barrier, queue):
    """One process of :func:`probe_together`: the median of its repeats, each after the
    barrier (the best would pick the repeat the scheduler left alone; NaN if its work
    failed, so that the others are not left waiting)."""
    quiet_worker()
    try:
        times = _timings(kind, REPEATS[kind], lambda: barrier.wait(timeout=PROBE_TIMEOUT))
    except Exception:
        barrier.abort()
        times = [np.nan]
    queue.put(float(np.median(times)))


def _forced(text: str) -> float:
    """The slowdown ``FEM_TWIN_SLOWDOWN`` sets: a finite number within :data:`BOUNDS`."""
    try:
        value = float(text)
    except ValueError:
        value = np.nan
    if not BOUNDS[0] <= value <= BOUNDS[1]:
        raise InputError(f"FEM_TWIN_SLOWDOWN = {text!r}: this machine's time over the "
                         f"calibration machine's, a number from {BOUNDS[0]:g} to "
                         f"{BOUNDS[1]:g} (2 is twice as slow)")
    return value


def slowdown(ball: bool = False, workers: int = 1) -> Slowdown:
    """This machine's time for the same work over the calibration machine's, now (about 2
    s to measure), each kernel's within :data:`BOUNDS`: the cells' (with SuperLU times
    :data:`SUPERLU_CELLS`), and a pin's macro point
    or (``ball``) a ball's, each timed in ``workers`` processes at once (at most one a
    core; :func:`probe_together`); ``FEM_TWIN_SLOWDOWN`` (a number) sets both without
    measuring."""
    if not isinstance(ball, bool) or isinstance(workers, bool) or not isinstance(
            workers, (int, np.integer)) or workers < 1:
        raise InputError(f"slowdown: ball is True or False and workers a whole number >= 1, "
                         f"got ball={ball!r}, workers={workers!r}")
    forced = os.environ.get("FEM_TWIN_SLOWDOWN")
    if forced:
        return Slowdown(*(2 * [_forced(forced)]))
    processes = max(1, min(workers, os.cpu_count() or 1))
    seconds = {kind: probe_together(kind, processes)
               for kind in ("micro", "ball" if ball else "macro")}
    if not all(np.isfinite(list(seconds.values()))):
        raise SolverError(f"a speed probe failed in one of its {processes} processes")
    if default_backend() == "superlu":
        seconds["micro"] *= SUPERLU_CELLS
    return Slowdown(*(float(np.clip(t / REFERENCE_SECONDS[kind], *BOUNDS))
                      for kind, t in seconds.items()))
