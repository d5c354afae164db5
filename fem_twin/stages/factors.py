"""The roughness side of the main job: the flow factors of every patch pair (eqs 8-16),
checkpointed per h0, side by side on the shared pool, and their average."""

from __future__ import annotations

import logging
import os
from dataclasses import fields

import numpy as np
from tqdm import tqdm

from ..case import Case
from ..io.checkpoint import load_or_none
from ..io.files import read_topography
from ..io.layout import RunLayout
from ..io.writers import Writers
from ..micro import CellSettings, FlowFactors, average, homogenise
from ..micro.output import plot_flow_factors
from ..micro.store import prune_checkpoints
from ..numerics.threads import side_threads
from ..peers import average_flow_factors
from ..topography import resample_cell

log = logging.getLogger("fem_twin")


def homogenise_patches(case: Case, out: RunLayout, executor=None, progress: bool = True,
                       h0=None, writers: Writers | None = None):
    """Flow factors of every patch pair (checkpointed per h0) and their average (``h0``:
    the case's range unless given).  With an executor the patches run side by side (a
    thread each hands its h0 tasks to the shared pool), so the pool is not left idle at
    the end of a patch or of a round of adaptive h0, and a cluster gets every patch's
    tasks at once.  The figure is drawn on ``writers`` (the caller waits for it), else at
    once."""
    out.micro.mkdir(parents=True, exist_ok=True)
    mc = case.micro
    h0 = mc.h0_candidates() if h0 is None else np.asarray(h0)
    n = len(case.geometry.patches)
    bar = tqdm(total=n * len(h0), desc="flow factors", unit="h0", disable=not progress
               or os.environ.get("FEM_TWIN_NO_PROGRESS") == "1")
    try:
        if executor is None:
            factors = [_patch_factors(case, out, i, h0, None, bar) for i in range(n)]
        else:
            with side_threads() as threads:
                factors = list(threads.map(
                    lambda i: _patch_factors(case, out, i, h0, executor, bar), range(n)))
    finally:
        bar.close()
    mean = average(factors)
    mean.save(out.flow_factors)
    mean.write_csv(out.flow_factors_csv)
    (writers or Writers()).write(
        plot_flow_factors, [*factors, mean], out.flow_factors_png,
        labels=[f"patch {i + 1}" for i in range(len(factors))] + ["average"])
    estimate = mean.meta.get("error_estimate", {})
    return {"model": mc.model, "patches": len(factors),
            "h0_m": [float(h0[0]), float(h0[-1]), len(h0)],
            "h0_solved": [len(f) for f in factors], "h0_tol": mc.h0_tol,
            "grid": list(mc.resolution), "steps": mc.steps,
            "time_derivative": mc.time_derivative,
            "error_estimate": estimate,
            "p_con_max_Pa": float(mean.p_con.max()),
            "files": [out.flow_factors_csv.name, out.flow_factors_png.name]}


def _knows_thin(path) -> bool:
    """Whether the factors file at ``path`` holds the confined films' moments (a file of
    an earlier fem_twin does not, and reads them as none: its cells are recomputed where
    the case shears those films, ``[boundary] thin_films = "viscous"``)."""
    with np.load(path) as data:
        return "thin_area" in data


def _patch_factors(case: Case, out: RunLayout, i: int, h0, executor, bar) -> FlowFactors:
    """Flow factors of patch pair ``i`` (0-based): its file if present, else computed."""
    mc = case.micro
    path, checkpoints = out.patch_factors(i + 1), out.patch_checkpoints(i + 1)
    ff = load_or_none(path, FlowFactors.load)
    if ff is not None and (case.boundary.thin_films != "viscous" or _knows_thin(path)):
        bar.update(len(h0))
        return ff
    low = read_topography(out.patch(i + 1, "low"))
    up = read_topography(out.patch(i + 1, "up"))
    if low.shape != tuple(mc.resolution):
        low, up = resample_cell(low, mc.resolution), resample_cell(up, mc.resolution)
    if mc.model == "average-flow":
        settings = cell_settings(case)
        ff = average_flow_factors(low, up, settings.e_reduced,
                                  slide_to_roll=settings.slide_to_roll)
        bar.update(len(h0))
        ff.save(path)
        return ff
    ff = homogenise(low, up, h0, settings=cell_settings(case), h0_tol=mc.h0_tol,
                    friction=case.macro.friction,
                    executor=executor,
                    workers=getattr(executor, "n_workers", 1),
                    checkpoint=checkpoints, progress=bar,
                    patch_id=f"patch {i + 1}")
    ff.save(path)
    stale = prune_checkpoints(checkpoints, ff.meta["checkpoint_keys"])
    if stale:
        log.info("patch %d: %d stale h0 checkpoints removed", i + 1, stale)
    return ff


def cell_settings(case: Case) -> CellSettings:
    """The cell settings of a case: its ``[micro]`` settings, the materials' E' and hardness
    filled in (:meth:`~fem_twin.case.sections.Case.filled`)."""
    return case.filled(CellSettings(**{f.name: getattr(case.micro, f.name)
                                       for f in fields(CellSettings)}))
