"""Calibration studies (paper 3.2, Figures 9-13): how the Stribeck curve depends on choices.

Each study runs variants of a case and reports C_f,dev (eq 35) of every variant against a
reference curve, at the case's first viscosity:

``filter``
    Gaussian FWHM of the macro geometry [px] (0: unfiltered); reference 11 px
``resolution``
    macro grid size [px]; reference: the largest
``disk``
    measured disks against a flat disk; reference: measured
``pins``
    every single levelled pin against the set average; reference: average
``patches``
    flow factors of every single patch against the patch average; reference: the average

The micro scale is computed once (it does not depend on the macro choices) and shared by
the variants; every variant keeps its own checkpoints, so an interrupted study resumes.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np

from .case import Case
from .errors import InputError
from .io.atomic import atomic_path
from .io.figure import save_figure
from .io.layout import RunLayout
from .micro import FlowFactors
from .stages.curves import macro_settings
from .stages.factors import homogenise_patches
from .stages.geometry import face_load, level_pins, macro_geometry, reconstruct_geometry
from .stribeck import friction_deviation, plot_stribeck, stribeck_sweep, write_stribeck_csv
from .threads import executor_for

STUDIES = ("filter", "resolution", "disk", "pins", "patches")


def variants(case: Case, study: str, values=None) -> tuple[dict, str]:
    """``{label: (case, patch index or None)}`` of a study and the reference label."""
    g = case.macro_geometry
    if study == "filter":
        values = values or [0, 3, 5, 7, 9, 11]
        out = {f"fwhm {v:g} px": (replace(case, macro_geometry=replace(g, fwhm_px=float(v))),
                                  None) for v in values}
        ref = max(values, key=lambda v: (v == 11, v))
        return out, f"fwhm {ref:g} px"
    if study == "resolution":
        values = values or [64, 128, 256]
        out = {f"{int(v)} px": (replace(case, macro_geometry=replace(
            g, resolution=(int(v), int(v)))), None) for v in values}
        return out, f"{int(max(values))} px"
    if study == "disk":
        if not case.geometry.disks:
            raise InputError("the disk study needs measured disks in [geometry] disks")
        flat = replace(case, geometry=replace(case.geometry, disks=()))
        return {"measured disk": (case, None), "flat disk": (flat, None)}, "measured disk"
    if study == "pins":
        out = {"set average": (replace(case, macro=replace(case.macro, pin="average")), None)}
        for k in range(1, len(case.geometry.pins) + 1):
            out[f"pin {k}"] = (replace(case, macro=replace(case.macro, pin=k)), None)
        return out, "set average"
    if study == "patches":
        out = {"patch average": (case, None)}
        for k in range(1, len(case.geometry.patches) + 1):
            out[f"patch {k}"] = (case, k)
        return out, "patch average"
    raise InputError(f"unknown study {study!r}; choose one of {STUDIES}")


def calibrate(case: Case, study: str, outdir, *, values=None, progress: bool = True) -> dict:
    """Run a study into ``outdir``; write ``calibration.json``, ``stribeck.csv`` (all
    variants) and plots of C_f and C_f,dev versus speed.  Returns the summary."""
    out = RunLayout(outdir)
    out.root.mkdir(parents=True, exist_ok=True)
    cases, ref_label = variants(case, study, values)
    reconstruct_geometry(case, out, progress)
    with executor_for(case.run.workers, case.run.scheduler) as executor:
        homogenise_patches(case, out, executor, progress)
    lub = case.lubricant.lubricants()[0]
    curves = {}
    for i, (label, (variant, patch)) in enumerate(cases.items()):
        folder = out.sub(f"variant_{i + 1}")
        reconstruct_geometry(variant, folder, progress)
        level_pins(variant, folder, progress)
        factors = FlowFactors.load(out.patch_factors(patch))
        gap, spacing, face, _ = macro_geometry(variant, folder)
        curves[label] = stribeck_sweep(
            gap, spacing, factors, variant.sweep.speeds, load=face_load(variant),
            lubricant=lub, diameter=variant.tribometer.pin_diameter, face=face,
            settings=macro_settings(variant),
            checkpoint=folder.points, progress=progress).with_load_share(
                variant.tribometer.load_share)
    ref = curves[ref_label]
    dev = {k: friction_deviation(c.friction_coefficient, ref.friction_coefficient)
           for k, c in curves.items()}
    labels = list(curves)
    write_stribeck_csv(out.stribeck_csv, curves.values())
    plot_stribeck(list(curves.values()), out.stribeck_png("speed"), labels=labels)
    _plot_deviation(out.deviation_png, ref.speed, dev, ref_label, study)
    summary = {"study": study, "reference": ref_label, "viscosity_Pa_s": lub.viscosity,
               "variants": {k: {"folder": out.sub(f"variant_{i + 1}").root.name,
                                "max_abs_cf_dev": float(np.abs(dev[k]).max())}
                            for i, k in enumerate(labels)},
               "files": [p.name for p in (out.stribeck_csv, out.stribeck_png("speed"),
                                          out.deviation_png)]}
    with atomic_path(out.calibration) as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    return summary


def _plot_deviation(path, speed, dev, ref_label, study):
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for label, d in dev.items():
        ax.semilogx(speed, 100 * d, "o-", ms=3, label=label)
    ax.set_xlabel("sliding speed U [m/s]")
    ax.set_ylabel(f"C_f,dev vs {ref_label} [%] (eq 35)")
    ax.set_title(f"calibration study: {study}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
