"""``fem-twin report OUT``: one self-contained HTML page with the paper's figures for a run.

Figures (images embedded as base64 PNG): the 3D virtual geometry of pin and disk and of one
roughness patch (Figures 2 and 6; pyvista in a child process, skipped with a note when no
OpenGL backend exists), the levelled pin centre lines (Figure 3), the flow factors
(Figures 4-5), the Stribeck curves versus speed and Hersey number with the patch scatter band
and measured curves (Figure 14), the macro fields, validation and calibration deviations
(Figures 9-13) when the run folder has them; then the error estimates, settings and timings.
"""

from __future__ import annotations

import base64
import html
import json
from pathlib import Path

import numpy as np

from ..errors import InputError, MissingFile
from ..io.atomic import atomic_path
from ..io.figure import save_figure
from ..io.files import read_topography
from ..io.layout import RunLayout
from ..io.render import render_views
from ..macro.laws.friction import LAWS
from ..stribeck.accuracy import error_clause, film_clause
from .fit_file import read_fit


def write_report(outdir, path=None, *, render: bool = True) -> Path:
    """Write ``OUT/report.html`` (or ``path``) for the run in ``outdir``; return its path."""
    out = RunLayout(outdir)
    summary_path = out.summary
    if not summary_path.is_file():
        raise MissingFile(f"{summary_path} not found: give the output folder of a "
                                "finished fem-twin run")
    try:
        summary = json.loads(summary_path.read_text())
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise InputError(f"{summary_path}: damaged ({err}); run fem-twin run on the case "
                         "again to rewrite it (finished work is kept)") from None
    if not isinstance(summary, dict):
        raise InputError(f"{summary_path}: not a run's summary (a JSON object); run fem-twin "
                         "run on the case again to rewrite it")
    work = out.report_figures
    work.mkdir(exist_ok=True)
    sections = [geometry_section(out, work, render), levelling_section(out, work),
                figure_section("Flow factors (Figures 4-5)", [out.flow_factors_png],
                               "Patch pairs and their average versus the separation h0, "
                               "with the friction factors of the force on the pin."),
                stribeck_section(out, summary.get("stages", {}).get("stribeck", {})
                                 .get("friction")), fit_section(out), calibration_section(out),
                tables_section(summary)]
    page = _PAGE.format(title=html.escape(f"fem_twin report: {summary.get('case', '')}"),
                        body="\n".join(s for s in sections if s))
    path = Path(path) if path is not None else out.report
    with atomic_path(path) as tmp:
        tmp.write_text(page)
    return path


def geometry_section(out: RunLayout, work: Path, render: bool) -> str:
    jobs = [(out.macro_vtu(1), work / "geometry_pin.png",
             "Figure 2: virtual pin 1 and disk 1"),
            (out.patch_vtu(1), work / "geometry_patch.png",
             "Figure 6: roughness patch pair 1")]
    jobs = [j for j in jobs if j[0].is_file()]
    if not render:
        return section("Virtual geometry (Figures 2 and 6)", "<p>3D views not rendered "
                       "(--no-3d).</p>")
    made, note = render_views(jobs)
    titles = {png: title for _, png, title in jobs}
    body = "".join(_figure(p, titles[p]) for p in made)
    if note:
        body += f'<p class="note">{html.escape(note)}</p>'
    return section("Virtual geometry (Figures 2 and 6)", body)


def levelling_section(out: RunLayout, work: Path) -> str:
    files = out.levelled_pins()
    if not files:
        return ""
    png = plot_centre_lines(files, work / "pin_centre_lines.png")
    return figure_section("Levelled pins (Figure 3)", [png], "Centre lines along the sliding "
                          "direction x1 of the levelled pins and their set average (pin face "
                          "only).")


def plot_centre_lines(files, path) -> Path:
    """Figure 3: x3_low along x1 through the centre of each levelled pin [um over mm]."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 3.8))
    for f in files:
        pin = read_topography(f)
        row = pin.heights[pin.shape[0] // 2]
        x1 = pin.origin[0] + pin.spacing[0] * np.arange(pin.shape[1])
        face = row > -20e-6
        ax.plot(x1 * 1e3, np.where(face, row * 1e6, np.nan),
                lw=2.0 if "average" in f.stem else 1.0, label=f.stem.replace("_", " "))
    ax.set_xlabel("$x_1$ [mm]")
    ax.set_ylabel("$x_{3,low}$ [µm]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)


def stribeck_section(out: RunLayout, friction: str | None = None) -> str:
    pngs = [out.stribeck_png("speed"), out.stribeck_png("hersey"), out.parts_png,
            out.temperature_png]
    law = LAWS[friction].description if friction in LAWS else "eq 31"
    text = ("Friction coefficient (eq 34) of the patch-average flow factors, the friction "
            f"being {law}, with the estimated "
            "discretisation error of each point as error bars; the shaded band spans the "
            "single-patch curves (Figure 13), squares are measured curves; C_f split into "
            "its film part, which the twin predicts, and its boundary part, which the "
            "boundary law's calibration sets (boundary_share); a thermal run "
            "adds the film's and the asperity contacts' temperatures.")
    body = figure_section("Stribeck curves (Figure 14)", pngs, text)
    fields, val = out.fields_pngs(), out.validation_pngs()
    return (body + figure_section("Traction curves (fem-twin traction)", [out.traction_png],
                                  "C_f versus the slide-to-roll ratio at one entrainment "
                                  "speed, each point with its estimated discretisation "
                                  "error.")
            + figure_section("Macro fields", fields, "Fastest, middle and slowest "
                             "point of each sweep.")
            + figure_section("Validation against measured curves (eq 35)", val, ""))


def fit_section(out: RunLayout) -> str:
    """``fem-twin fit``: the fitted parameters with their 95 % intervals, and the curves."""
    if not out.fit.is_file():
        return ""
    fit = read_fit(out.fit)
    names = fit["fit"]["parameters"] + [k for k in fit if k.startswith("viscosity_")]
    text = "; ".join(f"{k} = {fit[k]['value']:.4g} (95 %: {fit[k]['low']:.4g} to "
                     f"{fit[k]['high']:.4g})" for k in names)
    return figure_section("Fitted to measured curves", [out.fit_png],
                          f"{text}; rms C_f,dev {fit['fit']['rms_cf_dev']:.2%} (eq 35) over "
                          f"{fit['fit']['points']} points, weights: {fit['fit']['weights']}."
                          + "".join(f" {w}." for w in fit["fit"].get("warnings", [])))


def calibration_section(out: RunLayout) -> str:
    pngs = out.deviation_pngs()
    return figure_section("Calibration studies (Figures 9-13)", pngs,
                          "C_f,dev (eq 35) of each variant against its reference.")


def tables_section(summary: dict) -> str:
    stages = summary.get("stages", {})
    micro = stages.get("micro", {})
    rows = [("wall time", f"{summary.get('wall_time_s', float('nan')):.1f} s")]
    if "estimated_s" in summary:
        rows.append(("estimated before the run", f"{summary['estimated_s']:.0f} s"))
    rows += [(f"stage {k}", f"{v:.1f} s") for k, v in summary.get("seconds", {}).items()]
    graph = summary.get("task_graph") or {}
    rows += [(f"its {graph['tasks']} tasks on {w} workers (task graph)", f"{v:.1f} s")
             for w, v in graph.get("wall_s", {}).items()]
    timing = _table(["", "time"], rows)
    est = micro.get("error_estimate", {})
    qs = sorted({q for kind in est.values() if isinstance(kind, dict) for q in kind
                 if isinstance(kind[q], float)})
    errors = _table(["estimate", *qs], [(k, *(f"{v.get(q, float('nan')):.2%}" for q in qs))
                                       for k, v in est.items() if isinstance(v, dict)])
    stribeck = stages.get("stribeck", {})
    body = (f"<h3>Timings</h3><p>Of the last <code>fem-twin run</code> of this folder: stages "
            f"reused from its checkpoints take seconds.</p>{timing}"
            + cf_error_paragraph(stribeck.get("cf_error"))
            + "<h3>Estimated flow-factor errors (relative, largest over h0; the detail "
            f"behind the C_f estimate)</h3>{errors}")
    if "patch_band_max_width" in stribeck:
        body += (f"<p>Widest patch scatter band: ΔC_f = {stribeck['patch_band_max_width']:.4f}"
                 "</p>")
    if "hersey_collapse_max_abs_cf_dev" in stribeck:
        body += (f"<p>Hersey collapse between viscosities: max |C_f,dev| = "
                 f"{stribeck['hersey_collapse_max_abs_cf_dev']:.2%} (eq 35)</p>")
    body += ("<h3>Settings and provenance</h3><pre>"
             + html.escape(json.dumps({"provenance": summary.get("provenance"),
                                       "stages": stages}, indent=1, default=str)) + "</pre>")
    case_file = (summary.get("provenance") or {}).get("case_file")
    if case_file and Path(case_file).is_file():
        body += f"<h3>Case file</h3><pre>{html.escape(Path(case_file).read_text())}</pre>"
    return section("Error estimates, settings, timings", body)


def figure_section(title: str, pngs, text: str) -> str:
    pngs = [p for p in pngs if Path(p).is_file()]
    if not pngs:
        return ""
    return section(title, (f"<p>{html.escape(text)}</p>" if text else "")
                   + "".join(_figure(p, caption(Path(p))) for p in pngs))


def caption(png: Path) -> str:
    """A reader's caption for a figure file of the run folder."""
    stem = png.stem
    fixed = {"stribeck_speed": "C_f versus sliding speed U [m/s]",
             "stribeck_hersey": "C_f versus Hersey number (eq 46)",
             "stribeck_parts": "C_f split into its film (predicted) and boundary "
                               "(calibrated) parts, with the patch band",
             "flow_factors": "flow factors versus h0", "pin_centre_lines": "pin centre lines",
             "traction": "C_f versus the slide-to-roll ratio",
             "contact_temperature": "the film's and the asperity contacts' temperatures "
                                    "versus sliding speed",
             "cf_dev": f"C_f,dev of the {png.parent.name} study"}
    if stem in fixed:
        return fixed[stem]
    for prefix, text in (("fields_mu", "pressure, cavity fraction and contact pressure at "
                          "mu_0 = {} Pa s"), ("validation_mu", "measured against simulated "
                                              "at mu_0 = {} Pa s")):
        if stem.startswith(prefix):
            return text.format(stem[len(prefix):])
    return stem.replace("_", " ")


def section(title: str, body: str) -> str:
    return f"<section><h2>{html.escape(title)}</h2>{body}</section>"


def _figure(png, caption: str) -> str:
    data = base64.b64encode(Path(png).read_bytes()).decode()
    return (f'<figure><img alt="{html.escape(caption)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>")


def cf_error_paragraph(err) -> str:
    """The line on the C_f error estimate (``summary["stages"]["stribeck"]["cf_error"]``)."""
    if not err:
        return ""
    parts = ", ".join(f"{k} {v:.2%}" for k, v in err["parts_max_relative"].items())
    verdict = ("within" if err["points_above"] == 0 else
               f"above at {err['points_above']} points of")
    return (f"<h3>Accuracy of C_f</h3><p>Estimated discretisation error of every point's "
            f"friction coefficient (error bars of the Stribeck plots, <code>cf_err</code> in "
            f"stribeck.csv): {error_clause(err)} ({parts}), "
            f"{verdict} the tolerance {err['tolerance']:.2%} of C_f,b{film_clause(err)}.</p>")


def _table(header, rows) -> str:
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>"
                   for r in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font-family: sans-serif; max-width: 1100px; margin: 2em auto; color: #222; }}
figure {{ display: inline-block; margin: 0.5em; max-width: 100%; vertical-align: top; }}
img {{ max-width: 100%; border: 1px solid #ddd; }}
figcaption {{ font-size: 0.9em; color: #555; }}
table {{ border-collapse: collapse; margin: 0.5em 0; }}
td, th {{ border: 1px solid #ccc; padding: 0.2em 0.6em; text-align: right; }}
pre {{ background: #f6f6f6; padding: 0.6em; overflow-x: auto; font-size: 0.8em; }}
.note {{ color: #a60; }}
</style></head><body><h1>{title}</h1>
{body}
</body></html>
"""
