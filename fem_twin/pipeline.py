"""The main job: from a case file to results in an output folder.

Stages run so far: virtual geometry reconstruction (pins, disks, roughness patches).
Each stage writes its results atomically into the output folder; a stage whose outputs
exist is not recomputed when the job runs again.
"""

from __future__ import annotations

import json
import logging
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .case import Case
from .io.atomic import atomic_path
from .io.files import read_topography, write_topography
from .io.mesh import grid_mesh, write_vtu
from .topography.prepare import flat_disk, prepare_disk, prepare_patch, prepare_pin

log = logging.getLogger("fem_twin")


def run(case: Case, outdir, *, progress: bool = True) -> dict:
    """Run every stage of the pipeline that exists for ``case``; return the summary."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    summary = {"case": case.name, "stages": {}}
    summary["stages"]["geometry"] = reconstruct_geometry(case, outdir / "geometry", progress)
    summary["wall_time_s"] = time.perf_counter() - t0
    with atomic_path(outdir / "summary.json") as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    return summary


def reconstruct_geometry(case: Case, outdir: Path, progress: bool = True) -> dict:
    """Prepare every pin (with its disk, or a flat one) and patch pair; write npz + VTU."""
    opts = case.macro_geometry
    jobs = [("pin", i) for i in range(len(case.geometry.pins))]
    jobs += [("patch", i) for i in range(len(case.geometry.patches))]
    result = {"pins": [], "patches": []}
    for kind, i in tqdm(jobs, desc="geometry", disable=not progress, unit="surface"):
        if kind == "pin":
            pin_out, disk_out = outdir / f"pin_{i + 1}.npz", outdir / f"disk_{i + 1}.npz"
            if not (pin_out.exists() and disk_out.exists()):
                pin = prepare_pin(read_topography(case.geometry.pins[i]), opts)
                disk = (prepare_disk(read_topography(case.geometry.disks[i]), opts)
                        if case.geometry.disks else flat_disk(pin))
                if disk.shape != pin.shape:
                    raise ValueError(f"pin {i + 1} and its disk differ in resolution "
                                     f"{pin.shape} vs {disk.shape}")
                write_vtu(outdir / f"macro_{i + 1}.vtu",
                          grid_mesh(pin.shape, pin.spacing, pin.origin),
                          {"x3_low": pin.heights, "x3_up": disk.heights,
                           "pin_face": (pin.heights > opts.holder_height).astype(float)})
                write_topography(disk_out, disk)
                write_topography(pin_out, pin)
            pin = read_topography(pin_out)
            face = pin.heights > opts.holder_height
            result["pins"].append({"file": pin_out.name, "grid": list(pin.shape),
                                   "spacing_m": list(pin.spacing),
                                   "face_fraction": float(face.mean()),
                                   "face_range_m": [float(pin.heights[face].min()),
                                                    float(pin.heights[face].max())]})
        else:
            low_out, up_out = outdir / f"patch_{i + 1}_low.npz", outdir / f"patch_{i + 1}_up.npz"
            if not (low_out.exists() and up_out.exists()):
                src_pin, src_disk = case.geometry.patches[i]
                low = prepare_patch(read_topography(src_pin), case.geometry.patch_shape,
                                    case.geometry.patch_start)
                up = prepare_patch(read_topography(src_disk), case.geometry.patch_shape,
                                   case.geometry.patch_start, upper=True)
                write_vtu(outdir / f"patch_{i + 1}.vtu",
                          grid_mesh(low.shape, low.spacing, periodic=True),
                          {"x3_low": low.heights, "x3_up": up.heights})
                write_topography(up_out, up)
                write_topography(low_out, low)
            sq_low = read_topography(low_out).rms_height()
            sq_up = read_topography(up_out).rms_height()
            result["patches"].append({"files": [low_out.name, up_out.name], "sq_low_m": sq_low,
                                      "sq_up_m": sq_up, "sq_m": float(np.hypot(sq_low, sq_up))})
    return result
