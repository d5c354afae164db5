"""The macro side of the main job: the virtual geometry of every pin, disk and patch pair
(paper 2.2.1), the pin levelling by torque balance (eqs 1-7), and the macro gap the
Reynolds scale solves on (the levelled set average, or a ball's sphere)."""

from __future__ import annotations

import logging
from functools import lru_cache
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..case import Case
from ..contact.levelling import average_pins, level_pin, tilt_pin
from ..errors import InputError
from ..io.checkpoint import load_or_none
from ..io.files import read_topography, write_topography
from ..io.layout import RunLayout
from ..io.mesh import grid_mesh, write_vtu
from ..macro.reference.point_contact import PointContact
from ..numerics.threads import run_jobs
from ..topography.filling import fill_defects
from ..topography.geometry import pin_face
from ..topography.plausibility import check_patch, check_pin
from ..topography.prepare import flat_disk, prepare_disk, prepare_patch, prepare_pin
from ..topography.sphere import cap_gap, fit_sphere

log = logging.getLogger("fem_twin")


def reconstruct_geometry(case: Case, out: RunLayout, progress: bool = True,
                         executor=None) -> dict:
    """Prepare every pin (with its disk, or a flat one) and patch pair, one job each (on the
    workers of ``executor``: the bundled case's nine surfaces took 2.5 s in one process);
    write npz + VTU."""
    out.geometry.mkdir(parents=True, exist_ok=True)
    jobs = [] if case.tribometer.ball else [("pin", i) for i in range(len(case.geometry.pins))]
    jobs += [("patch", i) for i in range(len(case.geometry.patches))]
    result = {"pins": [], "patches": []}
    done = run_jobs(executor, _surface, [(case, out, kind, i) for kind, i in jobs])
    for (kind, _), (entry, warnings) in zip(jobs, tqdm(
            done, total=len(jobs), desc="geometry", disable=not progress, unit="surface")):
        for warning in warnings:
            log.warning("%s", warning)
        result[{"pin": "pins", "patch": "patches"}[kind]].append(entry)
    return result


def _surface(job) -> tuple[dict, list[str]]:
    """One job of :func:`reconstruct_geometry`, ``(case, out, kind, i)``: its summary entry
    and the warnings of its checks."""
    case, out, kind, i = job
    return _pin_geometry(case, out, i) if kind == "pin" else _patch_geometry(case, out, i)


def _pin_geometry(case: Case, out: RunLayout, i: int) -> tuple[dict, list[str]]:
    """Pin ``i`` and its disk (or a flat one) prepared for the macro scale."""
    opts = case.preprocessing
    pin_out, disk_out = out.pin(i + 1), out.disk(i + 1)
    if not all(load_or_none(f, read_topography) for f in (pin_out, disk_out)):
        raw = read_topography(case.geometry.pins[i])
        check_pin(raw, case.geometry.pins[i].name, case.tribometer.pin_diameter)
        pin = prepare_pin(raw, opts)
        disk = (prepare_disk(read_topography(case.geometry.disks[i]), opts)
                if case.geometry.disks else flat_disk(pin))
        if disk.shape != pin.shape:
            raise InputError(f"pin {i + 1} and its disk differ in resolution "
                             f"{pin.shape} vs {disk.shape}")
        write_vtu(out.macro_vtu(i + 1), grid_mesh(pin.shape, pin.spacing, pin.origin),
                  {"x3_low": pin.heights, "x3_up": disk.heights,
                   "pin_face": pin_face(pin, opts.holder_height).astype(float)})
        write_topography(disk_out, disk)
        write_topography(pin_out, pin)
    pin = read_topography(pin_out)
    face = pin_face(pin, opts.holder_height)
    return {"file": pin_out.name, "grid": list(pin.shape), "spacing_m": list(pin.spacing),
            "face_fraction": float(face.mean()),
            "face_range_m": [float(pin.heights[face].min()),
                             float(pin.heights[face].max())]}, []


def _patch_geometry(case: Case, out: RunLayout, i: int) -> tuple[dict, list[str]]:
    """Patch pair ``i`` cut and prepared for the micro scale."""
    low_out, up_out = out.patch(i + 1, "low"), out.patch(i + 1, "up")
    warnings = []
    if not all(load_or_none(f, read_topography) for f in (low_out, up_out)):
        src_pin, src_disk = case.geometry.patches[i]
        axis = case.preprocessing.sliding_direction
        low = prepare_patch(read_topography(src_pin), case.geometry.patch_shape,
                            case.geometry.patch_start, sliding_direction=axis)
        up = prepare_patch(read_topography(src_disk), case.geometry.patch_shape,
                           case.geometry.patch_start, upper=True, sliding_direction=axis)
        for t, src in ((low, src_pin), (up, src_disk)):
            warnings += check_patch(t, src.name, case.tribometer.pin_diameter)
        write_vtu(out.patch_vtu(i + 1), grid_mesh(low.shape, low.spacing, periodic=True),
                  {"x3_low": low.heights, "x3_up": up.heights})
        write_topography(up_out, up)
        write_topography(low_out, low)
    sq_low = read_topography(low_out).rms_height()
    sq_up = read_topography(up_out).rms_height()
    return {"files": [low_out.name, up_out.name], "sq_low_m": sq_low, "sq_up_m": sq_up,
            "sq_m": float(np.hypot(sq_low, sq_up))}, warnings


#: pins on finer grids are levelled on every k-th pixel, at most this many a side, and
#: tilted by the result (:func:`levelled_pin`): the tilt of sample pin 1 moves by under
#: 1 nm over the face from 500 to 999 px, where levelling every pixel takes about 11x the time
#: (docs/model.md, "Levelling fine grids on the measured points")
LEVELLING_GRID = 512


def level_pins(case: Case, out: RunLayout, progress: bool = True, executor=None) -> dict:
    """Level every pin against its disk (torque balance, Table 4 at 50 N), one job each (on
    the workers of ``executor``); average the levelled set and level the average (paper
    2.2.1).  Writes ``levelling/``."""
    if case.tribometer.ball:
        if case.geometry.ball is None:
            return {"skipped": "ball-on-disk: the macro gap is the ball's sphere"}
        cap, fit = measured_ball(case.geometry.ball)
        log.info("ball cap %s: R = %.6g m, apex at %s m, form error rms %.3g m",
                 case.geometry.ball.name, fit.radius, fit.apex, fit.form_error_rms)
        return {"ball": {"file": str(case.geometry.ball), "radius_m": fit.radius,
                         "apex_m": list(fit.apex), "form_error_rms_m": fit.form_error_rms,
                         "grid": list(cap.shape), "spacing_m": list(cap.spacing)}}
    out.levelling.mkdir(parents=True, exist_ok=True)
    n = len(case.geometry.pins)
    levelled = list(tqdm(run_jobs(executor, _levelled, [(case, out, i) for i in range(n)]),
                         total=n, desc="levelling", disable=not progress, unit="pin"))
    _averaged((case, out))
    return {"pins": [{"file": out.levelled_pin(i + 1).name,
                      "tilt_rad": pin.meta.get("tilt_rad")} for i, pin in enumerate(levelled)],
            "macro_pin": macro_pin_file(case, out).name}


def prepare_pins(runs, progress: bool = True, executor=None) -> None:
    """The pins of several runs ``[(case, out)]`` (the variants of a calibration study)
    prepared (:func:`reconstruct_geometry`, pins only) and levelled (:func:`level_pins`),
    each step one set of jobs over all runs on the workers of ``executor``, the finest
    grids first, so that no run's last pin keeps a worker idle (the variants' pins run
    beside the micro stage)."""
    runs = sorted((r for r in runs if not r[0].tribometer.ball),
                  key=lambda r: -np.prod(r[0].preprocessing.resolution or (0, 0)))
    for case, out in runs:
        out.geometry.mkdir(parents=True, exist_ok=True)
        out.levelling.mkdir(parents=True, exist_ok=True)
    pins = [(case, out, i) for case, out in runs for i in range(len(case.geometry.pins))]
    steps = (("geometry", _surface, [(case, out, "pin", i) for case, out, i in pins]),
             ("levelling", _levelled, pins), ("average pin", _averaged, runs))
    for desc, job, items in steps:
        for _ in tqdm(run_jobs(executor, job, items), total=len(items), desc=desc,
                      disable=not progress, unit="pin"):
            pass


def _averaged(job) -> None:
    """The levelled set average of ``(case, out)`` levelled against the first disk and
    written (when the set has more than one pin and the file is missing or unreadable)."""
    case, out = job
    n, path = len(case.geometry.pins), out.levelled_pin("average")
    if n < 2 or load_or_none(path, read_topography) is not None:
        return
    levelled = [read_topography(out.levelled_pin(i + 1)) for i in range(n)]
    g = case.preprocessing
    write_topography(path, levelled_pin(
        average_pins(levelled, radius=g.level_radius, truncation=g.truncation,
                     holder_height=g.holder_height), read_topography(out.disk(1)), case))


def _levelled(job):
    """Pin ``i`` of ``(case, out, i)`` levelled against its disk (read, or computed and
    written)."""
    case, out, i = job
    path = out.levelled_pin(i + 1)
    if load_or_none(path, read_topography) is None:
        write_topography(path, levelled_pin(read_topography(out.pin(i + 1)),
                                            read_topography(out.disk(i + 1)), case))
    return read_topography(path)


def levelled_pin(pin, disk, case: Case):
    """``pin`` levelled against ``disk`` by torque balance (the case's materials), its tilt
    and torque residuals in its meta.  A pin of more than ``LEVELLING_GRID`` pixels a side
    is levelled on every k-th pixel of it and of the disk (the fewest that fit; 999 and 1997
    px give back the measured 500 px points) and tilted by the result: kept points keep
    their coordinates, where a resampling would move them (nearest pixels, by up to half a
    pixel: 1.6e-6 rad) or smear the 1 mm step to the holder into a ramp (linear)."""
    holder = case.preprocessing.holder_height
    k = -(-max(pin.shape) // LEVELLING_GRID)
    lev = level_pin(_every(pin, k), _every(disk, k), e_reduced=case.materials.e_reduced,
                    hardness=case.materials.hardness, holder_height=holder)
    out = lev.pin if k == 1 else tilt_pin(pin, lev.tilt, holder)
    return out.with_heights(out.heights, meta={**out.meta, "tilt_rad": list(lev.tilt),
                                               "torque_residuals": list(lev.residuals)})


def _every(topo, k: int):
    """Every ``k``-th pixel of ``topo`` from the first, at their own coordinates."""
    if k == 1:
        return topo
    return topo.with_heights(topo.heights[::k, ::k], spacing=(k * topo.spacing[0],
                                                               k * topo.spacing[1]))


def macro_pin_number(case: Case) -> int | str:
    """The pin of the macro scale: ``"average"`` (the levelled set's average, when the set
    has more than one pin) or its number, counted from 1 (its disk serves the average)."""
    if case.macro.pin == "average":
        return "average" if len(case.geometry.pins) > 1 else 1
    return case.macro.pin


def macro_pin_file(case: Case, out: RunLayout) -> Path:
    """The levelled pin of the macro scale (:func:`macro_pin_number`)."""
    return out.levelled_pin(macro_pin_number(case))


def macro_geometry(case: Case, out: RunLayout):
    """Gap ``h_g = x3_up - x3_low``, spacing, pin-face mask and origin of the macro pin, or
    of the ball's sphere over [-4a, 2a] x [-3a, 3a] (a the Hertz radius; face: all)."""
    if case.tribometer.ball:
        gap, spacing, x1, x2 = ball_grid(case)
        if case.geometry.ball is not None:
            gap = cap_gap(*measured_ball(case.geometry.ball), x1, x2)
        return gap, spacing, np.ones(gap.shape, bool), (float(x1[0]), float(x2[0]))
    pin = read_topography(macro_pin_file(case, out))
    k = macro_pin_number(case)
    disk = read_topography(out.disk(1 if k == "average" else k))
    face = pin_face(pin, case.preprocessing.holder_height)
    return disk.heights - pin.heights, pin.spacing, face, pin.origin


def ball_grid(case: Case, contact: PointContact | None = None) -> tuple:
    """A ball's ``(gap, spacing, x1, x2)`` on its ``[macro] grid``, or on the mesh graded
    over it (``[macro] mesh``, :meth:`.PointContact.mesh`), of its ``contact`` (None: the
    case's, :func:`ball_contact`)."""
    contact = ball_contact(case) if contact is None else contact
    build = contact.mesh if case.macro.mesh == "graded" else contact.grid
    return build(case.macro.grid)


def ball_contact(case: Case) -> PointContact:
    """The smooth ball of a ball-on-disk case (Hertz radius, Hamrock-Dowson films) at the
    first viscosity and the sweep's fastest entrainment speed; of a measured cap's fitted
    radius when the case has one."""
    tr, lb = case.tribometer, case.lubricant
    radius = (tr.ball_radius if case.geometry.ball is None
              else measured_ball(case.geometry.ball)[1].radius)
    return PointContact(radius, tr.load, case.materials.e_reduced, lb.viscosities[0],
                        lb.roelands_alpha, case.sweep.speed_max)


@lru_cache(maxsize=4)
def measured_ball(path: Path):
    """``(cap, fit)``: a measured ball cap (defects filled) and its sphere
    (:func:`fem_twin.topography.sphere.fit_sphere`)."""
    cap = read_topography(path)
    if not np.all(np.isfinite(cap.heights)):
        cap = fill_defects(cap)
    return cap, fit_sphere(cap)


def hersey_length(case: Case) -> float:
    """D of the Hersey number (eq 46) [m]: the pin diameter, or a ball's Hertz diameter."""
    return (2 * ball_contact(case).hertz_radius if case.tribometer.ball
            else case.tribometer.pin_diameter)
