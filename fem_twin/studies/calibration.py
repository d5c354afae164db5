"""Calibration studies (paper 3.2, Figures 9-13): how the Stribeck curve depends on choices.

Each study runs variants of a case and reports C_f,dev (eq 35) of every variant against a
reference curve at the case's first viscosity: ``filter``, the macro geometry's Gaussian
FWHM [px] (reference 11 px); ``resolution``, the macro grid [px] (by default the paper's
Figure 10: 128, 256, 500, 999 and 1997 px, the reference the maps' own resolution or else
the largest, the finer grids swept at :data:`FINE_SPEEDS` only); ``disk``, measured disks
against a flat one; ``pins``, every levelled pin against the set average; ``patches``,
every patch's flow factors against their average.

The micro scale is computed once and shared by the variants; each variant's sweep is a
task on the study's workers (``[run] workers``), its points checkpointed as they finish,
so an interrupted study resumes."""

from __future__ import annotations

import json
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace

import numpy as np

from ..case import Case
from ..checks import memory_shortfall
from ..errors import InputError
from ..io.atomic import atomic_path
from ..io.checkpoint import input_key
from ..io.figure import save_figure
from ..io.files import read_topography
from ..io.layout import RunLayout
from ..micro import FlowFactors
from ..numerics.threads import executor_for
from ..stages.factors import homogenise_patches
from ..stages.geometry import prepare_pins, reconstruct_geometry
from ..stages.requests import sweep_request
from ..stages.sweeps import run_sweeps
from ..stribeck import friction_deviation, plot_stribeck, write_stribeck_csv

STUDIES = ("filter", "resolution", "disk", "pins", "patches")
#: the paper's resolution study (3.2, Figure 10): macro grids [px] interpolated from its
#: measured 500^2 maps (the reference), 999 and 1997 keeping every measured point
PAPER_RESOLUTIONS = (128, 256, 500, 999, 1997)
#: ... and the speeds [m/s] at which it swept the grids finer than the reference, "in
#: order to save computational resources" (the other grids sweep these too)
FINE_SPEEDS = (0.1, 0.08, 0.06, 0.04, 0.02)


def variants(case: Case, study: str, values=None) -> tuple[dict, str]:
    """``{label: (case, patch index or None, speeds [m/s] or None for the case's)}`` of a
    study and the reference label."""
    g = case.preprocessing
    if values and study not in ("filter", "resolution"):
        raise InputError(f"--values: the {study} study takes none (its variants are the "
                         "case's own); --values goes with the filter and resolution studies")
    if case.tribometer.ball:
        raise InputError(f"the {study} study runs on pin-on-disk cases (the paper's 3.2); a "
                         "ball-on-disk case's sweeps need its slide-to-roll ratio, which the "
                         "studies do not pass")
    if study == "filter":
        if values and not all(0 <= v <= 200 for v in values):
            raise InputError(f"--values {values}: filter widths FWHM in pixels, 0 to 200")
        values = values or [0, 3, 5, 7, 9, 11]
        out = {f"fwhm {v:g} px": (replace(case, preprocessing=replace(g, fwhm_px=float(v))),
                                  None, None) for v in values}
        ref = max(values, key=lambda v: (v == 11, v))
        return out, f"fwhm {ref:g} px"
    if study == "resolution":
        return _resolutions(case, _grid_sizes(values or PAPER_RESOLUTIONS))
    if study == "disk":
        if not case.geometry.disks:
            raise InputError("the disk study needs measured disks in [geometry] disks")
        flat = replace(case, geometry=replace(case.geometry, disks=()))
        return {"measured disk": (case, None, None), "flat disk": (flat, None, None)}, \
            "measured disk"
    if study == "pins":
        out = {"set average": (replace(case, macro=replace(case.macro, pin="average")), None,
                               None)}
        for k in range(1, len(case.geometry.pins) + 1):
            out[f"pin {k}"] = (replace(case, macro=replace(case.macro, pin=k)), None, None)
        return out, "set average"
    if study == "patches":
        out = {"patch average": (case, None, None)}
        for k in range(1, len(case.geometry.patches) + 1):
            out[f"patch {k}"] = (case, k, None)
        return out, "patch average"
    raise InputError(f"unknown study {study!r}; choose one of {STUDIES}")


def _grid_sizes(values) -> list:
    """The resolution study's grids [px a side], whole numbers from 16, each within this
    machine's memory (:func:`fem_twin.checks.memory_shortfall`; else :class:`InputError`
    before any work)."""
    if not all(float(v).is_integer() and v >= 16 for v in values):
        raise InputError(f"--values {list(values)}: macro grids in pixels a side, whole "
                         "numbers from 16 (the paper: 128 256 500 999 1997)")
    for v in values:
        short = memory_shortfall(int(v) ** 2, "macro")
        if short:
            raise InputError(f"--values {int(v)}: {short}")
    return [int(v) for v in values]


def _resolutions(case: Case, values) -> tuple[dict, str]:
    """The resolution study's variants: the reference is the measured maps' own resolution
    if among ``values`` (no interpolation), else the largest; finer grids sweep
    :data:`FINE_SPEEDS`, the others the case's speeds and those."""
    measured = (read_topography(case.geometry.pins[0]).shape[0] if case.geometry.pins
                else None)
    ref = measured if measured in values else max(values)
    both = np.array(sorted({*case.sweep.speeds, *FINE_SPEEDS}, reverse=True))
    out = {f"{v} px": (replace(case, preprocessing=replace(case.preprocessing,
                                                            resolution=(v, v))), None,
                       np.array(FINE_SPEEDS) if v > ref else both) for v in values}
    return out, f"{ref} px"


def calibrate(case: Case, study: str, outdir, *, values=None, progress: bool = True) -> dict:
    """Run a study into ``outdir``; write ``calibration.json``, ``stribeck.csv`` (all
    variants) and plots of C_f and C_f,dev versus speed.  Returns the summary."""
    out = RunLayout(outdir)
    cases, ref_label = variants(case, study, values)        # checked before any work
    out.root.mkdir(parents=True, exist_ok=True)
    lub = case.lubricant.lubricants()[0]
    folders = [out.sub(f"variant_{i + 1}") for i in range(len(cases))]
    with executor_for(case.run.workers, case.run.scheduler) as executor:
        reconstruct_geometry(case, out, progress, executor)
        with ThreadPoolExecutor(1) as beside:      # the variants' pins beside the micro stage
            pins = beside.submit(prepare_pins, [(v, f) for (v, _, _), f in
                                                zip(cases.values(), folders)], progress,
                                 executor)
            homogenise_patches(case, out, executor, progress)
            pins.result()
        tasks = [_sweep(variant, folder, out, patch, speeds)
                 for folder, (variant, patch, speeds) in zip(folders, cases.values())]
        swept = run_sweeps(tasks, executor, progress, desc="calibration points").curves
    curves = dict(zip(cases, swept))
    ref = curves[ref_label]
    cfb = case.tribometer.boundary_friction
    dev = {k: friction_deviation(c.friction_coefficient, _at(ref, c.speed), cfb)
           for k, c in curves.items()}
    labels = list(curves)
    write_stribeck_csv(out.stribeck_csv, curves.values())
    plot_stribeck(list(curves.values()), out.stribeck_png("speed"), labels=labels,
                  boundary_friction=cfb)
    _plot_deviation(out.deviation_png, {k: c.speed for k, c in curves.items()}, dev,
                    ref_label, study)
    summary = {"study": study, "reference": ref_label, "viscosity_Pa_s": lub.viscosity,
               "variants": {k: {"folder": out.sub(f"variant_{i + 1}").root.name,
                                "max_abs_cf_dev": float(np.abs(dev[k]).max())}
                            for i, k in enumerate(labels)},
               "files": [p.name for p in (out.stribeck_csv, out.stribeck_png("speed"),
                                          out.deviation_png)]}
    with atomic_path(out.calibration) as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    return summary


def _sweep(variant: Case, folder: RunLayout, out: RunLayout, patch, speeds):
    """The sweep request of one variant (first viscosity) on its levelled pins in
    ``folder`` (:func:`~fem_twin.stages.geometry.prepare_pins`), its points in the study's
    checkpoints; isothermal, as the paper's studies."""
    path = out.patch_factors(patch)
    return sweep_request(variant, folder, factors=FlowFactors.load(path),
                         factors_key=input_key(np.frombuffer(path.read_bytes(), np.uint8)),
                         speeds=variant.sweep.speeds if speeds is None else speeds,
                         thermal=None, checkpoint=out.points)


def _at(curve, speeds):
    """``curve``'s C_f at ``speeds`` [m/s], each one of its own speeds."""
    return np.array([curve.friction_coefficient[np.flatnonzero(np.isclose(
        curve.speed, u, rtol=1e-12, atol=0))[0]] for u in speeds])


def _plot_deviation(path, speeds, dev, ref_label, study):
    """C_f,dev [%] of each variant at its speeds (``{label: speeds}``) against speed."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for label, d in dev.items():
        ax.semilogx(speeds[label], 100 * d, "o-", ms=3, label=label)
    ax.set_xlabel("sliding speed U [m/s]")
    ax.set_ylabel(f"C_f,dev vs {ref_label} [%] (eq 35)")
    ax.set_title(f"calibration study: {study}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
