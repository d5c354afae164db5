"""Run the benchmarks and print wall times with ratios to a same-run baseline.

    python benchmarks/run.py [GROUP ...]      # topography contact micro macro stribeck ...
                                              # (micro-full: ~15 min, estimate: ~40 min,
                                              #  estimate-paper: ~100 min, scale: ~10 min,
                                              #  amg: ~3 min, ab: the example cases on
                                              #  FEM_TWIN_AB_BASE and now, ~10 min,
                                              #  cores: the bundled case on 1, 2, all workers;
                                              #  deterministic: the mixed regime, ~20 min;
                                              #  deterministic-fine: its knee at eps 1/8 to
                                              #  1/32, ~70 min;
                                              #  unsteady: both bodies rough, moving;
                                              #  peers: the average-flow model beside the
                                              #  twin and the deterministic pads, ~45 min;
                                              #  estimates: each example's printed run
                                              #  time against its run, ~4 min, ~9 with
                                              #  FEM_TWIN_ESTIMATE_LOAD=1;
                                              #  contact-area: the dry area against
                                              #  the cell grid, ~2 min;
                                              #  only when named)
"""

from __future__ import annotations

import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from fem_twin import read_topography  # noqa: E402
from fem_twin import topography as tp  # noqa: E402
from fem_twin.topography.prepare import prepare_pin  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from ab import bench_ab  # noqa: E402
from amg import bench_amg  # noqa: E402
from common import SAMPLE, best_of, macro_factors, macro_gap  # noqa: E402
from contact_area import bench_contact_area  # noqa: E402
from cores import bench_cores  # noqa: E402
from defaults import bench_defaults  # noqa: E402
from deterministic import bench_deterministic, bench_deterministic_fine  # noqa: E402
from estimates import bench_estimates  # noqa: E402
from peers import bench_peers  # noqa: E402
from scale import bench_scale  # noqa: E402
from unsteady import bench_unsteady  # noqa: E402


def bench_topography():
    """Macro pin reconstruction at 500^2 against one rfft2+irfft2 of the same grid."""
    raw = read_topography(os.path.join(SAMPLE, "pin_1.npz"))
    z = np.nan_to_num(raw.heights)
    base, _ = best_of(lambda: np.fft.irfft2(np.fft.rfft2(z), s=z.shape), 5)
    rows = [("baseline: rfft2+irfft2 500^2", base, "")]
    t_fill, filled = best_of(lambda: tp.fill_defects(raw))
    rows.append(("fill_defects (Laplace) 500^2", t_fill, f"{(~raw.valid).sum()} holes"))
    t_filt, _ = best_of(lambda: tp.gaussian_filter(filled, 9))
    rows.append(("gaussian_filter 9 px 500^2", t_filt, ""))
    t_ref, _ = best_of(lambda: tp.refine(filled, 4))
    rows.append(("refine 500 -> 1997", t_ref, ""))
    t_pin, _ = best_of(lambda: prepare_pin(raw))
    rows.append(("prepare_pin (whole chain, 256^2 out)", t_pin, ""))
    return base, rows


def bench_contact(sizes=(256, 512, 1024)):
    """Periodic rough contact (Hurst 0.8, Sq 150 nm, 85 um patch) vs textbook numpy PK."""
    from contact_reference import polonsky_keer

    from fem_twin import contact
    from fem_twin.topography.synthetic import self_affine

    e_red = contact.reduced_modulus(210e9, 0.3, 210e9, 0.3)
    rows, base = [], None
    for n in sizes:
        dx = 85e-6 / n
        shape = -self_affine((n, n), dx, 0.8, 150e-9, rng=1).heights
        z = np.random.default_rng(0).random((n, n))
        t_fft, _ = best_of(lambda: np.fft.irfft2(np.fft.rfft2(z), s=z.shape), 5)
        load = 100e6 * 85e-6 ** 2
        t_ref, (p_ref, it_ref) = best_of(lambda: polonsky_keer(shape, dx, e_red, 100e6), 1)
        t_el, el = best_of(lambda: contact.solve(shape, dx, e_red, load=load, periodic=True), 1)
        near = contact.solve(shape, dx, e_red, load=0.9 * load, periodic=True)
        t_w, warm = best_of(lambda: contact.solve(shape, dx, e_red, load=load, periodic=True,
                                                  initial_pressure=near.pressure), 1)
        h0 = el.separation
        t_s, sep = best_of(lambda: contact.solve(shape, dx, e_red, separation=h0, periodic=True,
                                                 hardness=6.99e9), 1)
        t_sw, sepw = best_of(lambda: contact.solve(shape, dx, e_red, separation=h0, periodic=True,
                                                   hardness=6.99e9,
                                                   initial_pressure=el.pressure), 1)
        base = base or t_fft
        per = lambda t, it: f"{it} it, {t / it / t_fft:.2f} x (rfft2+irfft2) per it"  # noqa: E731
        assert np.abs(el.pressure - p_ref).max() < 1e-6 * p_ref.max()
        rows += [
            (f"{n}^2 baseline rfft2+irfft2", t_fft, ""),
            (f"{n}^2 textbook numpy PK, 100 MPa (ref)", t_ref, per(t_ref, it_ref)),
            (f"{n}^2 fem_twin PK, 100 MPa, cold", t_el, per(t_el, el.iterations)),
            (f"{n}^2 fem_twin PK, warm from 90 MPa", t_w, per(t_w, warm.iterations)),
            (f"{n}^2 fixed h0 + H, cold", t_s, per(t_s, sep.iterations)),
            (f"{n}^2 fixed h0 + H, warm", t_sw, per(t_sw, sepw.iterations)),
        ]
    rows.append(_warm_patch_sweep(e_red))
    return base, rows


REPS = 3


def bench_contact_pk(sizes=(256, 1024)):
    """fem_twin.contact against the shared plain-numpy Polonsky-Keer (``../shared/baselines/
    pk_numpy.py``, one thread) on the periodic rough surface of ``contact``: load control
    (100 MPa), gap control (the separation of that state), gap + hardness (a cap of 0.6 x the
    elastic peak, so points are plastic) and load + hardness.  Both at tol 1e-8 (each its own
    criterion); accuracy: L2 of the pressure against a tol 1e-12 reference (fem_twin), bar
    1e-6.  FFT pairs per iteration counted in both (fem_twin: double + single precision).
    Tamaas's load-controlled PK beside them when it is installed (``pip install tamaas``).
    Each timing is the best of ``REPS`` runs (this machine's noise is 10-30 %).  Baseline:
    one rfft2+irfft2 pair."""
    shared = os.path.join(HERE, "..", "..", "shared", "baselines")
    if not os.path.isfile(os.path.join(shared, "pk_numpy.py")):
        return 1.0, [("pk_numpy.py absent (../shared/baselines): nothing to compare", 0.0, "")]
    sys.path.insert(0, shared)
    import pk_numpy

    from fem_twin import contact
    from fem_twin.contact import elastic
    from fem_twin.topography.synthetic import self_affine
    try:
        import tamaas
        tamaas.initialize(1)
        tamaas.set_log_level(tamaas.LogLevel.error)
    except ImportError:
        tamaas = None

    calls = {"n": 0, "single": 0}
    plain, single = elastic.ElasticOperator.__call__, elastic.ElasticOperator.single

    def counted(self, p):
        calls["n"] += 1
        return plain(self, p)

    def counted_single(self, p):
        calls["single"] += 1
        return single(self, p)

    elastic.ElasticOperator.__call__ = counted
    elastic.ElasticOperator.single = counted_single
    e_red = contact.reduced_modulus(210e9, 0.3, 210e9, 0.3)
    rows, base = [], None
    try:
        for n in sizes:
            dx = 85e-6 / n
            shape = -self_affine((n, n), dx, 0.8, 150e-9, rng=1).heights
            z = np.random.default_rng(0).random((n, n))
            t_fft, _ = best_of(lambda: np.fft.irfft2(np.fft.rfft2(z), s=z.shape), 5)
            base = base or t_fft
            load = 100e6 * 85e-6 ** 2
            el = contact.solve(shape, dx, e_red, load=load, periodic=True, tol=1e-12)
            cap = 0.6 * el.pressure.max()
            cases = {"load": dict(load=load), "gap": dict(separation=el.separation),
                     "gap + hardness": dict(separation=el.separation, hardness=cap),
                     "load + hardness": dict(load=load, hardness=cap)}
            K = pk_numpy.Periodic((n, n), (85e-6, 85e-6), e_red / 2, workers=1)
            for name, kw in cases.items():
                ref = contact.solve(shape, dx, e_red, periodic=True, tol=1e-12, **kw).pressure
                pk_kw = dict(hardness=kw.get("hardness", np.inf), tol=1e-8)
                if "load" in kw:
                    pk_kw["pmean"] = 100e6
                else:
                    pk_kw["offset"] = kw["separation"]
                K.nfft = 0
                t_pk, out = best_of(lambda: pk_numpy.solve(K, -shape, **pk_kw), REPS)
                calls["n"] = calls["single"] = 0
                t_ft, res = best_of(lambda: contact.solve(shape, dx, e_red, periodic=True,
                                                          tol=1e-8, **kw), REPS)
                l2 = lambda p: np.linalg.norm(p - ref) / np.linalg.norm(ref)  # noqa: E731
                rows += [(f"{n}^2 {name}: pk_numpy", t_pk, f"{out['it']} it, "
                          f"{K.nfft / REPS / 2 / out['it']:.2f} FFT pairs/it, "
                          f"L2 {l2(out['p']):.1e}"),
                         (f"{n}^2 {name}: fem_twin", t_ft, f"{res.iterations} it, "
                          f"{calls['n'] / REPS / res.iterations:.2f} + "
                          f"{calls['single'] / REPS / res.iterations:.2f} single FFT pairs/it, "
                          f"L2 {l2(res.pressure):.1e}; pk_numpy / fem_twin = {t_pk / t_ft:.2f}")]
                if name == "load" and tamaas is not None:
                    rows.append(_tamaas_row(tamaas, shape, dx, e_red, ref, t_ft, f"{n}^2 {name}"))
    finally:
        elastic.ElasticOperator.__call__ = plain
        elastic.ElasticOperator.single = single
    return base, rows


def _tamaas_row(tamaas, shape, dx, e_red, ref, t_ft, label):
    """Tamaas's Polonsky-Keer (Rey's variant, one thread) under the same mean pressure
    (100 MPa) at tol 1e-8; its E* = E'/2 against a rigid surface of heights -shape."""
    n = shape.shape[0]
    model = tamaas.ModelFactory.createModel(tamaas.model_type.basic_2d, [n * dx] * 2, [n, n])
    model.E, model.nu = e_red / 2, 0.0
    solver = tamaas.PolonskyKeerRey(model, np.ascontiguousarray(-shape), 1e-8)
    t, _ = best_of(lambda: solver.solve(100e6), 1)
    p = np.array(model.traction).reshape(n, n)
    return (f"{label}: Tamaas", t, f"L2 {np.linalg.norm(p - ref) / np.linalg.norm(ref):.1e}; "
            f"Tamaas / fem_twin = {t / t_ft:.2f}")


def _warm_patch_sweep(e_red):
    """The micro stage's contact use: sample patch 3 at 256^2, 8 sliding instants, h0 from
    0.4 to 0.1 um, each warm-started from the same instant at the previous h0 (hardness
    cap on); time per CG iteration in units of one rfft2+irfft2 pair at 256^2."""
    from fem_twin import contact
    from fem_twin.micro.sliding import CellSettings, sliding_pass
    pin, disk = _patch_pair()
    shapes = sliding_pass(pin.heights, disk.heights, pin.spacing, CellSettings(steps=8)).shapes
    z = np.random.default_rng(0).random(pin.shape)
    t_fft, _ = best_of(lambda: np.fft.irfft2(np.fft.rfft2(z), s=z.shape), 5)

    def sweep():
        warm, its = [None] * len(shapes), 0
        for h0 in (0.4e-6, 0.3e-6, 0.2e-6, 0.14e-6, 0.1e-6):
            for k, s in enumerate(shapes):
                r = contact.solve(s, pin.spacing, e_red, separation=h0, hardness=6.99e9,
                                  periodic=True, initial_pressure=warm[k])
                warm[k], its = (r.pressure if r.load > 0 else None), its + r.iterations
        return its
    t, its = best_of(sweep, 1)
    return ("256^2 patch sweep, 8 instants x 5 h0, warm", t,
            f"{its} it, {t / its / t_fft:.2f} x (rfft2+irfft2) per it")


def _patch_pair(n=256):
    from fem_twin.topography.prepare import prepare_patch
    pin = prepare_patch(read_topography(os.path.join(SAMPLE, "patch_3_pin.npz")), (n, n))
    disk = prepare_patch(read_topography(os.path.join(SAMPLE, "patch_3_disk.npz")), (n, n),
                         upper=True)
    return pin, disk


def _amg_rows(cs, gap):
    """The FE cell step with smoothed-aggregation AMG (pyamg) as the CG preconditioner,
    setup included, to tol 1e-10, against the direct solution of the production step: why
    the cell problems are solved directly (docs/user_guide.md)."""
    import pyamg
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


def bench_micro(full=False):
    """Cell problems at 256^2 (sample patch 3) against a full scikit-fem assembly.

    ``full``: the whole patch pair, 100 h0 x 32 steps on 2 processes (about 15 min here);
    otherwise 10 of the 100 h0 values (every 10th) serially, whose time x 10 / 2 estimates it.
    """
    from fem_twin.contact import solve
    from fem_twin.contact.levelling import TABLE4
    from fem_twin.fvm import CellSolverFV
    from fem_twin.micro import DEFAULT_H0, CellSolver, homogenise
    from fem_twin.micro.cell import flow_form

    pin, disk = _patch_pair()
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
    for name, make in (("FE", CellSolver), ("FVM", CellSolverFV)):
        for backend in backends:
            solver = make(pin.shape, pin.spacing, backend=backend)
            t, _ = best_of(lambda: solver.solve(gap))
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
    return base, rows


def bench_macro():
    """One operating point (150 N, 0.066 Pa s, 0.1 and 1 m/s), cold start, FE and FVM.

    Sample pin 1 on disk 1 at 128^2 and 256^2; flow factors of sample patch 1 at 64^2
    (30 h0 x 8 steps, computed first).  Baseline: the FVM point at 128^2, 1 m/s.
    Goal: a converged 256^2 point in under 20 s.
    """
    from fem_twin.macro import Lubricant, MacroSettings, solve_mixed

    ff = macro_factors()
    rows, base = [], None
    for n in (128, 256):
        gap, spacing, face = macro_gap(n)
        for speed in (1.0, 0.1):
            cf = {}
            for method in ("fvm", "fe"):
                t0 = time.perf_counter()
                r = solve_mixed(gap, spacing, ff, load=150.0, speed=speed, face=face,
                                lubricant=Lubricant(0.066), settings=MacroSettings(method=method))
                t = time.perf_counter() - t0
                base = base or t
                cf[method] = r.friction_coefficient
                newton = int(r.history[:, 6].sum())
                rows.append((f"{method.upper()} {n}^2, U = {speed} m/s", t,
                             f"{r.iterations} it, {newton} Newton steps, "
                             f"C_f {r.friction_coefficient:.5f}"))
            rows.append(("  FE / FVM time; |C_f,dev|", rows[-1][1] / rows[-2][1],
                         f"{abs(cf['fe'] - cf['fvm']) / 0.19245:.2e}"))
            t0 = time.perf_counter()
            r = solve_mixed(gap, spacing, ff, load=150.0, speed=speed, face=face,
                            lubricant=Lubricant(0.066),
                            settings=MacroSettings(method="fvm", complementarity="fb"))
            rows.append((f"FVM + FBNS (paper's inner solver) {n}^2, U = {speed}",
                         time.perf_counter() - t0,
                         f"{r.iterations} it, {int(r.history[:, 6].sum())} Newton steps, "
                         f"C_f {r.friction_coefficient:.5f}"))
    return base, rows


def bench_stribeck():
    """The bundled case end to end (fresh output folder), and one paper-grade Stribeck curve:
    25 speeds 2 -> 0.01 m/s at 256^2 with the flow factors given (sample patch 1 at 64^2,
    30 h0 x 8 steps).  Baseline: the first (cold) point of that curve.  Goal: curve < 600 s.
    """
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
    return base, rows


def bench_newton():
    """The macro Newton loop: a warm-started sweep of 8 speeds (2 -> 0.01 m/s) at 128^2 and
    256^2 by the previous method (SuperLU, symbolic analysis and matrix slicing every step,
    every inner Reynolds solve to convergence: ``inner_steps=0``), by PARDISO on the fixed
    stencil pattern (analysis once per grid) with exact inner solves, and by the default
    (PARDISO, one Newton step per inner solve while the coupling is far from converged).
    Baseline: the previous method at 128^2.  Goal of the paper-grade issue: 2x at 256^2."""
    from fem_twin.macro import Lubricant, MacroSettings
    from fem_twin.numerics.linalg import _mkl_rt
    from fem_twin.stribeck import SweepRequest, stribeck_sweep

    ff = macro_factors()
    backend = "pardiso" if _mkl_rt() is not None else "superlu"
    methods = {"previous (SuperLU, exact inner solves)": ("superlu", 0),
               f"{backend}, exact inner solves": (backend, 0),
               f"default ({backend}, inexact inner solves)": (backend, 1)}
    rows, base = [], None
    for n in (128, 256):
        gap, spacing, face = macro_gap(n)
        times, cf = [], []
        for name, (sparse, steps) in methods.items():
            os.environ["FEM_TWIN_SPARSE"] = sparse
            t0 = time.perf_counter()
            c = stribeck_sweep(SweepRequest(gap, spacing, ff, np.geomspace(2.0, 0.01, 8),
                                            load=150.0,
                               lubricant=Lubricant(0.066), face=face,
                               settings=MacroSettings(inner_steps=steps)))
            times.append(time.perf_counter() - t0)
            cf.append(c.friction_coefficient)
            base = base or times[-1]
            rows.append((f"sweep of 8 speeds {n}^2: {name}", times[-1],
                         f"{int(c.iterations.sum())} coupling iterations; previous / this = "
                         f"{times[0] / times[-1]:.2f}, max |C_f,dev| "
                         f"{np.abs(cf[-1] - cf[0]).max() / 0.19245:.1e}"))
        os.environ.pop("FEM_TWIN_SPARSE")
    return base, rows


def bench_paper():
    """A reduced paper case and the whole-twin extrapolation (examples/paper.toml: 6 patch
    pairs at 256^2 x 32 steps over the paper's 100 h0 candidates, adaptive h0; 2
    viscosities x 25 speeds (+ refinement, ~37 points) at 256^2; patch band: 12 more
    sweeps at 64^2, the nested solves' coarsest grid; 2 cores).  Measured here: sample
    patch pair 3 at 256^2, adaptive h0 on 2 processes, and the previous method's cost of
    one h0 (10 of the 100, serial); 8 consecutive speeds of the paper's 25 (0.53 -> 0.07 m/s) at
    256^2 with the macro groups' flow factors (patch 1 at 64^2, 30 h0), the first point cold, and
    the same speeds on the band's grids (128^2, "coarse", the default before; 64^2, "coarsest").
    Baseline: the measured micro time of one h0."""
    from fem_twin.case import load_case
    from fem_twin.macro import Lubricant
    from fem_twin.macro.nested import nested_levels
    from fem_twin.macro.point import coarsened
    from fem_twin.micro import DEFAULT_H0, homogenise
    from fem_twin.stribeck import SweepRequest, stribeck_sweep

    case = load_case(os.path.join(HERE, "..", "examples", "paper.toml"))
    cores, patches, n_mu = 2, len(case.geometry.patches), len(case.lubricant.viscosities)
    pin, disk = _patch_pair()
    t0 = time.perf_counter()
    homogenise(pin, disk, DEFAULT_H0[::10], workers=1, error_estimate=False)
    per_h0 = (time.perf_counter() - t0) / 10
    t0 = time.perf_counter()
    ad = homogenise(pin, disk, DEFAULT_H0, workers=cores, h0_tol=case.micro.h0_tol)
    t_pair = time.perf_counter() - t0
    gap, spacing, face = macro_gap(256)
    speeds = np.geomspace(2.0, 0.01, case.sweep.count)[6:14]
    ff = macro_factors()          # smooth factors (30 h0): 10 h0 kink p_con, the sweep stalls
    t0 = time.perf_counter()
    stribeck_sweep(SweepRequest(gap, spacing, ff, speeds[:1], load=150.0,
                                lubricant=Lubricant(0.066),
                   face=face))
    cold = time.perf_counter() - t0
    t0 = time.perf_counter()
    curve = stribeck_sweep(SweepRequest(gap, spacing, ff, speeds, load=150.0,
                                        lubricant=Lubricant(0.066),
                           face=face))
    warm = (time.perf_counter() - t0 - cold) / (speeds.size - 1)
    band = []                                  # a point on each of the band's grids
    grid = (gap, spacing, face)
    for _ in range(nested_levels(gap.shape)):
        grid = coarsened(*grid)
        t0 = time.perf_counter()
        stribeck_sweep(SweepRequest(grid[0], grid[1], ff, speeds, load=150.0,
                                    lubricant=Lubricant(0.066),
                       face=grid[2]))
        band.append((time.perf_counter() - t0) / speeds.size)
    coarse, coarsest = band[0], band[-1]
    dense = per_h0 * case.micro.h0_count * patches / cores
    micro = t_pair * patches
    points = case.sweep.count * 1.5                      # refinement adds ~50 % (bundled)
    sweep = cold + (points - 1) * warm
    macro_avg = sweep * n_mu / min(cores, n_mu)
    macro_band = sweep * patches * n_mu / cores
    coarse_band = points * coarse * patches * n_mu / cores
    coarsest_band = points * coarsest * patches * n_mu / cores
    return per_h0, [
        ("micro: one h0 (32 steps, 256^2), measured", per_h0, "serial, 10 of the 100 h0"),
        ("micro: one patch pair, adaptive h0, measured", t_pair,
         f"{len(ad)} of {case.micro.h0_count} h0 on {cores} processes, error estimate "
         f"included; h0 bound {max(ad.meta['error_estimate']['h0'].values()):.1e}"),
        ("macro: cold 256^2 point, measured", cold, f"{speeds[0]:.2f} m/s"),
        ("macro: warm 256^2 point, measured", warm,
         f"{int(curve.iterations[1:].sum())} coupling iterations over {speeds.size - 1} "
         f"speeds {speeds[1]:.2f} -> {speeds[-1]:.2f} m/s"),
        ("paper twin, micro, all 100 h0 (extrapolated)", dense,
         f"{case.micro.h0_count} h0 x {patches} pairs / {cores} cores: the previous method"),
        ("paper twin, micro, adaptive h0 (extrapolated)", micro,
         f"{patches} pairs; {dense / micro:.1f}x faster than all 100 h0"),
        ("paper twin, Stribeck sweeps (extrapolated)", macro_avg,
         f"{points:.0f} points x {n_mu} viscosities / {cores} cores"),
        ("macro: warm 128^2 point of the band's grid, measured", coarse,
         f"the same speeds, every other node; {warm / coarse:.1f}x cheaper"),
        ("paper twin, patch band on the full grid (extrapolated)", macro_band,
         f"{patches * n_mu} single-patch sweeps / {cores} cores (band_grid = \"full\")"),
        ("paper twin, patch band at 128^2 (extrapolated)", coarse_band,
         f"{patches * n_mu} sweeps / {cores} cores (band_grid = \"coarse\"); "
         f"{macro_band / coarse_band:.1f}x faster than the full grid"),
        ("macro: warm 64^2 point of the band's grid, measured", coarsest,
         f"the same speeds, every fourth node; {warm / coarsest:.1f}x cheaper"),
        ("paper twin, patch band at 64^2 (extrapolated)", coarsest_band,
         f"{patches * n_mu} sweeps / {cores} cores (the default, \"coarsest\"); "
         f"{coarse_band / coarsest_band:.1f}x faster than at 128^2"),
        ("paper twin, whole (extrapolated)", micro + macro_avg + coarsest_band,
         f"{(micro + macro_avg + coarsest_band) / 60:.1f} min; "
         f"{(micro + macro_avg + coarse_band) / 60:.1f} min with the band at 128^2, "
         f"{(micro + macro_avg + macro_band) / 60:.0f} min on the full grid, "
         f"{(micro + macro_avg) / 60:.1f} min without a band"),
    ]


def _refined(case, scale, steps, h0, every_h0=False):
    """``case`` with both grids ``scale`` times finer, ``steps`` x the instants and the h0
    candidates refined ``h0`` times (old candidates kept), all of them solved with
    ``every_h0``."""
    from dataclasses import replace

    res = tuple(scale * n for n in case.preprocessing.resolution)
    cell = tuple(scale * n for n in case.micro.resolution)
    return replace(case, preprocessing=replace(case.preprocessing, resolution=res),
                   micro=replace(case.micro, resolution=cell, steps=steps * case.micro.steps,
                                 h0_count=h0 * (case.micro.h0_count - 1) + 1,
                                 h0_tol=0.0 if every_h0 else case.micro.h0_tol))


def _run_kept(case, name, reuse=False):
    """Run ``case`` into ``$FEM_TWIN_BENCH_DIR/name`` (kept, so an interrupted reference
    resumes from its checkpoints) or a temporary directory; wall time [s] and the curve.
    ``reuse``: a kept folder that holds a finished run is read as it is (its wall time from
    its summary.json), even when the code has changed since: a reference solution."""
    import json
    import tempfile

    from fem_twin.stages import pipeline
    from fem_twin.stribeck.curve import read_stribeck_csv

    keep = os.environ.get("FEM_TWIN_BENCH_DIR")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(keep, name) if keep else tmp
        summary = os.path.join(out, "summary.json")
        if reuse and os.path.isfile(summary):
            seconds = json.load(open(summary))["wall_time_s"]
        else:
            t0 = time.perf_counter()
            pipeline.run(case, out, progress=False)
            seconds = time.perf_counter() - t0
        return seconds, read_stribeck_csv(os.path.join(out, "stribeck.csv"))[0]


def bench_estimate(case_file="pin_on_disk.toml", viscosity=0.066):
    """Honesty of the C_f error estimate at full size: a case with its first patch pair and
    first viscosity (no speed refinement, no band) against a reference at twice the
    resolution on both scales, four times the steps and twice the h0 candidates.  The
    bundled case (its 128^2 macro grid and 96^2 cells, 16 h0, 20 steps; reference 256^2 /
    192^2, every one of 31 h0, 80 steps) or, as
    ``estimate-paper``, the paper case (256^2, 100 h0, 32 steps; reference 512^2, 199 h0,
    128 steps, a few hours on 2 cores).  Rows: per speed, the estimate over the change to
    the reference (goal: 1 to 3, or both below 0.05 % C_f,b).  Baseline: the base run.
    ``$FEM_TWIN_BENCH_DIR`` keeps both runs (and resumes them); a finished reference there
    is read, not run again."""
    from dataclasses import replace

    from fem_twin.case import load_case

    case = load_case(os.path.join(HERE, "..", "examples", case_file))
    case = replace(case, geometry=replace(case.geometry, patches=case.geometry.patches[:1]),
                   thermal=replace(case.thermal, model="none"),
                   lubricant=replace(case.lubricant, viscosities=(viscosity,),
                                     temperatures=case.lubricant.temperatures[:1]),
                   sweep=replace(case.sweep, refine=0), measured=(),
                   run=replace(case.run, patch_band=False))
    fine = _refined(case, 2, 4, 2, every_h0=case_file == "pin_on_disk.toml")
    stem = os.path.splitext(case_file)[0]
    t_base, base = _run_kept(case, f"{stem}_base")
    t_ref, ref = _run_kept(fine, f"{stem}_reference", reuse=True)
    cb = case.tribometer.boundary_friction
    res, cell = fine.preprocessing.resolution[0], fine.micro.resolution[0]
    rows = [(f"baseline: {stem}, 1 patch, 1 viscosity", t_base, ""),
            (f"reference: {res}^2 / {cell}^2, {fine.micro.h0_count} h0, "
             f"{fine.micro.steps} steps", t_ref, "")]
    for u, cf, err, cf_ref in zip(base.speed, base.friction_coefficient, base.friction_error,
                                  ref.friction_coefficient):
        actual = abs(cf - cf_ref)
        ok = (err < 5e-4 * cb and actual < 5e-4 * cb) or 1 <= err / actual <= 3
        rows.append((f"  {u:.4g} m/s: C_f {cf:.5f}, reference {cf_ref:.5f}", 0.0,
                     f"estimate {err / cb:.3%}, actual {actual / cb:.3%} C_f,b, "
                     f"effectivity {err / actual:.2f} {'ok' if ok else 'OUTSIDE'}"))
    return t_base, rows


GROUPS = {"topography": bench_topography, "contact": bench_contact, "micro": bench_micro,
          "contact-pk": bench_contact_pk, "macro": bench_macro, "newton": bench_newton,
          "paper": bench_paper, "stribeck": bench_stribeck,
          "estimate": bench_estimate, "scale": bench_scale, "amg": bench_amg, "cores": bench_cores,
          "estimate-paper": lambda: bench_estimate("paper.toml"),
          "micro-full": lambda: bench_micro(full=True), "defaults": bench_defaults,
          "deterministic": bench_deterministic, "ab": bench_ab,
          "deterministic-fine": bench_deterministic_fine,
          "estimates": bench_estimates, "unsteady": bench_unsteady, "peers": bench_peers,
          "contact-area": bench_contact_area}


def main(argv):
    groups = argv or [g for g in GROUPS if g not in ("micro-full", "estimate", "estimate-paper",
                                                        "scale", "amg", "cores", "defaults",
                                                        "deterministic", "ab", "estimates",
                                                        "unsteady", "deterministic-fine",
                                                        "peers", "contact-area")]
    for name in groups:
        base, rows, *summary = GROUPS[name]()
        print(f"\n## {name}")
        print(f"| {'case':50s} | {'time [s]':>9s} | {'x baseline':>10s} | notes")
        print(f"|{'-' * 52}|{'-' * 11}|{'-' * 12}|------")
        for label, t, note in rows:
            print(f"| {label:50s} | {t:9.4f} | {t / base:10.1f} | {note}")
        for line in summary:                    # a group's one checked line, last
            print(line)


if __name__ == "__main__":
    main(sys.argv[1:])
