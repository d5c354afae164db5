"""Command line: ``fem-twin STAGE ...``, one subcommand per pipeline stage."""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
from pathlib import Path

import numpy as np

from .errors import InputError, MissingFile, NotConverged, RunLocked, SchedulerUnreachable
from .io.layout import RunLayout

DEFAULT_CASE = Path("examples/pin_on_disk.toml")

#: topography steps: name -> help text
_STEPS = {
    "info": "print grid, pitch, Sq and invalid pixels",
    "convert": "rewrite in another format (by suffix: .npz .npy .txt .csv .xyz)",
    "fill": "fill invalid pixels by the Laplace equation",
    "level": "subtract the mean plane (optionally within --radius of --centre)",
    "clip": "limit heights to [--lower, --upper] m",
    "filter": "Gaussian filter with FWHM --fwhm pixels",
    "resample": "interpolate to --shape NY NX pixels",
    "refine": "insert points between originals (500 -> 999 with --factor 2)",
    "patch": "cut a --shape NY NX patch at --start ROW COL (no interpolation)",
    "align": "rotate so that --direction becomes x1 (sliding velocity)",
    "flip": "flip a disk over the pin (about x1)",
    "mount": "pin in its holder: below --truncation becomes the holder at --holder m",
    "prepare-pin": "whole pin chain: fill, level, clip, filter, resample, centre, mount",
    "prepare-disk": "whole disk chain: fill, level, clip, filter, resample, centre, flip",
    "prepare-patch": "whole roughness-patch chain: fill, level, patch (, flip with --upper)",
}


#: exit codes (README "When something goes wrong"): exception types -> (code, label, advice)
EXIT_CODES = (
    ((ValueError, FileNotFoundError, IsADirectoryError, NotADirectoryError), 2, "error",
     "check the input named above"),
    ((NotConverged,), 3, "not converged", "the residual history is in run.log; see README"),
    ((OSError,), 4, "file system", "check free space and write permission of the folder"),
    ((SchedulerUnreachable,), 5, "cluster", "start the scheduler or remove [run] scheduler"),
    ((RunLocked,), 6, "busy", ""),
)


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    level = (logging.INFO if args.verbose else logging.ERROR if args.quiet
             else logging.WARNING)
    logging.basicConfig(format="%(levelname)s %(name)s: %(message)s")
    for handler in logging.getLogger().handlers:   # the terminal; run.log keeps everything
        handler.setLevel(level)
        if not args.debug:                          # tracebacks: run.log; the error: below
            handler.addFilter(lambda record: not record.exc_info)
    try:
        return args.func(args) or 0
    except KeyboardInterrupt:
        print(f"fem-twin {args.command}: interrupted; finished work is kept, run the same "
              "command again to resume", file=sys.stderr)
        return 130
    except Exception as err:                   # one line for the user, traceback on request
        if args.debug:
            raise
        return _report(args.command, err)


def _report(command: str, err: Exception) -> int:
    """Print one line (what, and what to do) and return the documented exit code."""
    for types, code, label, advice in EXIT_CODES:
        if isinstance(err, types):
            hint = f" ({advice})" if advice and code != 2 else ""
            print(f"fem-twin {command}: {label}: {_one_line(err)}{hint}", file=sys.stderr)
            return code
    print(f"fem-twin {command}: internal error: {type(err).__name__}: {_one_line(err)} "
          "(run again with --debug for the traceback, and please report it)", file=sys.stderr)
    return 1


def _one_line(err: Exception) -> str:
    text = " ".join(str(err).split())
    return text if len(text) < 400 else text[:400] + " ..."


class _Formatter(argparse.HelpFormatter):
    """Help lines end with the option's default, unless it has none or the text says it."""

    def _get_help_string(self, action):
        text = action.help or ""
        if ("default" in text or action.required or action.default in (None, False, (), [])
                or action.default is argparse.SUPPRESS):
            return text
        return f"{text} (default: %(default)s)"


class _Parser(argparse.ArgumentParser):
    """Every (sub)command shows the defaults of its options in ``--help``."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", _Formatter)
        super().__init__(*args, **kwargs)


def build_parser() -> argparse.ArgumentParser:
    from . import __version__
    p = _Parser(
        prog="fem-twin",
        description="Digital twin of a pin-on-disk tribometer in mixed lubrication. "
                    "Stages: topography -> contact -> homogenise -> macro; 'run' executes "
                    "the whole pipeline of a case file (up to the Stribeck curve). Exit "
                    "codes: README, 'When something goes wrong'.")
    p.add_argument("--version", action="version", version=f"fem-twin {__version__}")
    p.add_argument("-v", "--verbose", action="store_true",
                   help="print every logged step (stages, points) on the terminal")
    p.add_argument("-q", "--quiet", action="store_true", help="print errors only")
    p.add_argument("--debug", action="store_true",
                   help="show the Python traceback of an error (otherwise one line)")
    sub = p.add_subparsers(dest="command", required=True, metavar="STAGE")

    _add_case_commands(sub)
    _add_run_commands(sub)
    _add_topography(sub)
    _add_contact(sub)
    _add_homogenise(sub)
    _add_macro(sub)
    _add_utilities(sub)
    return p


def _add_case_commands(sub):
    """run, compare and calibrate: the commands on a case file."""
    rn = _case_command(sub, "run", "run the pipeline of a case file (TOML) into an output "
                                   "folder", "out", _run)
    rn.add_argument("--yes", action="store_true",
                    help=f"start even if estimated longer than {LONG_RUN_SECONDS // 60} min")
    _case_command(sub, "compare", "cross-check FE against the FVM reference on a case: "
                                  "flow factors, fields, C_f,dev (eq 35)", "compare", _compare)
    cb = _case_command(sub, "calibrate", "calibration study of a case (paper 3.2): C_f,dev "
                                         "of variants against a reference curve",
                       "calibration", _calibrate)
    ft = sub.add_parser("fit", help="fit C_f,b and the oil temperature of a case to measured "
                                    "Stribeck curves (runs or resumes the case first)")
    ft.add_argument("case", type=Path, help="case file")
    ft.add_argument("measured", type=Path, nargs="+",
                    help="measured CSV per viscosity of the case (speed [m/s], "
                         "friction_coefficient, optional cf_min/cf_max)")
    ft.add_argument("-o", "--output", type=Path, default=Path("out"), help="output folder")
    ft.add_argument("--params", default="boundary_friction,temperature",
                    help="comma-separated case keys to fit: boundary_friction, temperature")
    ft.add_argument("--predict", type=float, nargs="+", default=[], metavar="T",
                    help="oil temperatures [C] of predicted curves with their 95 %% band "
                         "(OUT/prediction_TC.csv)")
    ft.add_argument("--no-progress", action="store_true", help="no progress bars")
    ft.add_argument("--yes", action="store_true", help="start even if the run is long")
    ft.set_defaults(func=_fit)
    cb.add_argument("--study", required=True,
                    choices=("filter", "resolution", "disk", "pins", "patches"))
    cb.add_argument("--values", type=float, nargs="+",
                    help="filter FWHMs [px] or resolutions [px] (defaults: 0 3 5 7 9 11; "
                         "64 128 256)")


def _add_run_commands(sub):
    """validate and report: the commands on a finished run."""
    va = sub.add_parser("validate", help="compare a finished run with a measured Stribeck "
                                         "curve: C_f,dev (eq 35) at the measured speeds")
    va.add_argument("run", type=Path, help="output folder of fem-twin run (its stribeck.csv)")
    va.add_argument("measured", type=Path, help="CSV with columns speed and "
                    "friction_coefficient (or cf), optionally cf_min, cf_max")
    va.add_argument("--viscosity", type=float,
                    help="mu_0 [Pa s] of the simulated curve to compare (default: the first)")
    va.add_argument("--rpm", action="store_true",
                    help="the measured 'speed' column is in rpm: U = 2 pi r n / 60 with the "
                         "case's sliding radius (or --radius)")
    va.add_argument("--radius", type=float, help="sliding radius r [m] for --rpm")
    va.set_defaults(func=_validate)

    rp = sub.add_parser("report", help="one self-contained HTML page with the paper's figures "
                                       "of a finished run (3D geometry, levelled pins, flow "
                                       "factors, Stribeck curves with the patch band, "
                                       "errors, settings, timings)")
    rp.add_argument("run", type=Path, help="output folder of fem-twin run")
    rp.add_argument("-o", "--output", type=Path, help="HTML file (default: RUN/report.html)")
    rp.add_argument("--no-3d", action="store_true",
                    help="skip the pyvista 3D views (Figures 2 and 6)")
    rp.set_defaults(func=_html_report)


def _add_topography(sub):
    """topography STEP: one pre-processing step per subcommand."""
    t = sub.add_parser("topography", help="read and pre-process measured topographies")
    steps = t.add_subparsers(dest="step", required=True, metavar="STEP")
    for name, text in _STEPS.items():
        s = steps.add_parser(name, help=text, description=text)
        s.add_argument("input", type=Path)
        if name != "info":
            s.add_argument("output", type=Path)
        s.add_argument("--spacing", type=float, nargs="+", metavar="M",
                       help="pixel pitch [m] for files that do not store it")
        s.add_argument("--unit", default="m", help="unit of plain ASCII/.npy files")
        _step_options(name, s)
        s.set_defaults(func=_topography)


def _add_contact(sub):
    """contact level|average: dry contact of pins."""
    c = sub.add_parser("contact", help="dry contact: pin levelling by torque balance, set averaging")
    cs = c.add_subparsers(dest="step", required=True, metavar="STEP")
    lv = cs.add_parser("level", help="tilt a mounted pin until the 50 N contact torques vanish")
    lv.add_argument("pin", type=Path, help="mounted pin (fem-twin topography prepare-pin)")
    lv.add_argument("output", type=Path)
    lv.add_argument("--disk", type=Path, help="flipped disk on the same grid (default: flat)")
    lv.add_argument("--load", type=float, default=50.0, help="imposed load [N]")
    lv.add_argument("--method", choices=("broyden", "pid"), default="broyden")
    lv.set_defaults(func=_contact_level)
    av = cs.add_parser("average", help="set average of levelled pins, then level it again")
    av.add_argument("pins", type=Path, nargs="+")
    av.add_argument("-o", "--output", type=Path, required=True)
    av.set_defaults(func=_contact_average)


def _add_homogenise(sub):
    """homogenise run|average: the micro scale."""
    h = sub.add_parser("homogenise", help="micro scale: flow factors of roughness patch pairs "
                                          "versus h0 (eqs 8-16)")
    hs = h.add_subparsers(dest="step", required=True, metavar="STEP")
    hr = hs.add_parser("run", help="flow factors of one pin/disk patch pair (checkpointed)")
    hr.add_argument("pin", type=Path, help="pin patch (fem-twin topography prepare-patch)")
    hr.add_argument("disk", type=Path, help="disk patch flipped over the pin (--upper)")
    hr.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    hr.add_argument("--h0", type=float, nargs=3, default=(1e-7, 1e-6, 100),
                    metavar=("MIN", "MAX", "N"), help="geometric h0 range [m] and count "
                    "(default: 1e-7 1e-6 100, the paper's)")
    hr.add_argument("--steps", type=int, default=32, help="time steps N_t of one sliding pass")
    hr.add_argument("--method", choices=("fe", "fvm"), default="fe",
                    help="Q1 finite elements or the paper's finite volumes")
    hr.add_argument("--time-derivative", choices=("exact", "backward"), default="exact",
                    help="squeeze term of eq 8: exact at every instant or the "
                         "paper's backward difference")
    hr.add_argument("--time-tol", type=float,
                    help="adaptive instants: add midpoints at an h0 while A11 or b1 change by "
                         "more than this fraction (exact scheme)")
    hr.add_argument("--h0-tol", type=float,
                    help="adaptive h0: solve only the subset of the N values the log-h0 "
                         "interpolant needs to miss the others by less than this fraction "
                         "(e.g. 0.005; default: every value)")
    hr.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                    help="processes over h0 values (default: all cores)")
    hr.add_argument("--fields", type=float, nargs="*", default=(), metavar="H0",
                    help="also write the cell fields (VTU/PVD) at these h0 [m]")
    hr.add_argument("--no-progress", action="store_true", help="no progress bar")
    hr.set_defaults(func=_homogenise_run)
    ha = hs.add_parser("average", help="average flow factors over patches (same h0 range)")
    ha.add_argument("inputs", type=Path, nargs="+", help="flow_factors.npz files")
    ha.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    ha.set_defaults(func=_homogenise_average)


def _add_macro(sub):
    """macro point: one operating point."""
    mc = sub.add_parser("macro", help="macro scale: one operating point of the homogenised "
                                      "mixed-EHL solver (eqs 17-34)")
    ms = mc.add_subparsers(dest="step", required=True, metavar="STEP")
    mp = ms.add_parser("point", help="solve one operating point; write fields (npz, VTU) and "
                                     "a JSON summary")
    mp.add_argument("pin", type=Path, help="prepared macro pin (fem-twin topography prepare-pin)")
    mp.add_argument("factors", type=Path, help="flow_factors.npz (fem-twin homogenise)")
    mp.add_argument("--disk", type=Path, help="prepared, flipped disk on the pin's grid "
                                              "(default: flat)")
    mp.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    mp.add_argument("--speed", type=float, required=True, help="sliding speed U [m/s]")
    mp.add_argument("--viscosity", type=float, default=0.066, help="mu_0 [Pa s]")
    mp.add_argument("--load", type=float, default=150.0, help="imposed normal load [N]")
    mp.add_argument("--diameter", type=float, default=8e-3,
                    help="pin diameter D of the Hersey number, eq 46 [m]")
    mp.add_argument("--method", choices=("fe", "fvm"), default="fe")
    mp.add_argument("--coupling", choices=("auto", "anderson", "newton", "pid"),
                    default="auto", help="macro coupling: Anderson, with Newton for "
                    "elastically dominated contacts (auto), or one of them; pid is the paper's")
    mp.add_argument("--couette", choices=("central", "upwind"), default="central",
                    help="Couette flux of eq 17: second order (central) or the paper's "
                    "first-order upwind")
    mp.set_defaults(func=_macro_point)


def _add_utilities(sub):
    """mesh, example and sample."""
    m = sub.add_parser("mesh", help="topography -> structured FE mesh written as VTU for ParaView")
    m.add_argument("input", type=Path)
    m.add_argument("output", type=Path, help="VTU file")
    m.add_argument("--periodic", action="store_true", help="periodic mesh (roughness patch)")
    m.add_argument("--kind", choices=("quad", "tri"), default="quad")
    m.add_argument("--spacing", type=float, nargs="+", metavar="M")
    m.set_defaults(func=_mesh)

    ex = sub.add_parser("example", help="write the bundled example case and its sample twin "
                                         "into a folder (works without the repository)")
    ex.add_argument("folder", type=Path, help="where to write pin_on_disk.toml and meshes/")
    ex.set_defaults(func=_example)
    g = sub.add_parser("sample", help="regenerate the bundled sample twin (seeded)")
    g.add_argument("-o", "--output", type=Path, default=Path("meshes/sample"))
    g.set_defaults(func=_sample)


def _case_command(sub, name, text, output, func):
    """A subcommand on a case file: ``CASE`` (default: the bundled case), ``-o``, progress."""
    c = sub.add_parser(name, help=text)
    c.add_argument("case", nargs="?", type=Path, default=DEFAULT_CASE,
                   help="case file")
    c.add_argument("-o", "--output", type=Path, default=Path(output), help="output folder")
    c.add_argument("--no-progress", action="store_true", help="no progress bars")
    c.set_defaults(func=func)
    return c


def _step_options(name, s):
    if name == "level":
        s.add_argument("--radius", type=float, help="fit only within this radius [m]")
        s.add_argument("--centre", type=float, nargs=2, default=(0.0, 0.0), metavar=("X1", "X2"))
    elif name == "clip":
        s.add_argument("--lower", type=float, default=-20e-6)
        s.add_argument("--upper", type=float, default=20e-6)
    elif name == "filter":
        s.add_argument("--fwhm", type=float, required=True, help="FWHM in pixels")
    elif name in ("resample", "patch", "prepare-patch"):
        s.add_argument("--shape", type=int, nargs=2, metavar=("NY", "NX"),
                       required=name == "resample", default=(256, 256))
        if name != "resample":
            s.add_argument("--start", type=int, nargs=2, default=(0, 0), metavar=("ROW", "COL"))
        s.add_argument("--method", choices=("linear", "cubic", "nearest"), default="linear")
        if name == "prepare-patch":
            s.add_argument("--upper", action="store_true", help="disk patch: flip above the pin")
    elif name == "refine":
        s.add_argument("--factor", type=int, required=True)
        s.add_argument("--method", choices=("linear", "cubic"), default="linear")
    elif name == "align":
        s.add_argument("--direction", choices=("+x1", "-x1", "+x2", "-x2"), required=True)
    elif name == "mount":
        s.add_argument("--truncation", type=float, default=-20e-6)
        s.add_argument("--holder", type=float, default=-1e-3)
    elif name in ("prepare-pin", "prepare-disk"):
        s.add_argument("--fwhm", type=float, default=9.0)
        s.add_argument("--resolution", type=int, nargs=2, default=(256, 256))
        s.add_argument("--clip", type=float, default=20e-6)


def _read(args):
    from .io.files import read_topography
    return read_topography(args.input, spacing=args.spacing, unit=args.unit)


def _topography(args):
    from . import topography as tp
    from .io.files import write_topography
    from .topography.prepare import MacroOptions, prepare_disk, prepare_patch, prepare_pin
    topo = _read(args)
    step = args.step
    if step == "info":
        ny, nx = topo.shape
        inval = 0 if topo.mask is None else int((~topo.mask).sum())
        print(json.dumps({"file": str(args.input), "pixels_x1_x2": [nx, ny],
                          "spacing_x1_x2_m": topo.spacing, "size_x1_x2_m": topo.size,
                          "sq_as_measured_m": topo.rms_height(),
                          "sq_levelled_m": tp.level(tp.fill_defects(topo)).rms_height(),
                          "invalid_pixels": inval, "meta": topo.meta}, indent=2, default=str))
        return 0
    if step == "convert":
        out = topo
    elif step == "fill":
        out = tp.fill_defects(topo)
    elif step == "level":
        mask = None if args.radius is None else tp.radial_mask(topo, args.radius, args.centre)
        out = tp.level(topo, mask)
    elif step == "clip":
        out = tp.clip_heights(topo, args.lower, args.upper)
    elif step == "filter":
        out = tp.gaussian_filter(topo, args.fwhm)
    elif step == "resample":
        out = tp.resample(topo, args.shape, args.method)
    elif step == "refine":
        out = tp.refine(topo, args.factor, args.method)
    elif step == "patch":
        out = tp.extract_patch(topo, args.shape, args.start)
    elif step == "align":
        out = tp.align_sliding(topo, args.direction)
    elif step == "flip":
        out = tp.flip_disk(topo)
    elif step == "mount":
        out = tp.mount_pin(topo, args.truncation, args.holder)
    elif step in ("prepare-pin", "prepare-disk"):
        opts = MacroOptions(fwhm_px=args.fwhm, resolution=tuple(args.resolution), clip=args.clip)
        out = (prepare_pin if step == "prepare-pin" else prepare_disk)(topo, opts)
    else:  # prepare-patch
        out = prepare_patch(topo, args.shape, args.start, upper=args.upper)
    write_topography(args.output, out)
    print(f"{args.output}: {out!r}")
    return 0


def _contact_level(args):
    from .contact.levelling import level_pin
    from .io.files import read_topography, write_topography
    pin = read_topography(args.pin)
    disk = read_topography(args.disk) if args.disk else None
    res = level_pin(pin, disk, load=args.load, method=args.method)
    write_topography(args.output, res.pin)
    print(json.dumps({"tilt_rad": res.tilt, "residuals": res.residuals,
                      "contact_solves": len(res.history),
                      "contact_fraction": res.contact.contact_fraction}, indent=2))
    return 0


def _contact_average(args):
    from .contact.levelling import average_pins, level_pin
    from .io.files import read_topography, write_topography
    res = level_pin(average_pins([read_topography(p) for p in args.pins]))
    write_topography(args.output, res.pin)
    print(json.dumps({"pins": len(args.pins), "tilt_rad": res.tilt,
                      "residuals": res.residuals}, indent=2))
    return 0


def _homogenise_run(args):
    import numpy as np

    from .io.files import read_topography
    from .micro import homogenise
    from .micro.output import write_cell_fields
    pin, disk = read_topography(args.pin), read_topography(args.disk)
    lo, hi, n = args.h0
    if int(n) != n or n < 1:
        raise InputError(f"the number of h0 values must be a positive integer, got {n}")
    ff = homogenise(pin, disk, np.geomspace(lo, hi, int(n)), n_steps=args.steps,
                    method=args.method, time_derivative=args.time_derivative,
                    time_tol=args.time_tol, h0_tol=args.h0_tol, workers=args.workers,
                    checkpoint=args.output / "checkpoints", progress=not args.no_progress,
                    patch_id=f"{args.pin.stem}/{args.disk.stem}")
    _write_factors(args.output, ff)
    for h0 in args.fields:
        print(write_cell_fields(args.output / "fields", pin, disk, h0, n_steps=args.steps,
                                method=args.method, time_derivative=args.time_derivative))
    return 0


def _homogenise_average(args):
    from .micro import FlowFactors, average
    factors = [FlowFactors.load(p) for p in args.inputs]
    _write_factors(args.output, average(factors), factors)
    return 0


def _write_factors(folder, ff, patches=()):
    from .micro.output import plot_flow_factors
    out = RunLayout(folder)                  # the files of a run's flow factors, in folder
    ff.save(folder / out.flow_factors.name)
    ff.write_csv(out.flow_factors_csv)
    labels = [f.meta.get("patch_id") or f"patch {i + 1}" for i, f in enumerate(patches)]
    plot_flow_factors([*patches, ff], out.flow_factors_png,
                      labels=[*labels, "average" if patches else ff.meta.get("patch_id") or "patch"])
    print(json.dumps({"h0_um": [ff.h0[0] * 1e6, ff.h0[-1] * 1e6], "points": len(ff),
                      "p_con_max_MPa": float(ff.p_con.max() * 1e-6),
                      "A11_range": [float(ff.A[:, 0, 0].min()), float(ff.A[:, 0, 0].max())],
                      "estimated_relative_error": {
                          kind: {q: round(e, 5) for q, e in errors.items()}
                          for kind, errors in ff.meta.get("error_estimate", {}).items()
                          if kind in ("time", "grid", "h0")},
                      "files": [str(folder / out.flow_factors.name), str(out.flow_factors_csv),
                                str(out.flow_factors_png)]}, indent=2))


def _macro_point(args):
    from .io.atomic import atomic_path
    from .io.files import read_topography
    from .macro import Lubricant, MacroSettings, solve_mixed
    from .micro import FlowFactors
    pin = read_topography(args.pin)
    upper = read_topography(args.disk).heights if args.disk else 0.0 * pin.heights
    if np.shape(upper) != pin.shape:
        raise InputError(f"disk grid {np.shape(upper)} does not match the pin grid {pin.shape}")
    face = pin.heights > -0.5e-3                 # the holder sits 1 mm below the face
    res = solve_mixed(upper - pin.heights, pin.spacing, FlowFactors.load(args.factors),
                      load=args.load, speed=args.speed, lubricant=Lubricant(args.viscosity),
                      face=face, settings=MacroSettings(method=args.method,
                                                        coupling=args.coupling,
                                                        couette=args.couette))
    args.output.mkdir(parents=True, exist_ok=True)
    res.save(args.output / "point.npz")
    res.write_vtu(args.output / "point.vtu", origin=pin.origin)
    summary = {k: v for k, v in res.scalars().items()}
    summary["hersey"] = args.viscosity * args.speed * args.diameter / args.load   # eq 46
    summary["seconds"] = res.meta["seconds"]
    with atomic_path(args.output / "point.json") as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    print(json.dumps(summary, indent=2))
    return 0


def _mesh(args):
    from .io.files import read_topography
    from .io.mesh import grid_mesh, write_vtu
    topo = read_topography(args.input, spacing=args.spacing)
    gm = grid_mesh(topo.shape, topo.spacing, topo.origin, periodic=args.periodic, kind=args.kind)
    fields = {"height": topo.heights, "valid": topo.valid.astype(float)}
    write_vtu(args.output, gm, fields)
    print(f"{args.output}: {gm.mesh.nvertices} nodes, {gm.mesh.nelements} {args.kind} elements")
    return 0


def _sample(args):
    from . import samples
    for path in samples.generate(args.output):
        print(path)
    return 0


#: runs estimated longer than this ask for --yes (the bundled case: about 1 minute)
LONG_RUN_SECONDS = 10 * 60


def _confirm_cost(case, yes: bool) -> bool:
    """Say which sections take defaults and what the run will cost; refuse a long run
    without ``--yes``."""
    if case.defaulted:
        print(f"fem-twin run: sections not in {case.source.name}, defaults used: " + ", ".join(
            f"[{s}]" for s in case.defaulted), file=sys.stderr)
    cores = case.run.workers or os.cpu_count() or 1
    seconds = case.estimated_seconds(cores)
    mc = case.micro
    print(f"fem-twin run: {len(case.geometry.patches)} patch pairs at {mc.resolution[0]}x"
          f"{mc.resolution[1]}, {mc.h0_count} h0 x {mc.steps} steps"
          f"{f' (adaptive h0, tolerance {mc.h0_tol:g})' if mc.h0_tol else ''}; "
          f"{len(case.lubricant.viscosities)} x {case.sweep.count} speeds; estimated "
          f"{seconds / 60:.0f} min on {cores} cores", file=sys.stderr)
    if seconds > LONG_RUN_SECONDS and not yes:
        print(f"fem-twin run: error: this run is estimated at {seconds / 60:.0f} min (the "
              "bundled case: about 1 min); check the case and run again with --yes",
              file=sys.stderr)
        return False
    return True


def _run(args):
    from .case import load_case
    from .pipeline import run
    if not args.case.is_file():
        raise MissingFile(f"case file not found: {args.case} (give the case file as "
                                "the first argument)")
    case = load_case(args.case)
    if not _confirm_cost(case, args.yes):
        return 2
    summary = run(case, args.output, progress=not args.no_progress)
    print(_short_summary(summary, args.output))
    return 0


def _short_summary(summary: dict, out: Path) -> str:
    """A few lines for the terminal; everything is in ``OUT/summary.json``."""
    stages = summary["stages"]
    lines = [f"fem-twin run: {summary['case']} done in {summary['wall_time_s']:.0f} s ("
             + ", ".join(f"{k} {v:.0f} s" for k, v in summary["seconds"].items()) + ")"]
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
    if err:
        lines.append(f"  C_f estimated discretisation error: at most "
                     f"{err['max_relative']:.2%} of C_f,b (" + ", ".join(
                         f"{k} {v:.2%}" for k, v in err["parts_max_relative"].items())
                     + f"; tolerance {err['tolerance']:.2%}; flow-factor estimates in "
                     "summary.json)")
    lines.append(f"results in {out}/ (stribeck.csv, plots, results.nc and fields.nc for "
                 f"fem_twin.results.open_run, fields/ for ParaView, summary.json, run.log); "
                 f"the figures on one page: fem-twin report {out}")
    return "\n".join(lines)


def _fit(args):
    from .case import load_case
    from .fitting import fit_case
    if not args.case.is_file():
        raise MissingFile(f"case file not found: {args.case}")
    case = load_case(args.case)
    if not _confirm_cost(case, args.yes):
        return 2
    result = fit_case(case, args.measured, args.output,
                      [p.strip() for p in args.params.split(",") if p.strip()],
                      predict_at=args.predict, progress=not args.no_progress)
    for name in result["fit"]["parameters"] + [k for k in result if k.startswith("viscosity_")]:
        v = result[name]
        print(f"fem-twin fit: {name} = {v['value']:.5g} (95 %: {v['low']:.5g} to "
              f"{v['high']:.5g})")
    print(f"  rms C_f,dev {result['fit']['rms_cf_dev']:.2%} over {result['fit']['points']} "
          f"points; {RunLayout(args.output).fit} and fit.png")
    return 0


def _calibrate(args):
    from .calibration import calibrate
    from .case import load_case
    summary = calibrate(load_case(args.case), args.study, args.output, values=args.values,
                        progress=not args.no_progress)
    print(json.dumps(summary, indent=2))
    return 0


def _html_report(args):
    from .report import write_report
    path = write_report(args.run, args.output, render=not args.no_3d)
    print(f"report: {path}")
    return 0


def _validate(args):
    from dataclasses import replace

    from .case import load_case
    from .macro.friction import BOUNDARY_FRICTION
    from .stribeck import deviation_from_measured, plot_stribeck, read_measured_csv
    from .io.table import write_csv
    from .stribeck.curve import read_stribeck_csv
    run = RunLayout(args.run)
    csv_path = run.stribeck_csv
    if not csv_path.is_file():
        raise MissingFile(f"{csv_path} not found: give the output folder of fem-twin run")
    curves = read_stribeck_csv(csv_path)
    if args.viscosity is None:
        curve = curves[0]
    else:
        match = [c for c in curves if np.isclose(c.viscosity, args.viscosity, rtol=1e-6)]
        if not match:
            raise InputError(f"no curve at mu_0 = {args.viscosity} Pa s in {csv_path} (it has "
                             f"{[c.viscosity for c in curves]})")
        curve = match[0]
    case_file = _run_case_file(args.run)
    case = load_case(case_file) if case_file else None
    boundary = case.tribometer.boundary_friction if case else BOUNDARY_FRICTION
    measured = read_measured_csv(args.measured, unit="rpm" if args.rpm else "m/s")
    if args.rpm:
        radius = args.radius or (case.tribometer.sliding_radius if case else None)
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
                  boundary=boundary)
    write_csv(table, {"speed_m_s": measured.speed, "measured_cf": measured.friction_coefficient,
                      "cf_dev": dev})
    inside = np.isfinite(dev)
    print(f"fem-twin validate: mu_0 = {curve.viscosity:g} Pa s against {args.measured.name}: "
          f"max |C_f,dev| = {np.nanmax(np.abs(dev)):.2%} (eq 35, C_f,b = {boundary:.5g}) at "
          f"{inside.sum()} of {dev.size} measured speeds; {table}, {png.name}")
    return 0


def _run_case_file(run: Path):
    """The case file recorded in a run's summary.json, if it still exists."""
    try:
        path = Path(json.loads(RunLayout(run).summary.read_text())["provenance"]["case_file"])
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return path if path.is_file() else None


def _example(args):
    from importlib.resources import files

    from .samples import generate
    args.folder.mkdir(parents=True, exist_ok=True)
    case = args.folder / "pin_on_disk.toml"
    case.write_text(files("fem_twin.cases").joinpath("pin_on_disk.toml").read_text())
    generate(args.folder / "meshes" / "sample")
    print(f"wrote {case} and {args.folder / 'meshes' / 'sample'}/; run it with\n"
          f"  fem-twin run {case} -o {args.folder / 'out'}")
    return 0


def _compare(args):
    from .case import load_case
    from .compare import compare
    summary = compare(load_case(args.case), args.output, progress=not args.no_progress)
    print(json.dumps(summary, indent=2))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
