"""Cross-check of the FE solvers against the FVM reference twin on one case (issue: FVM).

Both methods run on the same prepared geometry: the cell problems of every patch pair
(flow factors per h0), and a Stribeck sweep at the case's first viscosity, FE with the FE
factors and FVM with the FVM factors.  Reported: per-h0 relative differences of the
averaged flow factors, the pressure and cavity-fraction field differences per speed, and
C_f,dev (eq 35) along the curve, with a plot; and each method against a converged
reference (FE on the cells refined by two with twice the steps, at three h0).
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..case import Case
from ..errors import InputError
from ..io.atomic import atomic_path
from ..io.figure import save_figure
from ..io.layout import RunLayout
from ..io.table import write_csv
from ..macro import MixedResult
from ..micro import FlowFactors
from ..micro.estimate import discrepancy, grid_separations
from ..micro.flow_factors import ARRAYS
from ..numerics.threads import executor_for
from ..stages.factors import homogenise_patches
from ..stages.geometry import level_pins, reconstruct_geometry
from ..stages.requests import macro_settings, sweep_request
from ..stribeck import friction_deviation, stribeck_sweep
from ..stribeck.sweep import point_files


def flow_factor_differences(fe: FlowFactors, fvm: FlowFactors) -> dict:
    """Per-h0 differences [-]: ``max |Delta A| / max |A|`` (likewise b, C),
    ``|Delta h_m| / h0``, ``|Delta d|``, and ``|Delta p_con| / max p_con``."""
    if not np.allclose(fe.h0, fvm.h0):
        raise InputError("flow factors to compare must share their h0 values")

    def rel(a, b, axes):
        return np.abs(a - b).max(axis=axes) / np.maximum(np.abs(b).max(axis=axes), 1e-300)

    return {"h0": fe.h0, "A": rel(fe.A, fvm.A, (1, 2)), "b": rel(fe.b, fvm.b, 1),
            "C": rel(fe.C, fvm.C, (1, 2)), "d": np.abs(fe.d - fvm.d).max(axis=1),
            "sC": np.abs(fe.friction_factor / fvm.friction_factor - 1),
            "h_m": np.abs(fe.h_m - fvm.h_m) / fe.h0,
            "p_con": np.abs(fe.p_con - fvm.p_con) / max(float(fvm.p_con.max()), 1e-300)}


def reference_factors(case: Case, outdir: Path, h0, *, executor=None,
                      progress: bool = True) -> FlowFactors:
    """The converged reference of the case's flow factors: FE on every patch cell refined
    by two (periodic bilinear, :func:`~fem_twin.topography.resample_cell`) with twice the
    time steps, at the smallest, middle and largest ``h0``; the patch average.  Both
    refinements halve the first-order grid error and the time error of the case's
    settings, so ``|f - f_ref|`` measures each method's own discretisation error."""
    mc = case.micro
    fine = replace(case, micro=replace(mc, method="fe", steps=2 * mc.steps, h0_tol=0.0,
                                       resolution=tuple(2 * n for n in mc.resolution)))
    out = RunLayout(outdir)
    ref_run = out.sub("reference")
    ref_run.root.mkdir(exist_ok=True)
    if not ref_run.geometry.exists():
        ref_run.geometry.symlink_to(out.geometry.resolve(), target_is_directory=True)
    homogenise_patches(fine, ref_run, executor, progress, h0=grid_separations(h0))
    ref = FlowFactors.load(ref_run.flow_factors)
    return FlowFactors(**{k: getattr(ref, k) for k in ARRAYS},
                       meta={**ref.meta, "grid": list(fine.micro.resolution),
                             "steps": fine.micro.steps})


def field_differences(fe: MixedResult, fvm: MixedResult) -> dict:
    """``max |Delta p_hd| / max(p_hd - p_amb)`` and ``max |Delta theta|`` of two operating
    points."""
    p_amb = fe.meta.get("settings", {}).get("ambient_pressure", 0.0)
    return {"pressure": float(np.abs(fe.pressure - fvm.pressure).max()
                              / max(float((fvm.pressure - p_amb).max()), 1e-300)),
            "cavity_fraction": float(np.abs(fe.cavity_fraction - fvm.cavity_fraction).max())}


def compare(case: Case, outdir, *, progress: bool = True) -> dict:
    """Run the case's micro and macro stages with both methods, each at every h0 of the case
    (no adaptive subset, so that they meet at the same separations); write ``compare.json``,
    ``compare_flow_factors.csv``, ``compare_stribeck.csv`` and ``compare.png``.  A
    ball-on-disk case is refused: its sweeps would need the entrainment speeds and the
    slide-to-roll ratio this study does not pass."""
    if case.tribometer.ball:
        raise InputError("fem-twin compare runs on pin-on-disk cases; for a ball, compare FE "
                         "and FVM by [micro] method and [macro] method in two runs")
    out = RunLayout(outdir)
    out.root.mkdir(parents=True, exist_ok=True)
    reconstruct_geometry(case, out, progress)
    level_pins(case, out, progress)
    factors = _both_factors(case, out, progress)
    reference = reference_factors(case, out.root, factors["fe"].h0, executor=None,
                                  progress=progress)
    against = {m: discrepancy(factors[m], reference) for m in ("fe", "fvm")}
    ffd = flow_factor_differences(factors["fe"], factors["fvm"])
    curves, points = {}, {}
    common = sweep_request(case, out, factors=factors["fe"], thermal=None)
    for method in ("fe", "fvm"):                  # isothermal: the methods, not the heat
        request = replace(common, factors=factors[method], settings=macro_settings(
            case, method), checkpoint=out.sub(method).points)
        curves[method] = stribeck_sweep(request, progress)
        points[method] = sorted((MixedResult.load(p) for p in point_files(request.checkpoint)),
                                key=lambda r: -r.speed)            # as the curve: fast first
    lub = request.lubricant
    dev = friction_deviation(curves["fe"].friction_coefficient,
                             curves["fvm"].friction_coefficient, case.tribometer.boundary_friction)
    fields = [field_differences(a, b) for a, b in zip(points["fe"], points["fvm"])]
    write_csv(out.compare_factors_csv, {"h0_m" if k == "h0" else k: v
                                                     for k, v in ffd.items()})
    write_csv(out.compare_stribeck_csv, {
        "speed_m_s": curves["fe"].speed, "cf_fe": curves["fe"].friction_coefficient,
        "cf_fvm": curves["fvm"].friction_coefficient, "cf_dev": dev,
        "pressure_diff": np.array([f["pressure"] for f in fields]),
        "cavity_fraction_diff": np.array([f["cavity_fraction"] for f in fields])})
    _plot(out.compare_png, ffd, curves, dev)
    summary = {"max_flow_factor_diff": {k: float(np.max(v)) for k, v in ffd.items()
                                        if k != "h0"},
               "against_reference": against,
               "reference": {"grid": list(reference.meta["grid"]),
                             "steps": reference.meta["steps"],
                             "h0_m": reference.h0.tolist()},
               "max_abs_cf_dev": float(np.abs(dev).max()),
               "max_pressure_diff": max(f["pressure"] for f in fields),
               "max_cavity_fraction_diff": max(f["cavity_fraction"] for f in fields),
               "viscosity_Pa_s": lub.viscosity,
               "files": [p.name for p in (out.compare_factors_csv, out.compare_stribeck_csv,
                                          out.compare_png)]}
    with atomic_path(out.compare) as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    return summary


def _both_factors(case: Case, out: RunLayout, progress: bool) -> dict:
    """``{method: FlowFactors}`` of the case by FE and by FVM at every h0 candidate, each in
    ``out/<method>`` beside links to the shared geometry and levelling."""
    factors = {}
    with executor_for(case.run.workers, case.run.scheduler) as executor:
        for method in ("fe", "fvm"):
            sub = out.sub(method)
            sub.root.mkdir(exist_ok=True)
            for link, target in ((sub.geometry, out.geometry), (sub.levelling, out.levelling)):
                if not link.exists():
                    link.symlink_to(target.resolve(), target_is_directory=True)
            c = replace(case, micro=replace(case.micro, method=method, h0_tol=0.0))
            homogenise_patches(c, sub, executor, progress)
            factors[method] = FlowFactors.load(sub.flow_factors)
    return factors


def _plot(path, ffd, curves, dev):
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
    for k in ("A", "b", "C", "h_m", "p_con"):
        ax[0].semilogy(ffd["h0"] * 1e6, np.maximum(ffd[k], 1e-16), label=k)
    ax[0].set_xlabel("h0 [um]")
    ax[0].set_ylabel("FE vs FVM relative difference")
    ax[0].legend()
    for m, c in curves.items():
        ax[1].semilogx(c.speed, c.friction_coefficient, "o-", ms=3, label=m.upper())
    ax[1].set_xlabel("sliding speed U [m/s]")
    ax[1].set_ylabel("C_f [-]")
    ax[1].legend()
    ax[2].semilogx(curves["fe"].speed, 100 * dev, "o-", ms=3)
    ax[2].set_xlabel("sliding speed U [m/s]")
    ax[2].set_ylabel("C_f,dev FE vs FVM [%] (eq 35)")
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
