"""The ``fem-twin`` commands of single stages (topography, contact, homogenise, macro, mesh,
sample); the parser is in :mod:`fem_twin.cli`."""

from __future__ import annotations

import json
import os

import numpy as np

from ..checks import number, plausible
from ..errors import InputError
from ..io.layout import RunLayout


def read_input(args):
    from ..io.files import read_topography
    return read_topography(args.input, spacing=args.spacing, unit=args.unit)


def topography(args):
    from .. import topography as tp
    from ..io.files import write_topography
    from ..topography.prepare import MacroOptions, prepare_disk, prepare_patch, prepare_pin
    topo = read_input(args)
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
        out = tp.mount_pin(topo, args.truncation, args.holder_height)
    elif step in ("prepare-pin", "prepare-disk"):
        opts = MacroOptions(fwhm_px=args.fwhm_px, resolution=tuple(args.resolution),
                            clip=args.clip)
        out = (prepare_pin if step == "prepare-pin" else prepare_disk)(topo, opts)
    else:  # prepare-patch
        out = prepare_patch(topo, args.shape, args.start, upper=args.upper)
    write_topography(args.output, out)
    print(f"{args.output}: {out!r}")
    return 0


def contact_level(args):
    from ..contact.levelling import level_pin
    from ..io.files import write_topography
    pin = _prepared(args.pin, "prepare-pin")
    disk = _prepared(args.disk, "prepare-disk") if args.disk else None
    res = level_pin(pin, disk, load=args.load, method=args.method)
    write_topography(args.output, res.pin)
    print(json.dumps({"tilt_rad": res.tilt, "residuals": res.residuals,
                      "contact_solves": len(res.history),
                      "contact_fraction": res.contact.contact_fraction}, indent=2))
    return 0


def _prepared(path, step: str):
    """The topography in ``path``, refused naming the file and the ``fem-twin topography
    STEP`` that prepares it where it holds invalid pixels (a raw map)."""
    from ..io.files import read_topography
    topo = read_topography(path)
    if not topo.valid.all() or not np.all(np.isfinite(topo.heights)):
        raise InputError(f"{path}: {int((~topo.valid).sum())} invalid pixels, a raw map; "
                         f"prepare it first: fem-twin topography {step} {path} PREPARED.npz")
    return topo


def contact_average(args):
    from ..contact.levelling import average_pins, level_pin
    from ..io.files import read_topography, write_topography
    res = level_pin(average_pins([read_topography(p) for p in args.pins]))
    write_topography(args.output, res.pin)
    print(json.dumps({"pins": len(args.pins), "tilt_rad": res.tilt,
                      "residuals": res.residuals}, indent=2))
    return 0


#: the cell settings ``homogenise run`` offers as options
CELL_OPTIONS = ("steps", "method", "time_derivative", "time_tol", "contact_tol", "rate_tol")
#: the macro settings ``macro point`` offers as options
MACRO_OPTIONS = ("method", "coupling", "couette", "complementarity", "inner_steps", "tol",
                 "max_iter")


def homogenise_run(args):
    from ..io.files import read_topography
    from ..micro import CellSettings, homogenise
    from ..micro.homogenisation import h0_candidates
    from ..micro.output import write_cell_fields
    lo, hi, n = args.h0
    plausible("--h0 MIN MAX [m]", [lo, hi], "separation")
    if int(n) != n or n < 1:
        raise InputError(f"the number of h0 values must be a positive integer, got {n}")
    workers = int(number("--workers", args.workers, "workers")) or os.cpu_count() or 1
    pin, disk = read_topography(args.pin), read_topography(args.disk)
    settings = CellSettings(**{k: getattr(args, k) for k in CELL_OPTIONS})
    ff = homogenise(pin, disk, h0_candidates(lo, hi, int(n)), settings=settings,
                    h0_tol=args.h0_tol, workers=workers,
                    checkpoint=args.output / "checkpoints", progress=not args.no_progress,
                    patch_id=f"{args.pin.stem}/{args.disk.stem}")
    _write_factors(args.output, ff)
    for h0 in args.fields:
        print(write_cell_fields(args.output / "fields", pin, disk, h0,
                                n_steps=settings.steps, method=settings.method,
                                time_derivative=settings.time_derivative))
    return 0


def homogenise_average(args):
    from ..micro import FlowFactors, average
    factors = [FlowFactors.load(p) for p in args.inputs]
    _write_factors(args.output, average(factors), factors)
    return 0


def _write_factors(folder, ff, patches=()):
    from ..micro.output import plot_flow_factors
    out = RunLayout(folder)                  # the files of a run's flow factors, in folder
    ff.save(folder / out.flow_factors.name)
    ff.write_csv(out.flow_factors_csv)
    labels = [f.meta.get("patch_id") or f"patch {i + 1}" for i, f in enumerate(patches)]
    plot_flow_factors([*patches, ff], out.flow_factors_png,
                      labels=[*labels, "average" if patches
                              else ff.meta.get("patch_id") or "patch"])
    print(json.dumps({"h0_um": [ff.h0[0] * 1e6, ff.h0[-1] * 1e6], "points": len(ff),
                      "p_con_max_MPa": float(ff.p_con.max() * 1e-6),
                      "A11_range": [float(ff.A[:, 0, 0].min()), float(ff.A[:, 0, 0].max())],
                      "estimated_relative_error": {
                          kind: {q: round(e, 5) for q, e in errors.items()}
                          for kind, errors in ff.meta.get("error_estimate", {}).items()
                          if kind in ("time", "grid", "h0")},
                      "files": [str(folder / out.flow_factors.name), str(out.flow_factors_csv),
                                str(out.flow_factors_png)]}, indent=2))


def macro_point(args):
    from ..io.atomic import atomic_path
    from ..io.files import read_topography
    from ..macro import Lubricant, MacroSettings, solve_mixed
    from ..micro import FlowFactors
    number("--diameter [m]", args.diameter, "pin_diameter")
    pin = read_topography(args.pin)
    upper = read_topography(args.disk).heights if args.disk else 0.0 * pin.heights
    if np.shape(upper) != pin.shape:
        raise InputError(f"disk grid {np.shape(upper)} does not match the pin grid {pin.shape}")
    face = pin.heights > -0.5e-3                 # the holder sits 1 mm below the face
    res = solve_mixed(upper - pin.heights, pin.spacing, FlowFactors.load(args.factors),
                      load=args.load, speed=args.speed, lubricant=Lubricant(args.viscosity),
                      face=face, settings=MacroSettings(
                          **{k: getattr(args, k) for k in MACRO_OPTIONS}))
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


def mesh(args):
    from ..io.files import read_topography
    from ..io.mesh import grid_mesh, write_vtu
    topo = read_topography(args.input, spacing=args.spacing)
    gm = grid_mesh(topo.shape, topo.spacing, topo.origin, periodic=args.periodic, kind=args.kind)
    fields = {"height": topo.heights, "valid": topo.valid.astype(float)}
    write_vtu(args.output, gm, fields)
    print(f"{args.output}: {gm.mesh.nvertices} nodes, {gm.mesh.nelements} {args.kind} elements")
    return 0


def sample(args):
    from ..io import samples
    for path in samples.generate(args.output):
        print(path)
    return 0

