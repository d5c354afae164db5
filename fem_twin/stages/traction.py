"""The traction side of a ball-on-disk case (``fem-twin traction``): one warm-started sweep
over the slide-to-roll ratio per viscosity at one entrainment speed, written as
``traction.csv`` and ``traction.png`` (:mod:`fem_twin.stribeck.traction`)."""

from __future__ import annotations

import logging

from ..case import Case
from ..io.layout import RunLayout
from ..numerics.threads import worker_heap
from ..stribeck.traction import plot_traction, traction_sweep, write_traction_csv
from .curves import curve_labels
from .requests import per_viscosity, sweep_request

log = logging.getLogger("fem_twin")


def traction_curves(case: Case, out: RunLayout, entrainment: float, ratios,
                    executor=None, progress: bool = True) -> dict:
    """C_f versus SRR at ``entrainment`` [m/s] for every viscosity of the ball-on-disk
    ``case`` (its micro stage done in ``out``), in parallel on ``executor``; the stage's
    summary."""
    # isothermal: a traction point's heat is not modelled ([thermal] is the Stribeck
    # curves'); its checkpoints in OUT/traction
    request = sweep_request(case, out, speeds=[entrainment], thermal=None,
                            checkpoint=out.traction_points)
    tasks = per_viscosity(case, request)
    if executor is None or len(tasks) == 1:
        curves = [traction_sweep(task, ratios, progress) for task in tasks]
    else:
        curves = [f.result() for f in [executor.submit(_task, (task, ratios))
                                       for task in tasks]]
    write_traction_csv(out.traction_csv, curves)
    plot_traction(curves, out.traction_png, curve_labels(case, curves))
    for c in curves:
        log.info("traction at u_m = %g m/s, mu_0 = %g Pa s: C_f %s at SRR %s", c.entrainment,
                 c.viscosity, c.friction_coefficient.round(5).tolist(),
                 c.slide_to_roll.tolist())
    return {"entrainment_m_s": entrainment, "slide_to_roll": list(curves[0].slide_to_roll),
            "max_cf_err": float(max(c.friction_error.max() for c in curves)),
            "files": [str(out.traction_csv), str(out.traction_png)]}


def _task(args):
    """One viscosity's traction sweep ``(request, ratios)`` (a picklable unit of work for
    pools and Dask)."""
    worker_heap()
    return traction_sweep(*args)
