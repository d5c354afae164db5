"""Group ``micro``: the cell problems at 256^2 (sample patch 3) against a full scikit-fem
assembly (the baseline): re-assembly from element tensors, one cell step by FE and FVM on
SuperLU and PARDISO (when MKL is there), pyamg's AMG-preconditioned CG against the direct
solution, a cold periodic contact, and the patch pair over 10 of the 100 h0 candidates
(every 10th, serially, for the paper's implicit Euler and the exact time derivative), whose
time x 10 / 2 estimates the 100 h0 on 2 processes (the goal: 300 s).  Checked: PARDISO's
cell step at least 2x faster than SuperLU's, FE and FVM (docs/performance.md: about 3x;
skipped without MKL).  The whole pair on 2 processes is the group ``micro-full``."""

from __future__ import annotations

import time

import numpy as np
from common import Check, best_of, sample_patch_pair

DEFAULT = True
#: PARDISO's cell step against SuperLU's: at least this much faster
GAIN = 2.0


def run(full=False):
    """``full``: the whole patch pair, 100 h0 x 32 steps on 2 processes (about 15 min here);
    otherwise 10 of the 100 h0 values (every 10th) serially, whose time x 10 / 2 estimates it.
    """
    from fem_twin.contact import solve
    from fem_twin.contact.levelling import TABLE4
    from fem_twin.fvm import CellSolverFV
    from fem_twin.micro import DEFAULT_H0, CellSolver, homogenise
    from fem_twin.micro.cell import flow_form

    pin, disk = sample_patch_pair()
    shape = disk.heights - pin.heights
    gap = solve(shape, pin.spacing, TABLE4["e_reduced"], separation=0.2e-6,
                hardness=TABLE4["hardness"], periodic=True).gap
    cs = CellSolver(pin.shape, pin.spacing)
    a_q = cs.at_quadrature(gap) ** 3
    P = cs.grid.periodic_map
    base, _ = best_of(lambda: P.T @ flow_form.assemble(cs.basis, a=a_q) @ P)
    rows = [("baseline: skfem assemble + P^T K P, 256^2", base, "")]
    t, _ = best_of(lambda: cs.operator(a_q), 5)
    rows.append(("re-assembly from element tensors", t, ""))
    from fem_twin.numerics.linalg import _mkl_rt, default_backend
    backends = ["superlu"] + (["pardiso"] if _mkl_rt() is not None else [])
    step = {}
    for name, make in (("FE", CellSolver), ("FVM", CellSolverFV)):
        for backend in backends:
            solver = make(pin.shape, pin.spacing, backend=backend)
            t, _ = best_of(lambda: solver.solve(gap))
            step[name, backend] = t
            rows.append((f"{name} cell step, {backend}", t,
                         "assemble + factor + 3 solves + means, h0 = 0.2 um"))
    rows += _amg_rows(cs, gap)
    t, r = best_of(lambda: solve(shape, pin.spacing, TABLE4["e_reduced"], separation=0.2e-6,
                                 hardness=TABLE4["hardness"], periodic=True))
    rows.append(("periodic contact, cold", t, f"{r.iterations} it"))
    h0 = DEFAULT_H0 if full else DEFAULT_H0[::10]
    workers = 2 if full else 1
    for scheme in ("backward", "exact"):
        t0 = time.perf_counter()
        frame = dict(moving="upper") if scheme == "backward" else {}   # the paper's frame
        ff = homogenise(pin, disk, h0, workers=workers, time_derivative=scheme,
                        error_estimate=False, **frame)
        wall = time.perf_counter() - t0
        sec = ff.meta["seconds"]
        note = (f"contact{' + rate' if scheme == 'exact' else ''} {sec['contact']:.0f} s + "
                f"cells {sec['cell']:.0f} s (CPU, summed)")
        rows.append((f"patch pair {len(h0)} h0 x 32 steps, {scheme}, {workers} process(es)",
                     wall, note + f", {default_backend()}"))
        if not full:
            rows.append(("  estimate 100 h0 on 2 processes", wall * 10 / 2, "goal: 300 s"))
    if "pardiso" not in backends:
        return base, rows, Check(None, "PARDISO against SuperLU: MKL absent")
    gain = {name: step[name, "superlu"] / step[name, "pardiso"] for name in ("FE", "FVM")}
    return base, rows, Check(min(gain.values()) >= GAIN, "PARDISO's cell step " + " and ".join(
        f"{g:.1f}x ({name})" for name, g in gain.items()) + f" faster than SuperLU's, at "
        f"least {GAIN:g}x")


def _amg_rows(cs, gap):
    """The FE cell step with smoothed-aggregation AMG (pyamg) as the CG preconditioner,
    setup included, to tol 1e-10, against the direct solution of the production step: why
    the cell problems are solved directly (docs/user_guide.md).  Without pyamg (the ``amg``
    extra) the row says so."""
    try:
        import pyamg
    except ImportError:
        return [("FE cell step, pyamg SA + CG: pyamg absent (the amg extra)", 0.0, "")]
    import scipy.sparse.linalg as spla
    h_q = cs.at_quadrature(gap)
    K = cs.operator(h_q ** 3)
    F = cs.right_hand_sides(h_q, h_q ** 3)
    direct = cs._factor.factor(K.data).solve(F)

    def amg():
        ml = pyamg.smoothed_aggregation_solver(K, symmetry="symmetric")
        M, its = ml.aspreconditioner(), [0]
        out = [spla.cg(K, F[:, k], M=M, rtol=1e-10, atol=0.0,
                       callback=lambda _: its.__setitem__(0, its[0] + 1))[0] for k in range(3)]
        return np.column_stack(out), its[0]

    t, (X, its) = best_of(amg, 1)
    err = np.abs(X - direct).max() / np.abs(direct).max()
    return [("FE cell step, pyamg SA + CG (3 solves)", t,
             f"{its} CG it, max diff to direct {err:.1e}, h0 = 0.2 um")]
