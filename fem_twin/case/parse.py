"""Case files (TOML): what to simulate, validated with clear errors.  SI units throughout."""

from __future__ import annotations

import os
import re
import tomllib
from itertools import pairwise
from pathlib import Path

from ..checks import arguments, memory_shortfall
from ..errors import InputError
from ..io.files import topography_shape
from ..macro.laws.boundary_friction import COMMON_KEYS, BoundaryLaw, thin_films_choice
from ..macro.laws.boundary_laws import LAWS
from ..macro.laws.friction import LAWS as FRICTION_LAWS
from ..macro.laws.thermal import ThermalSettings
from ..micro.sliding import whole_pixel_steps
from ..stribeck.curve import read_measured_csv
from ..stribeck.validation import check_like_with_like
from ..topography.prepare import MacroOptions
from .sections import (
    SECTIONS,
    Case,
    Geometry,
    LubricantSpec,
    MacroSpec,
    Materials,
    MicroSpec,
    RunSpec,
    SweepSpec,
    Tribometer,
)
from .table import CaseError, int_pair, only, read_table

#: local worker processes a case may ask for per core (``[run] workers``): more only add
#: memory and switching
WORKERS_PER_CORE = 4
#: the fewest pixels a side of the macro grid ([preprocessing] resolution): its error
#: estimate solves the grid coarsened by two
MACRO_SIDE = 16
#: the [micro] keys the statistical model (model = "average-flow") reads; the cell
#: problems' others are refused with it
STATISTICAL_KEYS = frozenset({"model", "resolution", "slide_to_roll"})


@arguments(path="path")
def load_case(path) -> Case:
    """Read and validate a TOML case file."""
    path = Path(path)
    if not path.is_file():
        raise CaseError(f"case file not found: {path}")
    raw = path.read_bytes()
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise CaseError(f"{path}: a UTF-16 text file (as some Windows editors save it); save "
                        "it as UTF-8 (in Notepad: Save as, Encoding UTF-8)")
    try:
        data = tomllib.loads(raw.decode("utf-8-sig"))                # a BOM is harmless
    except UnicodeDecodeError as err:
        raise CaseError(f"{path}: not UTF-8 text ({err.reason} at byte {err.start}); save it "
                        "as UTF-8") from err
    except tomllib.TOMLDecodeError as err:
        raise CaseError(f"{path}: not valid TOML: {err}") from err
    return parse_case(data, base=path.parent, source=path)


def parse_case(data: dict, base: Path = Path("."), source: Path | None = None) -> Case:
    """Validate a case given as a dict (as read from TOML); file paths relative to ``base``."""
    where = str(source or "case")
    only(data, {"name", "validation", *SECTIONS}, where)
    if "geometry" not in data:
        raise CaseError(f"{where}: missing [geometry] section")
    tribometer = _tribometer(data, where)
    geometry = _geometry(data, base, where, tribometer.ball)
    if geometry.ball is not None and "ball_radius" in data.get("tribometer", {}):
        raise CaseError(f"{where} [tribometer] ball_radius: the measured cap's fitted sphere "
                        "gives the radius ([geometry] ball); remove one of the two")
    preprocessing = _preprocessing(data, where)
    _maps(geometry, preprocessing.sliding_direction, where)
    lubricant = _lubricant(data, where)
    materials = read_table(data, "materials", Materials, where, positive=True)
    micro = _micro(data, where)
    macro = _macro(data, where, tribometer, geometry)
    sweep = _sweep(data, where)
    thermal = _thermal(data, where, lubricant)
    boundary = _boundary(data, where, lubricant, sweep, tribometer)
    _disk_axis(tribometer, materials, geometry, where)
    run = read_table(data, "run", RunSpec, where)
    if run.workers < 0:
        raise CaseError(f"{where} [run] workers: a number of processes >= 0 (0: all cores), "
                        f"got {run.workers}")
    if run.scheduler is not None and not (isinstance(run.scheduler, str) and (
            run.scheduler == "local" or re.fullmatch(r"([a-z]+://)?[\w.\-]+:\d+",
                                                     run.scheduler))):
        raise CaseError(f"{where} [run] scheduler: a Dask scheduler's address "
                        f'("tcp://10.0.0.1:8786") or "local", got {run.scheduler!r}')
    most = WORKERS_PER_CORE * (os.cpu_count() or 1)
    if run.workers > most and run.scheduler in (None, "local"):
        raise CaseError(f"{where} [run] workers = {run.workers}: at most {WORKERS_PER_CORE} "
                        f"processes per core on this machine ({most} on its "
                        f"{os.cpu_count() or 1} cores; 0: one per core)")
    if not 0 < run.band_tol < 1:
        raise CaseError(f"{where} [run] band_tol: a coupling tolerance in (0, 1), got "
                        f"{run.band_tol}")
    radius = preprocessing.level_radius
    if not tribometer.ball and radius is not None and not 0 < radius <= tribometer.pin_diameter:
        raise CaseError(f"{where} [preprocessing] level_radius = {radius}: the mean-plane radius "
                        f"in metres, at most the pin diameter {tribometer.pin_diameter:g} m "
                        "(3 mm is 3e-3)")
    if not geometry.patches:
        raise CaseError(f"{where} [geometry]: at least one roughness patch pair is required")
    measured = _measured(data.get("validation", {}), base, where, lubricant,
                         tribometer.load)
    defaulted = tuple(name for name in SECTIONS if name != "geometry" and name not in data)
    return Case(name=str(data.get("name", source.stem if source else "case")),
                geometry=geometry, preprocessing=preprocessing, tribometer=tribometer,
                lubricant=lubricant, materials=materials, micro=micro, macro=macro,
                thermal=thermal, boundary=boundary, sweep=sweep, run=run, measured=measured,
                source=source, defaulted=defaulted)


#: the keys each kind of tribometer has no use for (refused, not ignored): what they are,
#: and how to fix the case
UNUSED = {"pin-on-disk": {
    ("tribometer", key): "a ball-on-disk setting, unused in a pin case; remove it, or set "
                         'kind = "ball-on-disk"'
    for key in ("slide_to_roll", "ball_radius", "track_radius")} | {
    ("macro", "grid"): "a ball-on-disk setting, unused in a pin case; remove it, or set "
                       '[tribometer] kind = "ball-on-disk" (a pin\'s grid is [preprocessing] '
                       "resolution)",
    ("macro", "mesh"): "a ball-on-disk setting, unused in a pin case (a pin's face fills "
                       "its grid); remove it, or set [tribometer] kind = \"ball-on-disk\""},
    "ball-on-disk": {("tribometer", "sliding_radius"): "a pin's track, unused by a ball; a "
                                                       "ball's is track_radius"} | {
    key: "a pin's setting, unused by a ball (its macro gap is its sphere, on [macro] grid); "
         "remove it, or set [tribometer] kind = \"pin-on-disk\""
    for key in (("preprocessing", "resolution"), ("preprocessing", "level_radius"),
                ("tribometer", "pin_diameter"), ("macro", "pin"), ("geometry", "pins"))}}


def _tribometer(data, where) -> Tribometer:
    tribometer = read_table(data, "tribometer", Tribometer, where, positive=True)
    for (section, key), why in UNUSED[tribometer.kind].items():
        if key in data.get(section, {}):
            raise CaseError(f"{where} [{section}] {key}: {why}")
    if tribometer.ball and tribometer.load_share != 1.0:
        raise CaseError(f"{where} [tribometer] load_share: a ball carries the whole load "
                        "(load_share = 1); it is a pin face's share")
    return tribometer


def _disk_axis(tribometer, materials, geometry, where) -> None:
    """Refuse a turning disk whose axis lies under the face: within a pin's radius, or
    within the half-width of a smooth ball's grid (three Hertz radii)."""
    radius = tribometer.disk_radius
    if radius is None or (tribometer.ball and geometry.ball is not None):
        return
    if tribometer.ball:
        hertz = (3 * tribometer.load * tribometer.ball_radius / (2 * materials.e_reduced)
                 ) ** (1 / 3)
        reach, key, what = 3 * hertz, "track_radius", "the ball's grid (3 Hertz radii)"
    else:
        reach, key, what = tribometer.pin_diameter / 2, "sliding_radius", "the pin's face"
    if radius <= reach:
        raise CaseError(f"{where} [tribometer] {key} = {radius:g} m: the disk's axis would lie "
                        f"under {what}, {reach:g} m from its centre; the track's radius in "
                        "metres (30 mm is 30e-3)")


def _geometry(data, base, where, ball) -> Geometry:
    """[geometry]: the instrument files (resolved, existing) and the patch window."""
    g = data["geometry"]
    if isinstance(g, dict) and "ball" in g and not ball:
        raise CaseError(f"{where} [geometry] ball: a measured ball cap needs [tribometer] "
                        "kind = \"ball-on-disk\"")
    if isinstance(g, dict) and not ball and not g.get("pins"):
        raise CaseError(f"{where} [geometry]: at least one pin file is required in 'pins'")
    geometry = read_table(data, "geometry", Geometry, where, files=_files(base, where))
    int_pair(list(geometry.patch_shape), f"{where} [geometry] patch_shape")
    int_pair(list(geometry.patch_start), f"{where} [geometry] patch_start", 0)
    if geometry.disks and len(geometry.disks) != len(geometry.pins):
        raise CaseError(f"{where} [geometry]: {len(geometry.pins)} pins but "
                        f"{len(geometry.disks)} disks (give one disk per pin, or none for flat)")
    return geometry


def _maps(geometry: Geometry, direction: str, where: str) -> None:
    """Refuse a map of [geometry] that does not open as a topography, and a patch window
    (patch_shape at patch_start, in the frame turned to ``direction``) that does not fit
    a patch file: before any work (:func:`~fem_twin.io.files.topography_shape`)."""
    patches = {path for pair in geometry.patches for path in pair}
    for key, paths in (("pins", geometry.pins), ("disks", geometry.disks),
                       ("patches", sorted(patches)), ("ball", [geometry.ball] * bool(
                           geometry.ball))):
        for path in paths:
            try:
                shape = topography_shape(path)
            except InputError as err:
                raise CaseError(f"{where} [geometry] {key}: {err}") from None
            rows, cols = shape[::-1] if direction in ("+x2", "-x2") else shape
            (ny, nx), (r0, c0) = geometry.patch_shape, geometry.patch_start
            if key == "patches" and (r0 + ny > rows or c0 + nx > cols):
                raise CaseError(f"{where} [geometry] patch_shape = {[ny, nx]} at patch_start "
                                f"= {[r0, c0]}: does not fit {path.name}, {rows} x {cols} "
                                "pixels (along the sliding direction); cut a smaller patch")


def _files(base: Path, where: str):
    """The reader of ``[geometry]``'s file settings, by their declared unit ("file path",
    "file paths", "file path pairs"): paths relative to ``base`` resolved, each existing."""
    def one(key, value):
        if not isinstance(value, str):
            raise CaseError(f"{where} [geometry] {key}: expected a file path")
        path = (base / value).resolve()
        if not path.is_file():
            raise CaseError(f"{where} [geometry] {key}: file not found: {path}")
        return path

    def files(key, value, unit):
        if unit == "file path":
            return one(key, value)
        pairs = unit == "file path pairs"
        if not isinstance(value, list) or not all(
                isinstance(v, list) and len(v) == 2 if pairs else True for v in value):
            raise CaseError(f"{where} [geometry] {key}: expected a list of "
                            + ("[pin, disk] file pairs" if pairs else "file paths"))
        return tuple(tuple(one(key, v) for v in pair) if pairs else one(key, pair)
                     for pair in value)
    return files


def _preprocessing(data, where) -> MacroOptions:
    """[preprocessing]: the macro geometry's options, lengths in metres."""
    opts = read_table(data, "preprocessing", MacroOptions, where)
    rows, cols = int_pair(list(opts.resolution), f"{where} [preprocessing] resolution")
    if min(rows, cols) < MACRO_SIDE:
        raise CaseError(f"{where} [preprocessing] resolution: [rows, columns] of at least "
                        f"{MACRO_SIDE} pixels each (the error estimate solves the macro grid "
                        f"coarsened by two), got {[rows, cols]}")
    short = memory_shortfall(rows * cols, "macro")
    if short:
        raise CaseError(f"{where} [preprocessing] resolution: {short}")
    if opts.holder_height >= opts.truncation:
        raise CaseError(f"{where} [preprocessing] holder_height = {opts.holder_height:g} m: "
                        f"below the truncation height {opts.truncation:g} m (the holder "
                        "under the face: -1 mm is -1e-3)")
    if 0 < opts.fwhm_px < 1:
        raise CaseError(f"{where} [preprocessing] fwhm_px = {opts.fwhm_px}: the filter width "
                        "is in pixels (0: no filter, else at least 1; the paper's is 9)")
    return opts


def _lubricant(data, where) -> LubricantSpec:
    lubricant = read_table(data, "lubricant", LubricantSpec, where, positive=True,
                         zero_ok=("eyring_stress",))
    if not lubricant.viscosities:
        raise CaseError(f"{where} [lubricant] viscosities: give at least one mu_0 [Pa s]")
    if len(lubricant.temperatures) != len(lubricant.viscosities):
        raise CaseError(f"{where} [lubricant]: give one temperature per viscosity")
    return lubricant


def _micro(data, where) -> MicroSpec:
    if isinstance(data.get("micro"), dict) and "error_tolerance" in data["micro"]:
        raise CaseError(f"{where} [micro] error_tolerance: moved to [sweep] error_tolerance, "
                        "the estimated error of C_f as a fraction of C_f,b (e.g. 0.005); the "
                        "flow factors' own estimates are in summary.json")
    micro = read_table(data, "micro", MicroSpec, where)
    if not 0 <= micro.h0_tol < 1:
        raise CaseError(f"{where} [micro] h0_tol: 0 (every h0) or a fraction in (0, 1), "
                        "e.g. 0.005")
    if len(micro.resolution) != 2 or min(micro.resolution) < 8:
        raise CaseError(f"{where} [micro] resolution: [rows, columns] of at least 8 pixels each "
                        f"(the error estimate solves the cell coarsened by two), got "
                        f"{list(micro.resolution)}")
    short = memory_shortfall(micro.resolution[0] * micro.resolution[1], "cell")
    if short:
        raise CaseError(f"{where} [micro] resolution: {short}")
    if not (0 < micro.h0_min < micro.h0_max < 1e-3) or micro.h0_count < 2 or micro.steps < 1:
        raise CaseError(f"{where} [micro]: need 0 < h0_min < h0_max [m] (e.g. 1e-7, 1e-6), "
                        "h0_count >= 2 and steps >= 1")
    if micro.model != "average-flow":
        try:
            whole_pixel_steps(micro.resolution[1], micro.steps)
        except InputError as err:
            raise CaseError(f"{where} [micro] steps = {micro.steps}, resolution = "
                            f"{list(micro.resolution)}: {err}") from None
    if micro.boundary_film >= micro.h0_min:
        raise CaseError(f"{where} [micro] boundary_film = {micro.boundary_film:g} m is not "
                        f"below h0_min = {micro.h0_min:g} m: the boundary film must be thinner "
                        "than the smallest separation (10 nm is 10e-9)")
    unread = sorted(set(data.get("micro", {})) - STATISTICAL_KEYS)
    if micro.model == "average-flow" and unread:
        raise CaseError(f"{where} [micro] {', '.join(unread)}: the cell problems' setting(s), "
                        "unused by model = \"average-flow\" (its factors are closed forms of "
                        "the patches' statistics); remove them, or set model = \"cells\"")
    return micro


def _macro(data, where, tribometer, geometry) -> MacroSpec:
    macro = read_table(data, "macro", MacroSpec, where)       # MacroSettings' own rules too
    if not 9 <= macro.grid <= 1025:
        raise CaseError(f"{where} [macro] grid: nodes per side of the ball's grid, 9 to 1025 "
                        f"(e.g. 97), got {macro.grid}")
    if macro.mesh == "graded" and macro.grid % 2 == 0:
        raise CaseError(f"{where} [macro] grid = {macro.grid}: a graded mesh needs an odd "
                        "number of nodes (its error estimate's coarser mesh halves the grid), "
                        f"e.g. {macro.grid + 1}")
    if tribometer.reading == "torque" and not FRICTION_LAWS[macro.friction].drag:
        raise CaseError(f"{where} [tribometer] reading = \"torque\": the disk's drag is the "
                        "force law's; it needs [macro] friction = \"pin\"")
    if macro.pin != "average" and not tribometer.ball and not (isinstance(macro.pin, int)
                                       and 1 <= macro.pin <= len(geometry.pins)):
        raise CaseError(f"{where} [macro] pin: 'average' or a pin number 1..{len(geometry.pins)}")
    return macro


def _thermal(data, where, lubricant) -> ThermalSettings:
    """[thermal]: the flash model needs the oil's viscosity at two temperatures; the
    isothermal model (``"none"``) takes none of the model's keys."""
    thermal = read_table(data, "thermal", ThermalSettings, where)
    unused = sorted(set(data.get("thermal", {})) - {"model"})
    if thermal.model == "none" and unused:
        raise CaseError(f"{where} [thermal] {', '.join(unused)}: the thermal model's, unused "
                        "by model = \"none\" (isothermal at the oil's temperature); set "
                        "model = \"flash\" or remove them")
    if thermal.model != "none" and len(set(lubricant.temperatures)) < 2:
        raise CaseError(f"{where} [thermal] model = \"{thermal.model}\": the film's viscosity "
                        "at its temperature needs [lubricant] viscosities at two temperatures "
                        "(the Walther law); give them, or set [thermal] model = \"none\"")
    pairs = pairwise(sorted(zip(lubricant.temperatures, lubricant.viscosities)))
    if thermal.model != "none" and any(t1 > t0 and m1 >= m0 for (t0, m0), (t1, m1) in pairs):
        raise CaseError(f"{where} [lubricant]: an oil thins as it warms, but the viscosities "
                        f"{list(lubricant.viscosities)} Pa s do not fall as the temperatures "
                        f"{list(lubricant.temperatures)} C rise (swapped?); the thermal model's "
                        "Walther law needs them in order")
    return thermal


def _boundary(data, where, lubricant, sweep, tribometer) -> BoundaryLaw:
    """[boundary]: the keys of its law alone (:attr:`~BoundaryLaw.model`'s ``keys``), the
    values the law takes from elsewhere in the case (the shear law's alpha: ``[tribometer]
    boundary_friction``), the law's own rules at the case's oils (the shear law: some
    shear, a temperature term that leaves more than half of it at the hottest oil), a
    speed factor positive over the sweep's speeds."""
    table = data.get("boundary", {})
    if "thin_films" in table:                          # true/false of older case files
        table = {**table, "thin_films": thin_films_choice(table["thin_films"])}
    boundary = read_table({"boundary": table}, "boundary", BoundaryLaw, where)
    law = boundary.model
    given = set(data.get("boundary", {})) - set(COMMON_KEYS)
    unused = sorted(given - set(law.keys))
    if unused:
        owners = [other.name for other in LAWS.values() if set(unused) & set(other.keys)]
        whose = f"the {' or '.join(owners)} law's, " if owners else ""
        raise CaseError(f"{where} [boundary] {', '.join(unused)}: {whose}unused by law = "
                        f"\"{law.name}\" ({law.reads or 'its keys: ' + ', '.join(law.keys)}); "
                        + (f"set law = \"{owners[0]}\" or " if owners else "")
                        + "remove them")
    try:
        boundary = law.from_case(boundary, given, tribometer.boundary_friction)
        law.check_case(boundary, given, lubricant.temperatures)
        boundary.check_speeds(sweep.speed_min, sweep.speed_max)
    except InputError as err:
        raise CaseError(f"{where} {err}") from None
    return boundary


def _sweep(data, where) -> SweepSpec:
    sweep = read_table(data, "sweep", SweepSpec, where, positive=True, zero_ok=("refine",))
    if not 0 <= sweep.refine <= 4 or not 0 < sweep.refine_step < 1:
        raise CaseError(f"{where} [sweep]: refine is 0-4 passes, refine_step a fraction of "
                        "C_f,b in (0, 1)")
    if not 0 < sweep.error_tolerance <= 0.1:
        raise CaseError(f"{where} [sweep] error_tolerance: a fraction of C_f,b in (0, 0.1] "
                        f"(0.5 % is 0.005), got {sweep.error_tolerance}")
    if sweep.speed_min > sweep.speed_max or sweep.count < 1:
        raise CaseError(f"{where} [sweep]: need speed_min <= speed_max [m/s] and count >= 1")
    return sweep


def _measured(val, base, where, lubricant, load: float) -> tuple:
    """[validation] measured: one CSV file (or "") per viscosity, resolved, each read and
    refused when it names another load or oil than the case's (its curve's)."""
    only(val, {"measured"}, f"{where} [validation]")
    measured = val.get("measured", [])
    if (not isinstance(measured, list) or len(measured) > len(lubricant.viscosities)
            or not all(isinstance(m, str) for m in measured)):
        raise CaseError(f"{where} [validation] measured: a list of CSV files, one per viscosity "
                        "(\"\" for none)")
    measured = tuple((base / m).resolve() if m else None for m in measured)
    for m, mu in zip(measured, lubricant.viscosities):
        if m is not None and not m.is_file():
            raise CaseError(f"{where} [validation] measured: file not found: {m}")
        if m is not None:
            try:
                check_like_with_like(read_measured_csv(m), load, mu, str(m))
            except InputError as err:
                raise CaseError(f"{where} [validation] measured: {err}") from None
    return measured
