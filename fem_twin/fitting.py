"""``fem-twin fit``: the case's run (resumed when present), then its unknowns fitted to
measured curves (:mod:`fem_twin.stribeck.fit`); ``OUT/fit.json`` and ``OUT/fit.png``."""

from __future__ import annotations

import json
from pathlib import Path

from .case import Case
from .errors import InputError
from .io.atomic import atomic_path
from .io.layout import RunLayout
from .io.table import write_csv
from .macro.viscosity import WaltherLaw
from .stribeck import read_measured_csv
from .stribeck.curve import read_stribeck_csv
from .stribeck.fit import FitModel, check_parameters, fit_curves, plot_fit, predict


def fit_case(case: Case, measured, outdir, params, *, predict_at=(), progress: bool = True,
             run=None) -> dict:
    """Fit ``params`` (case-file keys, :data:`~fem_twin.stribeck.fit.PARAMETERS`) of
    ``case`` to the ``measured`` CSV files, the K-th against the case's K-th viscosity;
    ``predict_at``: oil temperatures [C] of predicted curves (``OUT/prediction_T.csv``,
    C_f with its 95 % band, :func:`~fem_twin.stribeck.fit.predict`).
    ``run``: the pipeline's ``run`` (runs or resumes the case into ``outdir``)."""
    params = list(params)
    check_parameters(params)                                      # before the run
    paths = [Path(p) for p in measured]
    curves_measured = [read_measured_csv(p) for p in paths]      # checked before any work
    lb = case.lubricant
    if not 1 <= len(paths) <= len(lb.viscosities):
        raise InputError(f"{len(paths)} measured curves for the case's {len(lb.viscosities)} "
                         "viscosities ([lubricant] viscosities): give one CSV per viscosity, "
                         "in their order")
    if (predict_at or "temperature" in params) and len(set(lb.temperatures)) < 2:
        raise InputError("fitting or predicting a temperature needs viscosities at two "
                         "temperatures in [lubricant] (the Walther law of ASTM D341)")
    law = (WaltherLaw.through(lb.temperatures, lb.viscosities, lb.density)
           if len(set(lb.temperatures)) > 1 else None)
    if run is None:
        from .pipeline import run
    run(case, outdir, progress=progress)
    out = RunLayout(outdir)
    simulated = read_stribeck_csv(out.stribeck_csv)[:len(paths)]
    model = FitModel(tuple(simulated), case.tribometer.boundary_friction, case.tribometer.load,
                     law)
    result = fit_curves(model, curves_measured, params,
                        start_temperatures=(list(lb.temperatures[:len(paths)])
                                            if "temperature" in params else None))
    result["measured"] = [str(p) for p in paths]
    with atomic_path(out.fit) as tmp:
        tmp.write_text(json.dumps(result, indent=2))
    plot_fit(result, out.fit_png, labels=[f"{t:g} C in the case" for t in lb.temperatures])
    speeds = simulated[0].speed
    for t in predict_at:
        p = predict(model, result, speeds, float(t), nominal=lb.temperatures[:len(paths)])
        write_csv(out.prediction(t), {"speed_m_s": p["speed_m_s"], "friction_coefficient":
                                      p["cf"], "cf_low": p["cf_low"], "cf_high": p["cf_high"],
                                      "cf_err": p["cf_err"]})
    return result
