"""Group ``stribeck``: the bundled case end to end (``fem-twin run``, a fresh output
folder), and one paper-grade Stribeck curve: 25 speeds 2 -> 0.01 m/s at 256^2 with the flow
factors given (sample patch 1 at 64^2, 30 h0 x 8 steps).  Baseline: the first (cold) point
of that curve.  Checked: the goal, the curve in under 600 s."""

from __future__ import annotations

import os
import sys
import time

import numpy as np
from common import Check, macro_factors, macro_gap

DEFAULT = True
HERE = os.path.dirname(os.path.abspath(__file__))
#: the goal for the paper-grade curve [s]
GOAL = 600.0


def run():
    import json
    import subprocess
    import tempfile

    from fem_twin.macro import Lubricant, solve_mixed
    from fem_twin.stribeck import SweepRequest, stribeck_sweep

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        case = os.path.join(HERE, "..", "examples", "pin_on_disk.toml")
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "fem_twin.cli", "run", case, "-o", tmp,
                        "--no-progress"], check=True, capture_output=True)
        wall = time.perf_counter() - t0
        sec = json.loads(open(os.path.join(tmp, "summary.json")).read())["seconds"]
    ff = macro_factors()
    gap, spacing, face = macro_gap(256)
    t0 = time.perf_counter()
    solve_mixed(gap, spacing, ff, load=150.0, speed=2.0, face=face,
                lubricant=Lubricant(0.066))
    base = time.perf_counter() - t0
    rows.append(("baseline: cold 256^2 point at 2 m/s", base, ""))
    rows.append(("bundled case, fem-twin run (2 viscosities)", wall,
                 ", ".join(f"{k} {v:.0f} s" for k, v in sec.items())))
    t0 = time.perf_counter()
    curve = stribeck_sweep(SweepRequest(gap, spacing, ff, np.geomspace(2.0, 0.01, 25), load=150.0,
                           lubricant=Lubricant(0.066), face=face))
    t = time.perf_counter() - t0
    rows.append(("paper-grade curve: 25 speeds at 256^2", t,
                 f"{int(curve.iterations.sum())} iterations, "
                 f"C_f {curve.friction_coefficient[0]:.4f}"
                 f" -> {curve.friction_coefficient[-1]:.4f}; goal 600 s"))
    return base, rows, Check(t < GOAL, f"the paper-grade curve of 25 speeds at 256^2 in "
                                       f"{t:.0f} s, under {GOAL:.0f} s")
