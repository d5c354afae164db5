"""The ``ab`` group: the example cases end to end on this checkout and on a base commit.

``FEM_TWIN_AB_BASE`` (default ``14b8abf``, the commit issue 73 measures against) is checked
out in a temporary git worktree; each case of ``FEM_TWIN_AB_CASES`` (default
``pin_on_disk,paper``; ``ball_on_disk`` too) runs as a fresh ``fem-twin run`` of the base,
then of this checkout, back to back, each in its own process.  Printed per run: the wall
time, and from its task graph (``summary.json``) the CPU time of its tasks and the critical
path; for this checkout, the CPU ratio to the base and the largest change of C_f between the
two curves in % C_f,b beside the larger of their error estimates.  The baseline is the
first case's run on the base.  Checked: no case's C_f changed by more than the larger of
the two curves' error estimates.
"""

from __future__ import annotations

import os
import subprocess
import tempfile
from pathlib import Path

import numpy as np
from common import Check, run_case

from fem_twin.case import load_case
from fem_twin.stribeck.curve import read_stribeck_csv

DEFAULT = False
ROOT = Path(__file__).resolve().parents[1]


def _run(tree: Path, case: str, out: Path) -> tuple[float, dict]:
    """Wall time [s] and summary of ``fem-twin run examples/CASE.toml`` in ``tree``."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    return run_case(tree / "examples" / f"{case}.toml", out, tree, env)[:2]


def _change(base: Path, new: Path, boundary_friction: float) -> tuple[str, bool]:
    """The largest |C_f change| between two runs' curves and their largest estimate, and
    whether the change is within the estimate."""
    change, estimate = 0.0, 0.0
    for a, b in zip(read_stribeck_csv(base / "stribeck.csv"),
                    read_stribeck_csv(new / "stribeck.csv")):
        change = max(change, float(np.max(np.abs(b.friction_coefficient
                                                 - a.friction_coefficient))))
        estimate = max(estimate, float(np.max(a.friction_error)),
                       float(np.max(b.friction_error)))
    return (f"C_f changed by at most {change / boundary_friction:.3%} C_f,b "
            f"(estimates at most {estimate / boundary_friction:.3%})"), change <= estimate


def run():
    """Rows: per case, its run on the base commit and on this checkout."""
    base_rev = os.environ.get("FEM_TWIN_AB_BASE", "14b8abf")
    cases = os.environ.get("FEM_TWIN_AB_CASES", "pin_on_disk,paper").split(",")
    rows, first, outside = [], None, []
    with tempfile.TemporaryDirectory() as tmp:
        tree = Path(tmp) / "base"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree),
                        base_rev], check=True, capture_output=True)
        try:
            for case in cases:
                cb = load_case(ROOT / "examples" / f"{case}.toml").tribometer.boundary_friction
                outs = {v: Path(tmp) / f"{case}_{v}" for v in ("base", "new")}
                wall_b, sum_b = _run(tree, case, outs["base"])
                wall_n, sum_n = _run(ROOT, case, outs["new"])
                first = first or wall_b
                graph_b, graph_n = sum_b["task_graph"], sum_n["task_graph"]
                change, within = _change(outs["base"], outs["new"], cb)
                outside += [] if within else [case]
                rows.append((f"{case} at {base_rev}", wall_b,
                             f"{graph_b['cpu_s']:.1f} CPU s, critical path "
                             f"{graph_b['critical_path_s']:.1f} s"))
                rows.append((f"{case} now", wall_n,
                             f"{graph_n['cpu_s']:.1f} CPU s "
                             f"({graph_n['cpu_s'] / graph_b['cpu_s']:.2f}x), critical path "
                             f"{graph_n['critical_path_s']:.1f} s; " + change))
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                            str(tree)], capture_output=True)
    return first, rows, Check(not outside, f"C_f of {', '.join(cases)} changed within the "
                                           f"error estimates since {base_rev}"
                                           + (f" (not {', '.join(outside)})" if outside else ""))
