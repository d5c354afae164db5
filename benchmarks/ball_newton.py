"""Group ``ball-newton``: the Newton coupling's dense elastic block against its threshold,
on the bundled ball's cold isothermal points (0.066 Pa s, the ``ball-mesh`` speeds).

    python benchmarks/run.py ball-newton      # about 5 min on 2 cores

``jacobian.DENSE_THRESHOLD`` decides which nodes of the loaded zone get the dense elastic
block of the preconditioner, whose LU costs the cube of their count.  Rows: each threshold
in ``THRESHOLDS`` on the uniform 73² grid and on the mesh graded over 145², the CPU
seconds of the five points and C_f's largest change against the default threshold
[% C_f,b].  Baseline: the 73² points at the default threshold.  Checked:
the converged C_f does not depend on the threshold (1e-3 % C_f,b, the coupling's
tolerance), and the default is within 10 % of the fastest threshold on the graded mesh.
"""

from __future__ import annotations

import time

from ball_mesh import CASE, RUN, SPEEDS, solve
from common import Check, run_case

from fem_twin.case.parse import load_case
from fem_twin.macro.coupling import jacobian

DEFAULT = False
THRESHOLDS = (0.02, 0.2, 1.0, 3.0)
MESHES = ((73, "uniform"), (145, "graded"))
SAME = 1e-3                          # % C_f,b


def _points(n: int, kind: str, threshold: float):
    """``(CPU s, C_f per speed)`` of the cold points under ``threshold``."""
    default, jacobian.DENSE_THRESHOLD = jacobian.DENSE_THRESHOLD, threshold
    try:
        start = time.process_time()
        cf = [solve(n, kind, u)[0] for u in SPEEDS]
        return time.process_time() - start, cf
    finally:
        jacobian.DENSE_THRESHOLD = default


def run():
    if not (RUN / "micro" / "flow_factors.npz").is_file():
        run_case(CASE, RUN, RUN.parents[1])
    cf_b = load_case(CASE).tribometer.boundary_friction
    default = jacobian.DENSE_THRESHOLD
    measured = {(n, kind, t): _points(n, kind, t) for n, kind in MESHES
                for t in sorted({*THRESHOLDS, default})}
    rows, worst = [], 0.0
    for (n, kind, t), (cpu, cf) in measured.items():
        change = max(abs(a - b) for a, b in zip(cf, measured[n, kind, default][1]))
        worst = max(worst, 100 * change / cf_b)
        rows.append((f"{kind} {n}^2, threshold {t:g}{' (default)' * (t == default)}", cpu,
                     f"C_f change {100 * change / cf_b:.1e} % C_f,b"))
    graded = {t: cpu for (n, kind, t), (cpu, _) in measured.items() if kind == "graded"}
    fastest = min(graded, key=graded.get)
    holds = worst <= SAME and graded[default] <= 1.1 * graded[fastest]
    return (measured[73, "uniform", default][0], rows,
            Check(holds, f"C_f within {SAME:g} % C_f,b of the default's at every threshold "
                         f"(largest {worst:.1e}); the default {default:g} within 10 % of the "
                         f"fastest on the graded mesh ({fastest:g}: "
                         f"{graded[default] / graded[fastest]:.2f}x)"))
