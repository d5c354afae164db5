"""How fast this machine runs fem_twin now, against the machine and hour the run-time
estimates were measured on (:func:`fem_twin.runtime.cost.estimated_seconds`).

Costs measured on one machine say little about another (a laptop, SuperLU instead of
PARDISO), and a shared machine runs the same work up to about 2x slower from one hour to
the next.  Before a run, :func:`slowdown` times a miniature of the micro stage (a 64^2
roughness patch pair, two separations, four instants: periodic contact and the three cell
problems, with the sparse backend the run will use) and divides by its time at the
calibration.  It sees the machine for about a second, so the estimate carries the scatter
of the machine's speed within a minute (benchmarks/README.md, "speed").
"""

from __future__ import annotations

import os
import time

import numpy as np

from ..errors import InputError
from ..micro import homogenise
from ..numerics.threads import one_thread
from ..topography.synthetic import self_affine

#: the miniature's time on the calibration machine, the hour the estimate's costs were
#: measured (best of five, PARDISO) [s]
REFERENCE_SECONDS = 0.18
#: timed repeats of the miniature (the best counts: the machine's speed, not a hiccup)
REPEATS = 5
#: the slowdown is kept within these bounds (a probe sees about a second and can misjudge;
#: an estimate off by more than 4x says more about the machine than about the case)
BOUNDS = (0.25, 4.0)


@one_thread
def probe_seconds(repeats: int = REPEATS) -> float:
    """The best of ``repeats`` timings of the miniature (one thread, as the workers) [s]."""
    rng = np.random.default_rng(0)
    pin, disk = (self_affine((64, 64), 1e-6, 0.8, 0.3e-6, rng=rng) for _ in range(2))
    h0 = np.array([0.2e-6, 0.5e-6])
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        homogenise(pin, disk, h0, steps=4, error_estimate=False)
        best = min(best, time.perf_counter() - t)
    return best


def slowdown() -> float:
    """This machine's time for the same work over the calibration machine's, now (about 1
    s to measure), within :data:`BOUNDS`; ``FEM_TWIN_SLOWDOWN`` (a number) sets it without
    measuring."""
    forced = os.environ.get("FEM_TWIN_SLOWDOWN")
    if forced:
        try:
            return float(np.clip(float(forced), *BOUNDS))
        except ValueError:
            raise InputError(f"FEM_TWIN_SLOWDOWN must be a number (this machine's time over "
                             f"the calibration machine's), got {forced!r}") from None
    return float(np.clip(probe_seconds() / REFERENCE_SECONDS, *BOUNDS))
