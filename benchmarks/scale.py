"""Benchmark group ``scale``: one cold and one warm macro point from 128^2 up (issue 28 item 3).

Sample pin 1 on disk 1 prepared at n^2 (``common.macro_gap``) with the macro groups' flow
factors (sample patch 1 at 64^2, 30 h0 x 8 steps), 150 N, 0.066 Pa s: a cold point at
0.03 m/s (mixed lubrication, the coarse-to-fine start included) and a warm one at
0.025 m/s from it, both as a sweep solves them (:func:`fem_twin.macro.nested.solve_nested`:
the point on every coarsening first).  Each grid runs in a process of its own, so its peak
memory (maximum resident set) is its own.  ``FEM_TWIN_SCALE_MAX`` (default 1024) is the
largest grid: 2048 takes about 3 min for its cold point and 7.4 GiB on two threads
(docs/performance.md, "Large macro grids").
A lone point has the machine to itself, so each grid's process gets as many PARDISO threads
as the machine has cores (``FEM_TWIN_THREADS``, if set, wins; PARDISO uses them only on
matrices of ``fem_twin.numerics.linalg.THREADED_UNKNOWNS`` or more).
Baseline: the cold point at 128^2.  The growth exponent is ``log(t_n / t_(n/2)) / log 4``,
in the number of nodes N.  Checked: issue 28's bars, the cold point's growth at most N^1.1
from 256^2 up and, when 2048^2 runs, its cold point under 3 min and 8 GiB.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

DEFAULT = False
COLD, WARM = 0.03, 0.025          # [m/s]
#: issue 28's bars: the cold point's growth in N from 256^2 up, and at 2048^2 [s], [GiB]
GROWTH, SECONDS_2048, GIB_2048 = 1.1, 180.0, 8.0
#: the environment before this process loads MKL, which sets its threading layer there
#: (``fem_twin.numerics.linalg``): a child given more threads must choose its own layer, not
#: inherit this process's sequential one
_ENVIRONMENT = dict(os.environ)


def run():
    from common import Check, macro_factors
    top = int(os.environ.get("FEM_TWIN_SCALE_MAX", "1024"))
    sizes = [n for n in (128, 256, 512, 1024, 2048) if n <= top]
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "factors.npz")
        macro_factors().save(path)
        env = {**_ENVIRONMENT,
               "FEM_TWIN_THREADS": os.environ.get("FEM_TWIN_THREADS", str(os.cpu_count() or 1))}
        runs = [json.loads(subprocess.run(
            [sys.executable, __file__, str(n), path], check=True, capture_output=True,
            text=True, env=env).stdout.splitlines()[-1]) for n in sizes]
    base, rows = runs[0]["cold"], []
    for i, r in enumerate(runs):
        growth = ("" if i == 0 else ", growth N^%.2f cold, N^%.2f warm" % tuple(
            np.log(r[k] / runs[i - 1][k]) / np.log(4) for k in ("cold", "warm")))
        rows.append((f"cold point {r['n']}^2, {COLD} m/s", r["cold"],
                     f"{r['cold_iterations']} it, C_f {r['cf']:.5f}, peak memory "
                     f"{r['rss_gib']:.2f} GiB, {env['FEM_TWIN_THREADS']} threads (MKL layer "
                     f"{r['layer']}){growth}"))
        rows.append((f"warm point {r['n']}^2, {WARM} m/s", r["warm"],
                     f"{r['warm_iterations']} it"))
    growth = [np.log(r["cold"] / p["cold"]) / np.log(4) for p, r in zip(runs, runs[1:])
              if r["n"] > 256]
    text = (f"the cold point's growth from 256^2 to {sizes[-1]}^2 at most N^{GROWTH:g} "
            f"(N^{max(growth, default=0.0):.2f})")
    holds = max(growth, default=0.0) <= GROWTH
    if sizes[-1] == 2048:
        last = runs[-1]
        holds = holds and last["cold"] < SECONDS_2048 and last["rss_gib"] < GIB_2048
        text += (f", the cold 2048^2 point under {SECONDS_2048:.0f} s and {GIB_2048:g} GiB "
                 f"({last['cold']:.0f} s, {last['rss_gib']:.2f} GiB)")
    return base, rows, Check(holds, text)


def _point(n: int, factors: str) -> dict:
    """One grid's cold and warm points (in a process of its own)."""
    from common import macro_gap

    from fem_twin.macro import Lubricant
    from fem_twin.macro.nested import solve_nested
    from fem_twin.macro.point import OperatingPoint
    from fem_twin.micro import FlowFactors
    ff = FlowFactors.load(factors)
    gap, spacing, face = macro_gap(n)
    common = dict(load=150.0, face=face, lubricant=Lubricant(0.066))
    t0 = time.perf_counter()
    cold = solve_nested(OperatingPoint(gap, spacing, ff, speed=COLD, **common))
    t1 = time.perf_counter()
    warm = solve_nested(OperatingPoint(gap, spacing, ff, speed=WARM, **common), cold)
    t2 = time.perf_counter()
    return {"n": n, "cold": t1 - t0, "warm": t2 - t1, "cf": cold[0].friction_coefficient,
            "cold_iterations": cold[0].iterations, "warm_iterations": warm[0].iterations,
            "rss_gib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2 ** 20,
            "layer": os.environ.get("MKL_THREADING_LAYER", "no MKL")}


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    print(json.dumps(_point(int(sys.argv[1]), sys.argv[2])))
