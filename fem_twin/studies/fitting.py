"""``fem-twin fit``: the case's run (resumed when present), then its unknowns fitted to
measured curves (:mod:`fem_twin.stribeck.fit`), ``OUT/fit.json`` and ``OUT/fit.png``; and
``fem-twin run --from-fit``: a case run with the fitted parameters, ``OUT/prediction.csv``."""

from __future__ import annotations

import json
import logging
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..case import Case
from ..checks import QUANTITIES, arguments, plausible
from ..errors import InputError
from ..io.atomic import atomic_path
from ..io.layout import RunLayout
from ..io.table import write_csv
from ..macro.laws.boundary_laws import fitted_law
from ..macro.laws.viscosity import WaltherLaw
from ..numerics.threads import executor_for
from ..runtime.taskgraph import fit_scaling
from ..stages.requests import per_viscosity, sweep_request
from ..stages.sweeps import run_sweeps
from ..stribeck import read_measured_csv
from ..stribeck.curve import read_stribeck_csv
from ..stribeck.fit import (
    LOAD_SHARES,
    RESISTANCES,
    FitModel,
    check_loads,
    check_parameters,
    fit_curves,
)
from ..stribeck.plateau import check_plateau, fit_plateau, plot_plateau
from ..stribeck.prediction import plot_fit, predict
from .fit_file import check_fit, read_fit, temperature_offset

log = logging.getLogger("fem_twin")


def fit_case(case: Case, measured, outdir, params, *, predict_at=(), predict_loads=(),
             plateau: float | None = None, progress: bool = True, run=None) -> dict:
    """Fit ``params`` (case-file keys, :data:`~fem_twin.stribeck.fit.PARAMETERS`) of
    ``case`` to the ``measured`` CSV files: the K-th against the case's K-th viscosity at
    the case's load, or at the ``load_N`` and ``viscosity_Pa_s`` its file gives (the twin
    swept there, checkpointed in ``OUT/fit/``); ``predict_at``: oil temperatures [C] and
    ``predict_loads``: loads [N] of predicted curves (``OUT/prediction_TC.csv``,
    ``OUT/prediction_LN.csv``, C_f with its 95 % band,
    :func:`~fem_twin.stribeck.prediction.predict`); ``plateau``: the asperities' share of
    the load from which the points fit the boundary law and the rest are predicted
    (:mod:`fem_twin.stribeck.plateau`).  ``run``: the pipeline's ``run`` (runs
    or resumes the case into ``outdir``); a ``load_share`` fit then sweeps the first
    viscosity at :data:`LOAD_SHARES` (so a rerun resumes)."""
    params = list(params)
    paths, curves_measured, tests = check_fit_request(case, measured, params, predict_at,
                                                      predict_loads, plateau)
    lb = case.lubricant
    law = (WaltherLaw.through(lb.temperatures, lb.viscosities, lb.density)
           if len(set(lb.temperatures)) > 1 else None)
    if run is None:
        from ..stages.pipeline import run
    run(case, outdir, progress=progress)
    out = RunLayout(outdir)
    simulated = _simulated(case, out, tests, progress)
    shares, resistances = extra_curves(
        case, out, simulated, LOAD_SHARES if "load_share" in params else (),
        RESISTANCES if "bulk_resistance" in params else (), progress)
    model = FitModel(tuple(simulated), case.tribometer.boundary_friction, case.tribometer.load,
                     law, case.tribometer.load_share, shares, case.thermal.bulk_resistance,
                     resistances, case.boundary, loads=tuple(load for load, _ in tests))
    nominal = [lb.temperatures[k] if c.viscosity is None else
               None if law is None else float(law.temperature(c.viscosity))
               for k, c in enumerate(curves_measured)]
    if plateau is not None:
        result = fit_plateau(model, curves_measured, params, plateau)
    else:
        result = fit_curves(model, curves_measured, params, verbose=progress,
                            start_temperatures=nominal if "temperature" in params else None)
    result["measured"] = [str(p) for p in paths]
    if shares or resistances:
        result["task_graph"] = fit_scaling(case, outdir)
    result["case"] = {"temperatures": nominal, "load_N": case.tribometer.load,
                      "loads_N": [load for load, _ in tests], "kind": case.tribometer.kind,
                      "law": None if law is None else vars(law)}
    with atomic_path(out.fit) as tmp:
        tmp.write_text(json.dumps(result, indent=2))
    (plot_fit if plateau is None else plot_plateau)(
        result, out.fit_png, labels=[f"{mu:g} Pa s, {load:g} N" for load, mu in tests])
    for t in predict_at:
        _write_prediction(out.prediction(t), [predict(model, result, simulated[0].speed,
                                                      float(t), nominal=nominal)])
    for load in predict_loads:
        _predict_load(case, out, result, float(load), progress)
    return result


def _tests(case: Case, curves) -> list[tuple[float, float]]:
    """Each measured curve's ``(load [N], viscosity [Pa s])``: its file's, else the case's
    load and K-th viscosity."""
    mus = case.lubricant.viscosities
    out = []
    for k, c in enumerate(curves):
        if c.viscosity is None and k >= len(mus):
            raise InputError(f"measured curve {k + 1} of {len(curves)}: the case has "
                             f"{len(mus)} viscosities ([lubricant] viscosities); give one CSV "
                             "per viscosity, in their order, or a viscosity_Pa_s column")
        out.append((c.load or case.tribometer.load, c.viscosity or mus[k]))
    return out


def check_fit_request(case: Case, measured, params, predict_at=(), predict_loads=(),
                      plateau=None):
    """Read the ``measured`` CSVs and refuse whatever :func:`fit_case` cannot do with them,
    before any work (the CLI calls it before it measures the machine): ``(paths, measured
    curves, tests)``, the tests as ``(load [N], viscosity [Pa s])`` per curve."""
    paths = [Path(p) for p in measured]
    curves_measured = [read_measured_csv(p) for p in paths]
    tests = _tests(case, curves_measured)
    _check_request(case, list(params), paths, curves_measured, tests, predict_at,
                   predict_loads)
    if plateau is not None:
        check_plateau(list(params), plateau)
    return paths, curves_measured, tests


#: how far from the case's load [x] a fit's parameters are carried by ``--predict-load``
LOAD_REACH = 10.0


def _check_request(case: Case, params, paths, curves, tests, predict_at, predict_loads):
    """Everything a fit can be refused for, before the run."""
    check_parameters(params)
    check_loads(params, [load for load, _ in tests])
    lb, tr = case.lubricant, case.tribometer
    own = [(tr.load, mu) for mu in lb.viscosities]
    if any(t not in own for t in tests) and {"load_share", "bulk_resistance"} & set(params):
        raise InputError("load_share and bulk_resistance are fitted on the case's own load and "
                         "viscosities; leave out the load_N and viscosity_Pa_s columns")
    bad = [t for t in predict_at if not -30.0 <= float(t) <= 250.0]
    if bad:
        raise InputError(f"--predict {bad}: oil temperatures in C, from -30 to 250 (the range "
                         "of the fitted contact temperatures)")
    for load in predict_loads:
        plausible("--predict-load [N]", load, "load")
        if not tr.load / LOAD_REACH <= load <= tr.load * LOAD_REACH:
            raise InputError(f"--predict-load {load:g} N: more than {LOAD_REACH:g}x from the "
                             f"case's {tr.load:g} N the fitted parameters were measured at "
                             "(loads in N: 0.15 kN is 150)")
    if (predict_at or "temperature" in params) and len(set(lb.temperatures)) < 2:
        raise InputError("fitting or predicting a temperature needs viscosities at two "
                         "temperatures in [lubricant] (the Walther law of ASTM D341)")
    if "load_share" in params and tr.ball:
        raise InputError("load_share is a pin face's share of the load; a ball carries it all")
    _check_models(case, params)
    _check_coverage(case, paths, curves, params)


def _check_models(case: Case, params) -> None:
    """Refuse (fitted) parameters the case's models do not read: a thermal one on an
    isothermal case, C_f,b on a shear-law case; for a fit before its run and for
    ``--from-fit`` alike."""
    if "bulk_resistance" in params and case.thermal.model == "none":
        raise InputError("bulk_resistance needs the thermal twin and the case has [thermal] "
                         "model = \"none\": set model = \"flash\", or fit without it")
    if ("temperature_coefficient" in params and case.thermal.model == "none"
            and len(set(case.lubricant.temperatures)) < 2):
        raise InputError("temperature_coefficient needs a temperature that varies: the "
                         "thermal twin ([thermal] model = \"flash\") or oils at two "
                         "temperatures")
    law = fitted_law(params)
    if law is not None:
        law.check_fit(case.boundary)


def _simulated(case: Case, out: RunLayout, tests, progress: bool) -> list:
    """The twin's curve for each measured one: the run's at the case's load and viscosity,
    else a sweep of its own at the test's load and viscosity (``OUT/fit/checkpoints``)."""
    tr, mus = case.tribometer, case.lubricant.viscosities
    run = read_stribeck_csv(out.stribeck_csv)
    own = [run[mus.index(mu)] if load == tr.load and mu in mus else None
           for load, mu in tests]
    first = _fit_sweep(case, out, error_estimate=True)   # cf_err, as the run's: the band
    tasks = [replace(first, load=load, lubricant=replace(first.lubricant, viscosity=mu))
             for (load, mu), c in zip(tests, own) if c is None]
    with executor_for(case.run.workers, case.run.scheduler) as executor:
        swept = iter(run_sweeps(tasks, executor, progress, desc="fit loads").curves
                     if tasks else [])
    return [c if c is not None else next(swept) for c in own]


def _predict_load(case: Case, out: RunLayout, result: dict, load: float, progress: bool):
    """``OUT/prediction_LN.csv``: the fitted twin at ``load`` [N], each case viscosity
    swept there, with the 95 % band of the fitted parameters."""
    tests = [(load, mu) for mu in case.lubricant.viscosities]
    curves = _simulated(case, out, tests, progress)
    model = FitModel(tuple(curves), case.tribometer.boundary_friction, load, None,
                     boundary=case.boundary)
    rows = [predict(model, result, c.speed, None, curve=k) for k, c in enumerate(curves)]
    _write_prediction(out.prediction_at_load(load), rows, [c.viscosity for c in curves])


def _check_coverage(case: Case, paths, curves, params) -> None:
    """Refuse, before the run, measured curves whose points inside the case's speed range
    ([sweep] speed_min to speed_max) are too few for the fitted unknowns (one temperature
    per curve) plus one, the least that leaves an interval."""
    sw = case.sweep
    inside = [int(np.sum((c.speed >= sw.speed_min) & (c.speed <= sw.speed_max)))
              for c in curves]
    outside = [p.name for p, n in zip(paths, inside) if n == 0]
    if outside:
        raise InputError(f"{', '.join(outside)}: no measured point lies inside the case's "
                         f"speeds ({sw.speed_min:g} to {sw.speed_max:g} m/s); widen [sweep] or "
                         "leave the curve out")
    unknowns = len(params) + (len(curves) - 1 if "temperature" in params else 0)
    if sum(inside) <= unknowns:
        where = ", ".join(f"{p.name}: {n} of {c.speed.size}" for p, n, c in
                          zip(paths, inside, curves))
        raise InputError(f"the measured points inside the case's speeds ({sw.speed_min:g} to "
                         f"{sw.speed_max:g} m/s) are too few to fit {unknowns} unknown(s) with "
                         f"an interval ({where}): measure more speeds there or widen [sweep]")


def extra_curves(case: Case, out: RunLayout, curves, shares=(), resistances=(),
                 progress: bool = True) -> tuple:
    """The fit's own sweeps, one batch of tasks (:func:`run_sweeps`), checkpointed in
    ``OUT/fit/checkpoints`` over the speeds of ``curves`` (the case's run, one per
    viscosity), the micro stage's flow factors reused: ``(share_pairs, resistance_pairs)``,
    ``((share, StribeckCurve), ...)`` for the first viscosity at the load ``shares`` and,
    per curve, ``((R_b, StribeckCurve), ...)`` at the thermal ``resistances`` [K/W];
    each ascending, with the case's own value's curve, empty where none is asked for."""
    tr, own = case.tribometer, case.thermal.bulk_resistance
    at_shares = sorted(s for s in shares if not np.isclose(s, tr.load_share, rtol=1e-9))
    at_resistances = sorted(r for r in resistances
                            if not np.isclose(r, own, rtol=1e-9, atol=1e-12))
    first = _fit_sweep(case, out, speeds=np.sort(curves[0].speed)[::-1])
    tasks = [replace(first, load_share=s) for s in at_shares] + [
        replace(request, speeds=np.sort(c.speed)[::-1], thermal=replace(
            request.thermal, settings=replace(request.thermal.settings, bulk_resistance=r)))
        for c, request in zip(curves, per_viscosity(case, _fit_sweep(case, out)))
        for r in at_resistances]
    with executor_for(case.run.workers, case.run.scheduler) as executor:
        swept = run_sweeps(tasks, executor, progress, desc="fit points").curves
    by_share, rest = swept[:len(at_shares)], swept[len(at_shares):]
    ascending = lambda pairs: tuple(sorted(pairs, key=lambda p: p[0]))  # noqa: E731
    n = len(at_resistances)
    return (ascending([*zip(at_shares, by_share), (tr.load_share, curves[0])])
            if len(shares) else (),
            tuple(ascending([*zip(at_resistances, rest[k * n:(k + 1) * n]), (own, c)])
                  for k, c in enumerate(curves)) if len(resistances) else ())


def _fit_sweep(case: Case, out: RunLayout, **changes):
    """The case's sweep request (first viscosity) for the fit's extra sweeps, checkpointed
    in ``OUT/fit/checkpoints``; ``changes`` as :func:`dataclasses.replace`'s."""
    return sweep_request(case, out, checkpoint=out.fit_points, **changes)


@arguments(case=Case, result=dict)
def apply_fit(case: Case, result: dict) -> Case:
    """``case`` with the fitted parameters of ``result`` (a ``fit.json``): C_f,b, the load
    share, and viscosities from the fit's Walther law at the case's temperatures plus the
    mean fitted offset of the contact temperature."""
    result = check_fit(result)
    tr, lb = case.tribometer, case.lubricant
    params, made = result["fit"]["parameters"], result["case"]
    _check_models(case, params)
    if "kind" not in made:
        log.warning("the fit.json does not name the tribometer it was fitted on; its "
                    "parameters are applied to this %s case as they are", tr.kind)
    if made.get("kind", tr.kind) != tr.kind:
        raise InputError(f"the fit was made on a {made['kind']} case and this is a {tr.kind} "
                         "case: its contact and kinematics differ; fit this tribometer's curves")
    if "load_share" in params and not np.isclose(made.get("load_N", tr.load), tr.load):
        log.warning("the load share was fitted at %g N and is applied at %g N: a face's share "
                    "may change with the load", made["load_N"], tr.load)
    get = lambda name, default: result.get(name, {}).get("value", default)  # noqa: E731
    tr = replace(tr, boundary_friction=get("boundary_friction", tr.boundary_friction),
                 load_share=get("load_share", tr.load_share))
    thermal = replace(case.thermal, bulk_resistance=get("bulk_resistance",
                                                        case.thermal.bulk_resistance))
    law = fitted_law(params)
    section = {} if law is None else {k: result[k]["value"] for k in law.keys if k in result}
    boundary = (replace(law.start(case.boundary, case.tribometer.boundary_friction), **section)
                if section else case.boundary)
    offset = temperature_offset(result)
    if offset is not None:
        law = WaltherLaw(**result["case"]["law"])
        lb = replace(lb, viscosities=tuple(float(law.viscosity(t + offset))
                                           for t in lb.temperatures))
    return replace(case, tribometer=tr, lubricant=lb, thermal=thermal, boundary=boundary)


def run_from_fit(case: Case, fit_path, outdir, *, progress: bool = True, run=None,
                 **options) -> dict:
    """Run ``case`` with the parameters fitted in ``fit_path`` (:func:`apply_fit`): at
    another load or oil temperature than the fit's; ``OUT/prediction.csv`` gives each
    curve with the 95 % band of the fitted parameters' covariance (a fitted load share or
    thermal resistance by more sweeps at its interval's ends) and the curve's C_f error
    estimate.
    Returns the run's summary with ``"prediction"``; ``options`` go to ``run``
    (:func:`fem_twin.stages.pipeline.run`)."""
    result = read_fit(fit_path)
    fitted = apply_fit(case, result)
    if run is None:
        from ..stages.pipeline import run
    summary = run(fitted, outdir, progress=progress, **options)
    out = RunLayout(outdir)
    curves = read_stribeck_csv(out.stribeck_csv)
    lb, tr = fitted.lubricant, fitted.tribometer
    law = None if result["case"]["law"] is None else WaltherLaw(**result["case"]["law"])
    lo, hi, _ = QUANTITIES["load_share"]
    share_ends = ({min(max(result["load_share"][e], lo), hi) for e in ("low", "high")}
                  if "load_share" in result else ())
    resistance_ends = ({max(result["bulk_resistance"][e], 0.0) for e in ("low", "high")}
                       if "bulk_resistance" in result else ())
    shares, resistances = extra_curves(fitted, out, curves, sorted(share_ends),
                                       sorted(resistance_ends), progress)
    shares = shares if len(shares) > 1 else ()                # a zero-width interval
    resistances = resistances if resistances and len(resistances[0]) > 1 else ()
    model = FitModel(tuple(curves), tr.boundary_friction, tr.load, law, tr.load_share, shares,
                     fitted.thermal.bulk_resistance, resistances, fitted.boundary)
    offset = temperature_offset(result)
    rows = [predict(model, result, c.speed, None if offset is None else t,
                    result["case"]["temperatures"], curve=k)
            for k, (c, t) in enumerate(zip(curves, lb.temperatures))]
    _write_prediction(out.prediction(), rows, [c.viscosity for c in curves])
    summary["prediction"] = {"file": out.prediction().name, "fit": str(fit_path),
                             "max_band_half_width": float(max(
                                 np.max(r["cf_high"] - r["cf"]) for r in rows))}
    return summary


def _write_prediction(path, rows, viscosities=None) -> None:
    """Predicted curves with their 95 % band (one block per curve); a warning names the
    points whose band was clipped to [0, 1] or whose C_f lies outside it."""
    cat = lambda key: np.concatenate([r[key] for r in rows])  # noqa: E731
    odd = cat("band_clipped") | (cat("cf") < 0) | (cat("cf") > 1)
    if odd.any():
        log.warning("%s: at %d of %d points the 95 %% band reaches beyond C_f in [0, 1] and "
                    "is clipped there (band_clipped = 1): the fitted parameters do not "
                    "pin C_f down at those speeds", Path(path).name, int(odd.sum()), odd.size)
    columns = {"speed_m_s": cat("speed_m_s"), "friction_coefficient": cat("cf"),
               "cf_low": cat("cf_low"), "cf_high": cat("cf_high"),
               "cf_err": np.concatenate([np.broadcast_to(r["cf_err"], r["cf"].shape)
                                         for r in rows]),
               "band_clipped": odd.astype(int)}
    if viscosities is not None:
        columns = {"viscosity_Pa_s": np.concatenate(
            [np.full(r["cf"].shape, mu) for r, mu in zip(rows, viscosities)]), **columns}
    write_csv(path, columns)
