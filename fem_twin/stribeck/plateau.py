"""The boundary level from the low-speed plateau, the mixed regime predicted (``fem-twin fit
--plateau``): the practice of Gelinck and Schipper (Tribol. Int. 33 (2000) 175) and Lu,
Khonsari and Gelinck (J. Tribol. 128 (2006) 789).

The boundary law's parameters are fitted to the measured points where the twin's
asperities carry at least ``share`` of the load (``contact_load_fraction``); every other
point is predicted with nothing else fitted, with its 95 % band (the fit's intervals and
the twin's ``cf_err``, :func:`.prediction.predict`).  ``fit.json``'s ``plateau`` reports
the fitted and the predicted points' C_f,dev apart: the predicted ones test the twin."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import InputError
from ..macro.laws.boundary_laws import fitted_parameters
from .curve import MeasuredCurve
from .fit import FitModel, fit_curves
from .prediction import finish_fit_figure, predict

#: the asperities' share of the load from which a measured point is on the plateau
PLATEAU_SHARE = 0.9

def check_plateau(params, share: float) -> None:
    """Refuse a plateau fit of anything but a boundary law's parameters
    (:func:`~fem_twin.macro.laws.boundary_laws.fitted_parameters`: what it may vary), or a share
    outside (0, 1)."""
    boundary = fitted_parameters()
    other = [p for p in params if p not in boundary]
    if other:
        raise InputError(f"--plateau fits the boundary law alone ({', '.join(boundary)}) and "
                         f"predicts the rest; {', '.join(other)} would be fitted to the "
                         "mixed regime it predicts: leave them out")
    if not 0 < share < 1:
        raise InputError(f"--plateau {share:g}: the asperities' share of the load from which a "
                         "point counts as the plateau, between 0 and 1 (0.9 is 90 %)")


def fit_plateau(model: FitModel, measured, params, share: float = PLATEAU_SHARE) -> dict:
    """Fit ``params`` (boundary law's) to the ``measured`` points whose twin asperity
    share is at least ``share`` [-], then predict every point (module docstring): the
    :func:`.fit.fit_curves` result with ``plateau``: the rows per curve and, for the
    ``fitted`` and ``predicted`` points, their count, rms and largest absolute C_f,dev [-]
    and the points inside their band."""
    check_plateau(params, share)
    on = [_shares(model, k, m) >= share for k, m in enumerate(measured)]
    keep = [k for k, mask in enumerate(on) if mask.any()]
    if sum(int(on[k].sum()) for k in keep) < len(params) + 1:
        raise InputError(f"--plateau: {sum(int(m.sum()) for m in on)} measured point(s) where "
                         f"the twin's asperities carry {share:.0%} of the load, too few for "
                         f"{len(params)} parameter(s): measure slower speeds")
    sub = replace(model, curves=tuple(model.curves[k] for k in keep),
                  loads=tuple(model.loads[k] for k in keep) if model.loads else ())
    result = fit_curves(sub, [_cut(measured[k], on[k]) for k in keep], params,
                        start_temperatures=None)
    rows = []
    for k, m in enumerate(measured):
        p = predict(model, result, m.speed, None, curve=k)
        rows.append({"curve": k + 1, "speed_m_s": m.speed.tolist(),
                     "asperity_share": _shares(model, k, m).tolist(),
                     "fitted": on[k].tolist(), "measured_cf": m.friction_coefficient.tolist(),
                     "cf": p["cf"].tolist(), "cf_low": p["cf_low"].tolist(),
                     "cf_high": p["cf_high"].tolist()})
    result["plateau"] = {"share": share, "rows": rows,
                         **{role: _summary(model, rows, role == "fitted")
                            for role in ("fitted", "predicted")}}
    return result


def _shares(model: FitModel, k: int, m: MeasuredCurve) -> np.ndarray:
    c = model.curves[k]
    at, inside = model.reader(c, m.speed, c.viscosity)
    return np.where(inside, at(c.contact_load_fraction), np.nan)


def _cut(m: MeasuredCurve, mask) -> MeasuredCurve:
    part = lambda a: None if a is None else np.asarray(a)[mask]  # noqa: E731
    return MeasuredCurve(m.speed[mask], m.friction_coefficient[mask], part(m.low),
                         part(m.high))


def _summary(model: FitModel, rows, fitted: bool) -> dict:
    """Count, rms and largest absolute C_f,dev of the fitted or predicted points, and how
    many of them lie inside their 95 % band."""
    pick = [np.array(r["fitted"]) == fitted for r in rows]
    get = lambda key: np.concatenate([np.array(r[key])[p] for r, p in zip(rows, pick)])  # noqa: E731
    dev = (get("cf") - get("measured_cf")) / model.boundary_friction
    inside = (get("cf_low") <= get("measured_cf")) & (get("measured_cf") <= get("cf_high"))
    return {"points": int(dev.size),
            "rms_cf_dev": float(np.sqrt(np.mean(dev ** 2))) if dev.size else None,
            "max_abs_cf_dev": float(np.abs(dev).max()) if dev.size else None,
            "inside_band": int(inside.sum())}


def plot_plateau(result: dict, path, labels=None):
    """Each curve's measured points (filled: the plateau fitted, open: predicted) and the
    predicted C_f with its 95 % band."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for i, row in enumerate(result["plateau"]["rows"]):
        label = labels[i] if labels else f"curve {row['curve']}"
        u, fitted = np.array(row["speed_m_s"]), np.array(row["fitted"])
        order = np.argsort(u)
        (line,) = ax.loglog(u[order], np.array(row["cf"])[order], "-", label=f"twin, {label}")
        ax.fill_between(u[order], np.array(row["cf_low"])[order],
                        np.array(row["cf_high"])[order], color=line.get_color(), alpha=0.2)
        cf = np.array(row["measured_cf"])
        ax.loglog(u[fitted], cf[fitted], "s", color=line.get_color(), ms=5,
                  label=f"plateau (fitted), {label}")
        ax.loglog(u[~fitted], cf[~fitted], "s", mfc="none", color=line.get_color(), ms=5,
                  label=f"predicted, {label}")
    p = result["plateau"]
    return finish_fit_figure(fig, ax, path, f"boundary level from {p['fitted']['points']} "
                             f"plateau points; {p['predicted']['inside_band']} of "
                             f"{p['predicted']['points']} predicted inside their band")
