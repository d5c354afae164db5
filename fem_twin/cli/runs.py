"""The ``fem-twin`` commands on a case or a finished run (run, compare, calibrate, fit,
validate, report, example); the parser is in :mod:`fem_twin.cli`."""

from __future__ import annotations

import json
import os
import shlex
import sys
from pathlib import Path

import numpy as np

from ..checks import number
from ..errors import FileSystemError, InputError, MissingFile
from ..io.layout import RunLayout

#: the bundled case's estimate on 2 cores of the calibration machine [s]
#: (``examples/pin_on_disk.toml``; tests/test_cli_inputs.py holds it to the estimate)
BUNDLED_SECONDS = 116.8
#: a run estimated above this many times the bundled case (both on the calibration
#: machine: the question does not depend on this machine's speed or load) asks for --yes
LONG_RUN_RATIO = 4.0
#: that threshold in the calibration machine's seconds
LONG_RUN_SECONDS = LONG_RUN_RATIO * BUNDLED_SECONDS
#: how a screening run (``[micro] model = "average-flow"``) names its model
SCREENING = ("the average-flow screening model (Patir-Cheng, Greenwood-Tripp): no cell "
             "problems, no error bar on C_f; its gap to the deterministic reference is in "
             "docs/peers.md")


def _confirm_cost(case, yes: bool) -> float | None:
    """Say which sections take defaults and what the run will cost on this machine now
    (:func:`fem_twin.runtime.machine.slowdown`); the estimate [s], or None (refused: a run
    estimated above :data:`LONG_RUN_RATIO` times the bundled case without ``--yes``)."""
    from ..runtime.cost import estimated_seconds
    from ..runtime.machine import slowdown
    if case.defaulted:
        print(f"fem-twin run: sections not in {case.source.name}, defaults used: " + ", ".join(
            f"[{s}]" for s in case.defaulted), file=sys.stderr)
    machine, local = os.cpu_count() or 1, case.run.scheduler in (None, "local")
    cores = case.run.workers or machine
    if local:                                   # more processes than cores share them
        cores = min(cores, machine)
    speed = slowdown(case.tribometer.ball, cores if local else 1)
    calibration = estimated_seconds(case, cores)
    seconds = estimated_seconds(case, cores, speed)
    on = {n: duration(estimated_seconds(case, n, speed)) for n in (16, 64)}
    mc = case.micro
    cells = (f"{mc.h0_count} h0 x {mc.steps} steps"
             f"{f' (adaptive h0, tolerance {mc.h0_tol:g})' if mc.h0_tol else ''}"
             if mc.model == "cells" else SCREENING)
    print(f"fem-twin run: {len(case.geometry.patches)} patch pairs at {mc.resolution[0]}x"
          f"{mc.resolution[1]}, {cells}; "
          f"{len(case.lubricant.viscosities)} x {case.sweep.count} speeds; estimated "
          f"{duration(seconds)} on {cores} cores, {on[16]} on 16 and {on[64]} on 64 (this "
          f"machine takes {speed} the calibration machine's time now)", file=sys.stderr)
    if calibration > LONG_RUN_SECONDS and not yes:
        ratio = calibration / BUNDLED_SECONDS
        print(f"fem-twin run: error: this run is estimated at {duration(seconds)}, "
              f"{ratio:.0f}x the bundled case (about "
              f"{duration(BUNDLED_SECONDS * seconds / calibration)} "
              f"here on 2 cores), above the {LONG_RUN_RATIO:.0f}x that asks first; check the "
              "case and run again with --yes", file=sys.stderr)
        return None
    return seconds


def duration(seconds: float) -> str:
    """``seconds`` for a person: "85 s", "4.2 min", "25 min"."""
    if seconds < 100:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.1f} min" if seconds < 600 else f"{seconds / 60:.0f} min"


def run(args):
    from ..case import load_case
    from ..stages.pipeline import run
    if not args.case.is_file():
        raise MissingFile(f"case file not found: {args.case} (give the case file as "
                                "the first argument)")
    case = load_case(args.case)
    fitted = case
    if args.from_fit is not None:
        from ..studies.fitting import apply_fit, read_fit, run_from_fit
        fitted = apply_fit(case, read_fit(args.from_fit))        # checked before any work
    _check_output(args.output)
    estimate = _confirm_cost(fitted, args.yes)
    if estimate is None:
        return 2
    if args.from_fit is None:
        summary = run(case, args.output, progress=not args.no_progress, estimated_s=estimate)
    else:
        summary = run_from_fit(case, args.from_fit, args.output, progress=not args.no_progress,
                               estimated_s=estimate)
    print(_short_summary(summary, args.output))
    if "prediction" in summary:
        p = summary["prediction"]
        print(f"  with the parameters of {p['fit']}: {RunLayout(args.output).prediction()}, "
              f"95 % band up to +-{p['max_band_half_width']:.4f} in C_f")
    return 0


def traction(args):
    from ..case import load_case
    from ..checks import plausible
    from ..stages.pipeline import traction
    from ..stribeck.traction import DEFAULT_RATIOS
    if not args.case.is_file():
        raise MissingFile(f"case file not found: {args.case}")
    case = load_case(args.case)
    plausible("--speed [m/s]", args.speed, "speed")
    ratios = DEFAULT_RATIOS if args.srr is None else args.srr
    if any(not 0 <= r <= 2 for r in ratios):
        raise InputError(f"--srr: slide-to-roll ratios lie in [0, 2] (50 % is 0.5), got "
                         f"{ratios}")
    summary = traction(case, args.output, args.speed, ratios, progress=not args.no_progress)
    out = RunLayout(args.output)
    t = summary["stages"]["traction"]
    print(f"{out.traction_csv}, {out.traction_png}: C_f at {len(t['slide_to_roll'])} "
          f"slide-to-roll ratios, u_m = {args.speed:g} m/s; largest estimated C_f error "
          f"{t['max_cf_err']:.2g}")
    return 0


def _short_summary(summary: dict, out: Path) -> str:
    """A few lines for the terminal; everything is in ``OUT/summary.json``."""
    from ..stribeck.accuracy import error_clause, film_clause

    stages = summary["stages"]
    estimated = (f"estimated {duration(summary['estimated_s'])}; "
                 if summary.get("estimated_s") else "")
    lines = [f"fem-twin run: {summary['case']} done in {duration(summary['wall_time_s'])} ("
             + estimated + ", ".join(f"{k} {v:.0f} s" for k, v in summary["seconds"].items())
             + ")"]
    for c in stages["stribeck"]["curves"]:
        lo, hi = c["friction_coefficient_range"]
        lines.append(f"  mu_0 = {c['viscosity_Pa_s']:g} Pa s: C_f from {lo:.4f} to {hi:.4f}")
    if "hersey_collapse_max_abs_cf_dev" in stages["stribeck"]:
        lines.append("  Hersey collapse: max |C_f,dev| = "
                     f"{stages['stribeck']['hersey_collapse_max_abs_cf_dev']:.2%} (eq 35)")
    film = stages["stribeck"].get("ehl_film")
    if film:
        lines.append(f"  EHL film at u_m = {film['entrainment_m_s']:g} m/s: h_c "
                     f"{film['h_c_m'] * 1e9:.0f} nm, h_min {film['h_min_m'] * 1e9:.0f} nm "
                     f"(Hamrock-Dowson, smooth: {film['hamrock_dowson_h_c_m'] * 1e9:.0f} nm, "
                     f"{film['hamrock_dowson_h_min_m'] * 1e9:.0f} nm)")
    err = stages["stribeck"].get("cf_error")
    if stages.get("micro", {}).get("model") == "average-flow":
        lines.append(f"  C_f by {SCREENING}")
    elif err:
        lines.append(f"  C_f estimated discretisation error: {error_clause(err)} ("
                     + ", ".join(f"{k} {v:.2%}" for k, v in err["parts_max_relative"].items())
                     + f"; tolerance {err['tolerance']:.2%}; flow-factor estimates in "
                     "summary.json)" + film_clause(err))
    graph = summary.get("task_graph")
    if graph:
        wall = graph["wall_s"]
        lines.append(f"  its {graph['tasks']} tasks ({graph['cpu_s']:.0f} CPU s) would take "
                     f"{wall['8']:.0f} s on 8 workers, {wall['64']:.0f} s on 64 (critical "
                     f"path {graph['critical_path_s']:.0f} s; fem_twin.runtime.taskgraph)")
    lines.append(f"results in {out}/ (stribeck.csv, plots, results.nc and fields.nc for "
                 f"fem_twin.results.open_run, fields/ for ParaView, summary.json, run.log); "
                 f"the figures on one page: fem-twin report {shlex.quote(str(out))}")
    return "\n".join(lines)


def _check_output(path) -> None:
    """Refuse an output folder that is a file or that this user cannot write, before the
    machine is measured or any work starts."""
    path = RunLayout(path).root                   # a file: refused there
    near = next((p for p in (path, *path.parents) if p.exists()), Path("."))
    if near.is_dir() and not os.access(near, os.W_OK | os.X_OK):
        raise InputError(f"-o {path}: {near} is not writable for this user; give another "
                         "output folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as err:                      # /proc, a read-only mount, a full disk
        raise FileSystemError(err.errno, f"-o {path}: cannot create the output folder "
                              f"({err.strerror}); give another") from None


def fit(args):
    from ..case import load_case
    from ..studies.fitting import check_fit_request, fit_case
    if not args.case.is_file():
        raise MissingFile(f"case file not found: {args.case}")
    case = load_case(args.case)
    params = [p.strip() for p in args.params.split(",") if p.strip()]
    check_fit_request(case, args.measured, params, args.predict, args.predict_load,
                      args.plateau)
    _check_output(args.output)
    if _confirm_cost(case, args.yes) is None:
        return 2
    result = fit_case(case, args.measured, args.output, params, predict_at=args.predict,
                      predict_loads=args.predict_load, plateau=args.plateau,
                      progress=not args.no_progress)
    for name in result["fit"]["parameters"] + [k for k in result if k.startswith("viscosity_")]:
        v = result[name]
        print(f"fem-twin fit: {name} = {v['value']:.5g} (95 %: {v['low']:.5g} to "
              f"{v['high']:.5g})")
    print(f"  rms C_f,dev {result['fit']['rms_cf_dev']:.2%} over {result['fit']['points']} "
          f"points; {RunLayout(args.output).fit} and fit.png")
    if "plateau" in result:
        for role in ("fitted", "predicted"):
            p = result["plateau"][role]
            if p["points"]:
                print(f"  {role}: {p['points']} points, rms C_f,dev {p['rms_cf_dev']:.2%}, "
                      f"largest {p['max_abs_cf_dev']:.2%} of C_f,b, {p['inside_band']} inside "
                      "their band")
    for warning in result["fit"]["warnings"]:
        print(f"  warning: {warning}")
    return 0


def calibrate(args):
    from ..case import load_case
    from ..studies.calibration import calibrate
    summary = calibrate(load_case(args.case), args.study, args.output, values=args.values,
                        progress=not args.no_progress)
    print(json.dumps(summary, indent=2))
    return 0


def html_report(args):
    from ..studies.report import write_report
    if args.output is not None and Path(args.output).is_dir():
        raise InputError(f"report -o {args.output} is a folder: give the page's file name "
                         "(e.g. report.html)")
    path = write_report(args.run, args.output, render=not args.no_3d)
    print(f"report: {path}")
    return 0


def validate(args):
    from dataclasses import replace

    from ..case import load_case
    from ..io.table import write_csv
    from ..stribeck import deviation_from_measured, plot_stribeck, read_measured_csv
    from ..stribeck.curve import read_stribeck_csv
    from ..stribeck.validation import check_like_with_like
    from ..tables import BOUNDARY_FRICTION
    if args.radius is not None:
        number("--radius [m]", args.radius, "length")
    run = RunLayout(args.run)
    csv_path = run.stribeck_csv
    if not csv_path.is_file():
        raise MissingFile(f"{csv_path} not found: give the output folder of fem-twin run")
    curves = read_stribeck_csv(csv_path)
    measured = read_measured_csv(args.measured, unit="rpm" if args.rpm else "m/s")
    mu = args.viscosity if args.viscosity is not None else measured.viscosity
    if mu is None:
        curve = curves[0]
    else:
        match = [c for c in curves if np.isclose(c.viscosity, mu, rtol=1e-6)]
        if not match:
            raise InputError(f"no curve at mu_0 = {mu:g} Pa s in {csv_path} (it has "
                             f"{[c.viscosity for c in curves]})")
        curve = match[0]
    if not np.all(np.isfinite(curve.friction_coefficient)):
        raise InputError(f"{csv_path}: the curve at mu_0 = {curve.viscosity:g} Pa s holds a "
                         "non-finite C_f; run fem-twin run on the case again to rewrite it")
    case_file = _run_case_file(args.run)
    case = load_case(case_file) if case_file else None
    boundary = case.tribometer.boundary_friction if case else BOUNDARY_FRICTION
    check_like_with_like(measured, case.tribometer.load if case else _run_load(args.run,
                                                                                measured),
                         curve.viscosity, str(args.measured))
    if args.rpm:
        radius = args.radius if args.radius is not None else (
            case.tribometer.sliding_radius if case else None)
        if radius is None:
            raise InputError("--rpm needs the sliding radius: give --radius [m]")
        measured = replace(measured, speed=measured.speed * 2 * np.pi * radius / 60)
    dev = deviation_from_measured(curve, measured, boundary)
    if not np.any(np.isfinite(dev)):
        raise InputError(f"the measured speeds ({measured.speed.min():.3g} to "
                         f"{measured.speed.max():.3g} m/s) lie outside the simulated range")
    png, table = run.validation_of(args.measured, ".png"), run.validation_of(args.measured, ".csv")
    band = None if measured.low is None else (measured.low, measured.high)
    plot_stribeck([curve], png,
                  labels=[f"simulated, $\\mu_0$ = {curve.viscosity:g} Pa s"],
                  reference=(measured.speed, measured.friction_coefficient, band),
                  boundary_friction=boundary)
    write_csv(table, {"speed_m_s": measured.speed, "measured_cf": measured.friction_coefficient,
                      "cf_dev": dev})
    inside = np.isfinite(dev)
    print(f"fem-twin validate: mu_0 = {curve.viscosity:g} Pa s against {args.measured.name}: "
          f"max |C_f,dev| = {np.nanmax(np.abs(dev)):.2%} (eq 35, C_f,b = {boundary:.5g}) at "
          f"{inside.sum()} of {dev.size} measured speeds; {table}, {png.name}")
    return 0


def _run_load(run: Path, measured) -> float:
    """The imposed load [N] a run recorded (its case file gone): its summary.json's, or the
    case its results.nc carries (older runs); else the measured curve's own (nothing to
    compare)."""
    import xarray as xr

    from ..results import ENGINE
    layout = RunLayout(run)
    try:
        return float(json.loads(layout.summary.read_text())["stages"]["stribeck"]["load_N"])
    except (OSError, ValueError, KeyError, TypeError):
        pass
    try:
        with xr.open_dataset(layout.results, group="stribeck", engine=ENGINE) as ds:
            return float(json.loads(ds.attrs["case"])["tribometer"]["load"])
    except (OSError, ValueError, KeyError, TypeError):
        return measured.load or 0.0


def _run_case_file(run: Path):
    """The case file recorded in a run's summary.json, if it still exists."""
    try:
        path = Path(json.loads(RunLayout(run).summary.read_text())["provenance"]["case_file"])
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return path if path.is_file() else None


def example(args):
    from importlib.resources import files

    from ..io.samples import generate
    _check_output(args.folder)
    case = args.folder / "pin_on_disk.toml"
    case.write_text(files("fem_twin.cases").joinpath("pin_on_disk.toml").read_text())
    generate(args.folder / "meshes" / "sample")
    print(f"wrote {case} and {args.folder / 'meshes' / 'sample'}/; run it with\n"
          f"  fem-twin run {case} -o {args.folder / 'out'}")
    return 0


def compare(args):
    from ..case import load_case
    from ..studies.compare import compare
    summary = compare(load_case(args.case), args.output, progress=not args.no_progress)
    print(json.dumps(summary, indent=2))
    return 0
