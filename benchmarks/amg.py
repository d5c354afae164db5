"""Benchmark group ``amg``: one Newton step of the p-theta switch, direct against algebraic
multigrid, from 256^2 up (issue 73 item 3).

The step is the first one of the finest level of ``scale``'s cold point (sample pin 1 on
disk 1 at n^2, 150 N, 0.066 Pa s, 0.03 m/s: mixed lubrication with a cavity), captured
from the solver itself.  Each solver runs in a process of its own (its peak memory is its
own, the matrix included): PARDISO as the solver runs it (single-precision factors in the
grid's nested-dissection order, refined to ``STEP_RTOL``; analysis included), SuperLU in
the same order (the fallback without MKL), and pyamg's classical (Ruge-Stuben) AMG as the
preconditioner of restarted GMRES to the same tolerance (smoothed aggregation and AIR
took 5-30x longer on the 1024^2 step, or did not converge).  ``FEM_TWIN_AMG_MAX``
(default 1024) is the largest grid.  Baseline: PARDISO at 256^2.  Checked: a direct solver
faster than AMG on the largest grid (why the twin solves directly, docs/performance.md).
"""

from __future__ import annotations

import json
import os
import pickle
import resource
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

DEFAULT = False
SOLVERS = ("pardiso", "superlu", "amg")


def run():
    from common import Check
    top = int(os.environ.get("FEM_TWIN_AMG_MAX", "1024"))
    sizes = [n for n in (256, 512, 1024, 2048) if n <= top]
    rows, base, last = [], None, {}
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            path = os.path.join(tmp, f"step_{n}.pkl")
            _child("capture", n, path)
            for solver in SOLVERS:
                r = _child(solver, n, path)
                last[solver] = r["seconds"]
                base = base or r["seconds"]
                its = f", {r['iterations']} GMRES it" if "iterations" in r else ""
                rows.append((f"Newton step {n}^2, {solver}", r["seconds"],
                             f"{r['unknowns']} unknowns, residual {r['residual']:.1e}{its}, "
                             f"peak memory {r['rss_gib']:.2f} GiB"))
    direct = min(last["pardiso"], last["superlu"])
    return base, rows, Check(direct < last["amg"], f"at {sizes[-1]}^2 a direct solver "
                                                   f"({direct:.2f} s) faster than AMG "
                                                   f"({last['amg']:.2f} s)")


def _child(what, n, path) -> dict:
    out = subprocess.run([sys.executable, __file__, what, str(n), path], check=True,
                         capture_output=True, text=True).stdout.splitlines()
    return json.loads(out[-1]) if out else {}


def _capture(n: int, path: str) -> dict:
    """Solve ``scale``'s cold point until the finest level's first Newton step; keep it."""
    from common import macro_factors, macro_gap

    import fem_twin.macro.film.switch as switch
    from fem_twin.macro import Lubricant, OperatingPoint
    from fem_twin.macro.nested import solve_nested
    real = switch.newton_solver

    class Captured(Exception):
        pass

    def spy(shape, dirichlet, interior, K, B):
        if shape is None or shape[0] < n:
            return real(shape, dirichlet, interior, K, B)

        def step(pos, dtheta, rhs):
            with open(path, "wb") as f:
                pickle.dump(dict(K=K.tocsr(), B=B.tocsr(), dirichlet=dirichlet, shape=shape,
                                 interior=interior, pos=pos, dtheta=dtheta, rhs=rhs), f)
            raise Captured
        step.release = lambda: None
        return step
    switch.newton_solver = spy
    gap, spacing, face = macro_gap(n)
    try:
        solve_nested(OperatingPoint(gap, spacing, macro_factors(), speed=0.03, load=150.0,
                                    face=face, lubricant=Lubricant(0.066)))
    except Captured:
        return {}
    raise RuntimeError(f"no Newton step captured at {n}^2")


def _solve(solver: str, path: str) -> dict:
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    with open(path, "rb") as f:
        d = pickle.load(f)
    K, B, interior = d["K"], d["B"], d["interior"]
    pos, dtheta, rhs = d["pos"], d["dtheta"], d["rhs"]
    full = np.zeros((2, K.shape[0]))
    full[0, interior], full[1, interior] = pos, dtheta
    J = (K @ sp.diags(full[0]) + B @ sp.diags(full[1])).tocsr()[interior][:, interior].tocsr()
    out = {}
    t0 = time.perf_counter()
    if solver == "pardiso":
        from fem_twin.macro.film.stencil_solver import newton_solver
        step = newton_solver(d["shape"], d["dirichlet"], interior, K, B)
        x = step(pos, dtheta, rhs)
    elif solver == "superlu":
        from fem_twin.macro.film.switch import _interior_order
        order = _interior_order(d["shape"], d["dirichlet"], interior)
        lu = spla.splu(J[order][:, order].tocsc(), permc_spec="NATURAL",
                       diag_pivot_thresh=0.1, options={"SymmetricMode": True})
        x = np.empty_like(rhs)
        x[order] = lu.solve(rhs[order])
    else:
        import pyamg

        from fem_twin.macro.film.stencil_solver import STEP_RTOL
        ml = pyamg.ruge_stuben_solver(J, max_coarse=500)
        its = []
        x, _ = spla.gmres(J, rhs, M=ml.aspreconditioner(), rtol=STEP_RTOL, restart=60,
                          maxiter=20, callback=its.append, callback_type="pr_norm")
        out["iterations"] = len(its)
    seconds = time.perf_counter() - t0
    return {**out, "seconds": seconds, "unknowns": int(interior.size),
            "residual": float(np.linalg.norm(J @ x - rhs) / np.linalg.norm(rhs)),
            "rss_gib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2 ** 20}


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    what, size, file = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    print(json.dumps(_capture(size, file) if what == "capture" else _solve(what, file)))
