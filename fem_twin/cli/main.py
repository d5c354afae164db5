"""Command line: ``fem-twin STAGE ...``, one subcommand per pipeline stage."""

from __future__ import annotations

import argparse
import inspect
import logging
import os
import re
from pathlib import Path

from .. import tables as T
from ..case.sections import Geometry, LubricantSpec, MicroSpec, Tribometer
from ..contact.levelling import level_pin
from ..numerics.threads import quiet_resource_tracker
from ..stribeck.fit import PARAMETERS
from ..stribeck.plateau import PLATEAU_SHARE
from ..topography.prepare import MacroOptions
from . import runs, steps
from .exits import interrupted, report

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
    quiet_resource_tracker()
    try:
        return args.func(args) or 0
    except KeyboardInterrupt:
        return interrupted(args.command)
    except Exception as err:                   # one line for the user, traceback on request
        if args.debug:
            raise
        return report(args.command, err)


class _Formatter(argparse.HelpFormatter):
    """Help lines end with the option's default, unless it has none or the text says it."""

    def _get_help_string(self, action):
        text = action.help or ""
        if ("default" in text or action.required or action.default in (None, False, (), [])
                or action.default is argparse.SUPPRESS):
            return text
        return f"{text} (default: %(default)s)"


#: a negative number, also in exponent form (-2e-05), read as a value, not as an option
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


class _Parser(argparse.ArgumentParser):
    """Every (sub)command shows the defaults of its options in ``--help`` and reads a
    negative number in exponent form as a value (argparse's own pattern has no exponent)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", _Formatter)
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER


def build_parser() -> argparse.ArgumentParser:
    from .. import __version__
    p = _Parser(
        prog="fem-twin",
        description="Digital twin of a pin-on-disk tribometer in mixed lubrication. "
                    "Stages: topography -> contact -> homogenise -> macro; 'run' executes "
                    "the whole pipeline of a case file (up to the Stribeck curve). Exit "
                    "codes: docs/troubleshooting.md.")
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
                                   "folder", "out", runs.run)
    rn.add_argument("--yes", action="store_true",
                    help=f"start even if estimated at more than {runs.LONG_RUN_RATIO:.0f}x "
                    "the bundled case")
    rn.add_argument("--from-fit", type=Path, metavar="FIT",
                    help="run with the parameters of a fit.json (fem-twin fit) and write "
                         "OUT/prediction.csv, each curve with its 95 %% band")
    tr = _case_command(sub, "traction", "traction curve of a ball-on-disk case (an MTM): C_f "
                                        "versus the slide-to-roll ratio at one entrainment "
                                        "speed, per viscosity", "out", runs.traction)
    tr.add_argument("--speed", type=float, required=True, metavar="U_M",
                    help="entrainment speed u_m [m/s]")
    tr.add_argument("--srr", type=float, nargs="+", metavar="SRR",
                    help="slide-to-roll ratios u_r / u_m in [0, 2] (default: 0 0.01 0.02 "
                         "0.05 0.1 0.2 0.3 0.5 0.7 1)")
    _case_command(sub, "compare", "cross-check FE against the FVM reference on a case: "
                                  "flow factors, fields, C_f,dev (eq 35)", "compare", runs.compare)
    cb = _case_command(sub, "calibrate", "calibration study of a case (paper 3.2): C_f,dev "
                                         "of variants against a reference curve",
                       "calibration", runs.calibrate)
    ft = sub.add_parser("fit", help="fit C_f,b or the boundary shear law, the oil "
                                    "temperature, the load share and the rig's thermal "
                                    "resistance of a case to measured Stribeck curves (runs or "
                                    "resumes the case first)")
    ft.add_argument("case", type=Path, help="case file")
    ft.add_argument("measured", type=Path, nargs="+",
                    help="measured CSV per viscosity of the case (speed [m/s], "
                         "friction_coefficient, optional cf_min/cf_max; load_N and "
                         "viscosity_Pa_s: the test's own, the twin swept there)")
    ft.add_argument("-o", "--output", type=Path, default=Path("out"), help="output folder")
    ft.add_argument("--params", default="boundary_friction,temperature",
                    help="comma-separated case keys to fit: " + ", ".join(PARAMETERS))
    ft.add_argument("--predict", type=float, nargs="+", default=[], metavar="T",
                    help="oil temperatures [C] of predicted curves with their 95 %% band "
                         "(OUT/prediction_TC.csv)")
    ft.add_argument("--predict-load", type=float, nargs="+", default=[], metavar="L",
                    help="loads [N] of predicted curves, each case viscosity swept there, "
                         "with their 95 %% band (OUT/prediction_LN.csv)")
    ft.add_argument("--plateau", type=float, nargs="?", const=PLATEAU_SHARE, default=None,
                    metavar="SHARE", help="fit the boundary law to the points where the twin's "
                    f"asperities carry SHARE of the load (default {PLATEAU_SHARE:g}) and "
                    "predict the rest with nothing else fitted (Gelinck and Schipper)")
    ft.add_argument("--no-progress", action="store_true", help="no progress bars")
    ft.add_argument("--yes", action="store_true", help="start even if the run is long")
    ft.set_defaults(func=runs.fit)
    cb.add_argument("--study", required=True,
                    choices=("filter", "resolution", "disk", "pins", "patches"))
    cb.add_argument("--values", type=float, nargs="+",
                    help="filter FWHMs [px] or resolutions [px] (defaults: 0 3 5 7 9 11; "
                         "the paper's 128 256 500 999 1997, the grids finer than the "
                         "measured maps at 0.02-0.1 m/s only)")


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
    va.set_defaults(func=runs.validate)

    rp = sub.add_parser("report", help="one self-contained HTML page with the paper's figures "
                                       "of a finished run (3D geometry, levelled pins, flow "
                                       "factors, Stribeck curves with the patch band, "
                                       "errors, settings, timings)")
    rp.add_argument("run", type=Path, help="output folder of fem-twin run")
    rp.add_argument("-o", "--output", type=Path, help="HTML file (default: RUN/report.html)")
    rp.add_argument("--no-3d", action="store_true",
                    help="skip the pyvista 3D views (Figures 2 and 6)")
    rp.set_defaults(func=runs.html_report)


def _add_topography(sub):
    """topography STEP: one pre-processing step per subcommand."""
    t = sub.add_parser("topography", help="read and pre-process measured topographies")
    parsers = t.add_subparsers(dest="step", required=True, metavar="STEP")
    for name, text in _STEPS.items():
        s = parsers.add_parser(name, help=text, description=text)
        s.add_argument("input", type=Path)
        if name != "info":
            s.add_argument("output", type=Path)
        s.add_argument("--spacing", type=float, nargs="+", metavar="M",
                       help="pixel pitch [m] for files that do not store it")
        s.add_argument("--unit", default="m", help="unit of plain ASCII/.npy files")
        _step_options(name, s)
        s.set_defaults(func=steps.topography)


def _add_contact(sub):
    """contact level|average: dry contact of pins."""
    c = sub.add_parser("contact",
                       help="dry contact: pin levelling by torque balance, set averaging")
    cs = c.add_subparsers(dest="step", required=True, metavar="STEP")
    lv = cs.add_parser("level", help="tilt a mounted pin until the contact torques vanish "
                       f"(Table 4: at {T.LEVELLING_LOAD:g} N)")
    lv.add_argument("pin", type=Path, help="mounted pin (fem-twin topography prepare-pin)")
    lv.add_argument("output", type=Path)
    lv.add_argument("--disk", type=Path, help="flipped disk on the same grid (default: flat)")
    lv.add_argument("--load", type=float, default=T.LEVELLING_LOAD,
                    help="imposed load [N] (default: %(default)s)")
    lv.add_argument("--method", choices=("broyden", "pid"),
                    default=inspect.signature(level_pin).parameters["method"].default)
    lv.set_defaults(func=steps.contact_level)
    av = cs.add_parser("average", help="set average of levelled pins, then level it again")
    av.add_argument("pins", type=Path, nargs="+")
    av.add_argument("-o", "--output", type=Path, required=True)
    av.set_defaults(func=steps.contact_average)


def _add_homogenise(sub):
    """homogenise run|average: the micro scale."""
    h = sub.add_parser("homogenise", help="micro scale: flow factors of roughness patch pairs "
                                          "versus h0 (eqs 8-16)")
    hs = h.add_subparsers(dest="step", required=True, metavar="STEP")
    hr = hs.add_parser("run", help="flow factors of one pin/disk patch pair (checkpointed)")
    hr.add_argument("pin", type=Path, help="pin patch (fem-twin topography prepare-patch)")
    hr.add_argument("disk", type=Path, help="disk patch flipped over the pin (--upper)")
    hr.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    micro = MicroSpec()                                   # [micro]: the paper's h0
    hr.add_argument("--h0", type=float, nargs=3,
                    default=(micro.h0_min, micro.h0_max, micro.h0_count),
                    metavar=("MIN", "MAX", "N"), help="geometric h0 range [m] and count "
                    "(default: %(default)s, the paper's)")
    from ..micro import CellSettings
    _settings_options(hr, CellSettings, steps.CELL_OPTIONS)
    hr.add_argument("--h0-tol", type=float,
                    help="adaptive h0: solve only the subset of the N values the log-h0 "
                         "interpolant needs to miss the others by less than this fraction "
                         "(e.g. 0.005; default: every value)")
    hr.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                    help="processes over h0 values (0: one per core; default: all cores)")
    hr.add_argument("--fields", type=float, nargs="*", default=(), metavar="H0",
                    help="also write the cell fields (VTU/PVD) at these h0 [m]")
    hr.add_argument("--no-progress", action="store_true", help="no progress bar")
    hr.set_defaults(func=steps.homogenise_run)
    ha = hs.add_parser("average", help="average flow factors over patches (same h0 range)")
    ha.add_argument("inputs", type=Path, nargs="+", help="flow_factors.npz files")
    ha.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    ha.set_defaults(func=steps.homogenise_average)


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
    tribometer = Tribometer()                             # [tribometer], [lubricant]
    mp.add_argument("--viscosity", type=float, default=LubricantSpec().viscosities[0],
                    help="mu_0 [Pa s] (default: %(default)s)")
    mp.add_argument("--load", type=float, default=tribometer.load,
                    help="imposed normal load [N] (default: %(default)s)")
    mp.add_argument("--diameter", type=float, default=tribometer.pin_diameter,
                    help="pin diameter D of the Hersey number, eq 46 [m] (default: "
                         "%(default)s)")
    from ..macro import MacroSettings
    _settings_options(mp, MacroSettings, steps.MACRO_OPTIONS)
    mp.set_defaults(func=steps.macro_point)


def _settings_options(parser, cls, names, flags=None) -> None:
    """An option per setting ``names`` of the dataclass ``cls``, with the default, choices,
    doc and unit of its one declaration (:func:`fem_twin.checks.setting`)."""
    from dataclasses import fields

    from ..checks import describe
    declared = {f.name: f for f in fields(cls)}
    for name in names:
        f, d = declared[name], describe(declared[name])
        unit = f" [{d['unit']}]" if d["unit"] and not d["choices"] else ""
        kw = dict(dest=name, default=f.default, help=(d["doc"] + unit).replace("%", "%%")
                  + " (default: %(default)s)")
        if d["choices"]:
            kw["choices"] = d["choices"]
        elif isinstance(f.default, tuple):
            kw.update(nargs=len(f.default), type=type(f.default[0]))
        else:
            kw["type"] = type(f.default) if f.default is not None else float
        parser.add_argument((flags or {}).get(name, "--" + name.replace("_", "-")), **kw)


def _add_utilities(sub):
    """mesh, example and sample."""
    m = sub.add_parser("mesh", help="topography -> structured FE mesh written as VTU for ParaView")
    m.add_argument("input", type=Path)
    m.add_argument("output", type=Path, help="VTU file")
    m.add_argument("--periodic", action="store_true", help="periodic mesh (roughness patch)")
    m.add_argument("--kind", choices=("quad", "tri"), default="quad")
    m.add_argument("--spacing", type=float, nargs="+", metavar="M")
    m.set_defaults(func=steps.mesh)

    ex = sub.add_parser("example", help="write the bundled example case and its sample twin "
                                         "into a folder (works without the repository)")
    ex.add_argument("folder", type=Path, help="where to write pin_on_disk.toml and meshes/")
    ex.set_defaults(func=runs.example)
    g = sub.add_parser("sample", help="regenerate the bundled sample twin (seeded)")
    g.add_argument("-o", "--output", type=Path, default=Path("meshes/sample"))
    g.set_defaults(func=steps.sample)


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
        clip = MacroOptions().clip                        # [preprocessing] clip
        s.add_argument("--lower", type=float, default=-clip, help="[m] (default: %(default)s)")
        s.add_argument("--upper", type=float, default=clip, help="[m] (default: %(default)s)")
    elif name == "filter":
        s.add_argument("--fwhm", type=float, required=True, help="FWHM in pixels")
    elif name in ("resample", "patch", "prepare-patch"):
        s.add_argument("--shape", type=int, nargs=2, metavar=("NY", "NX"),
                       required=name == "resample", default=Geometry().patch_shape)
        if name != "resample":
            s.add_argument("--start", type=int, nargs=2, default=Geometry().patch_start,
                           metavar=("ROW", "COL"))
        s.add_argument("--method", choices=("linear", "cubic", "nearest"), default="linear")
        if name == "prepare-patch":
            s.add_argument("--upper", action="store_true", help="disk patch: flip above the pin")
    elif name == "refine":
        s.add_argument("--factor", type=int, required=True)
        s.add_argument("--method", choices=("linear", "cubic"), default="linear")
    elif name == "align":
        s.add_argument("--direction", choices=("+x1", "-x1", "+x2", "-x2"), required=True)
    elif name == "mount":
        _settings_options(s, MacroOptions, ("truncation", "holder_height"),
                          {"holder_height": "--holder"})
    elif name in ("prepare-pin", "prepare-disk"):
        _settings_options(s, MacroOptions, ("fwhm_px", "resolution", "clip"),
                          {"fwhm_px": "--fwhm"})

