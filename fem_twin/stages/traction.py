"""The traction side of a ball-on-disk case (``fem-twin traction``): one warm-started sweep
over the slide-to-roll ratio per viscosity at one entrainment speed, written as
``traction.csv`` and ``traction.png`` (:mod:`fem_twin.stribeck.traction`)."""

from __future__ import annotations

import logging

from ..case import Case
from ..io.layout import RunLayout
from ..micro import FlowFactors
from ..stribeck.traction import plot_traction, traction_sweep, write_traction_csv
from ..numerics.threads import worker_heap
from .curves import curve_labels, macro_settings
from .geometry import face_load, macro_geometry
from .provenance import stage_keys

log = logging.getLogger("fem_twin")


def traction_curves(case: Case, out: RunLayout, entrainment: float, ratios,
                    executor=None, progress: bool = True) -> dict:
    """C_f versus SRR at ``entrainment`` [m/s] for every viscosity of the ball-on-disk
    ``case`` (its micro stage done in ``out``), in parallel on ``executor``; the stage's
    summary."""
    gap, spacing, face, _ = macro_geometry(case, out)
    common = dict(gap=gap, spacing=spacing, factors=FlowFactors.load(out.flow_factors),
                  slide_to_roll=ratios, entrainment=entrainment, load=face_load(case),
                  face=face, settings=macro_settings(case), checkpoint=out.traction_points,
                  factors_key=stage_keys(case)["micro"])
    tasks = [dict(common, lubricant=lub) for lub in case.lubricant.lubricants()]
    if executor is None or len(tasks) == 1:
        curves = [traction_sweep(**kw, progress=progress) for kw in tasks]
    else:
        curves = [f.result() for f in [executor.submit(_task, kw) for kw in tasks]]
    write_traction_csv(out.traction_csv, curves)
    plot_traction(curves, out.traction_png, curve_labels(case, curves))
    for c in curves:
        log.info("traction at u_m = %g m/s, mu_0 = %g Pa s: C_f %s at SRR %s", c.entrainment,
                 c.viscosity, c.friction_coefficient.round(5).tolist(),
                 c.slide_to_roll.tolist())
    return {"entrainment_m_s": entrainment, "slide_to_roll": list(curves[0].slide_to_roll),
            "max_cf_err": float(max(c.friction_error.max() for c in curves)),
            "files": [str(out.traction_csv), str(out.traction_png)]}


def _task(kwargs):
    """One viscosity's traction sweep (a picklable unit of work for pools and Dask)."""
    worker_heap()
    return traction_sweep(**kwargs)
