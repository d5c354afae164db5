"""Group ``ball-mesh``: the bundled ball's C_f on uniform grids and on graded meshes, against
the 289² grid, with each point's CPU time and the process's peak memory.

    python benchmarks/run.py ball-mesh            # about 40 min on 2 cores (289² points)

The bundled ball (`examples/ball_on_disk.toml`, its run's flow factors, made first into
``benchmarks/results/ball_mesh_run`` when missing) isothermal at 0.066 Pa s, cold points
at the entrainment speeds ``SPEEDS``: ``[macro] grid`` 73, 145, 289 uniform and 145, 289
graded (``[macro] mesh = "graded"``: the grid's pitch over the Hertz zone).  Rows: C_f, its
error against 289² [% C_f,b], the asperity load [N] and the CPU seconds of one point; the
baseline is the 73² point at 0.46 m/s.  The last line: the largest error of each mesh and
its CPU time over 73²'s; checked: graded 145 within 0.5 % C_f,b of 289² at every speed.
"""

from __future__ import annotations

import resource
import time
from dataclasses import replace
from pathlib import Path

from common import Check, run_case

from fem_twin.case.parse import load_case
from fem_twin.io.layout import RunLayout
from fem_twin.macro import solve_point
from fem_twin.stages.requests import sweep_request

DEFAULT = False
ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "examples" / "ball_on_disk.toml"
RUN = ROOT / "benchmarks" / "results" / "ball_mesh_run"
SPEEDS = (3.0, 1.6, 0.46, 0.1, 0.02)
MESHES = ((73, "uniform"), (145, "uniform"), (145, "graded"), (289, "graded"),
          (289, "uniform"))
TOLERANCE = 0.5                       # % C_f,b


def solve(n: int, kind: str, speed: float) -> tuple[float, float, float, int]:
    """``(C_f, asperity load [N], CPU s, nodes)`` of one cold isothermal point."""
    case = load_case(CASE)
    case = replace(case, macro=replace(case.macro, grid=n, mesh=kind))
    request = sweep_request(case, RunLayout(RUN), checkpoint=None)
    start = time.process_time()
    res = solve_point(request.operating_point(speed))
    return (res.friction_coefficient, res.asperity_load, time.process_time() - start,
            res.pressure.size)


def run():
    if not (RUN / "micro" / "flow_factors.npz").is_file():
        run_case(CASE, RUN, ROOT)
    cf_b = load_case(CASE).tribometer.boundary_friction
    points = {(n, kind, u): solve(n, kind, u) for n, kind in MESHES for u in SPEEDS}
    rows, worst, cost = [], {}, {}
    for (n, kind, u), (cf, w_asp, cpu, nodes) in points.items():
        error = 100 * (cf - points[289, "uniform", u][0]) / cf_b
        worst[n, kind] = max(worst.get((n, kind), 0.0), abs(error))
        cost[n, kind] = cost.get((n, kind), 0.0) + cpu
        rows.append((f"{kind} {n}^2 ({nodes} nodes), u_m = {u:g} m/s", cpu,
                     f"C_f {cf:.5f}, error {error:+.2f} % C_f,b, W_asp {w_asp:.3f} N"))
    base = cost[73, "uniform"]
    summary = "; ".join(f"{kind} {n}^2: largest error {worst[n, kind]:.2f} % C_f,b at "
                        f"{cost[n, kind] / base:.1f}x the CPU of 73^2"
                        for n, kind in MESHES if (n, kind) != (289, "uniform"))
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    holds = worst[145, "graded"] <= TOLERANCE
    return (points[73, "uniform", 0.46][2], rows, summary, f"peak memory {peak:.0f} MB",
            Check(holds, f"graded 145^2 within {TOLERANCE} % C_f,b of 289^2 at every speed "
                         f"(largest {worst[145, 'graded']:.2f} %)"))
