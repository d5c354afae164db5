"""Fitting the twin's unknowns to measured Stribeck curves, with 95 % intervals.

Parameters, named by their case-file keys:

``boundary_friction``
    C_f,b of eq 32.  The friction force is ``F_hd + C_f,b F_con`` (eqs 31-34) and the
    contact force does not depend on C_f,b, so a simulated curve's two force parts give C_f
    at any C_f,b without a new solve.
``temperature``
    one effective oil temperature per measured curve [C], through the lubricant's
    Walther law (:class:`~fem_twin.macro.viscosity.WaltherLaw`, fixed by the case's
    viscosities and temperatures).  By the Hersey collapse (eq 46; 0.1 % C_f,b between the
    bundled case's two viscosities) the simulated curve at ``mu_S`` gives the curve at
    ``mu`` at the speeds ``U mu / mu_S``: the micro and macro stages are not run again.

Least squares on C_f,dev (eq 35) at the measured speeds (the simulated curve interpolated
by PCHIP in log speed).  Weights: where the measured CSV gives ``cf_min``/``cf_max`` (the
scatter of a set of tests), ``sigma = (cf_max - cf_min) / 1.693``, the expected range of
three normal samples in standard deviations; otherwise equal weights and the variance from
the residuals.  Intervals: ``t_{0.975, n - p}`` times the square root of the diagonal of
``(J^T W J)^-1`` (scaled by the residual variance without a band).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, stats
from scipy.interpolate import PchipInterpolator

from ..errors import InputError, NotConverged
from ..macro.viscosity import WaltherLaw
from .curve import MeasuredCurve, StribeckCurve

#: the parameters :func:`fit_curves` can fit (case-file keys)
PARAMETERS = ("boundary_friction", "temperature")
#: expected range of three normal samples in standard deviations (d2 of n = 3)
RANGE_OF_THREE = 1.693


@dataclass(frozen=True)
class FitModel:
    """C_f of simulated curves at other C_f,b and oil temperatures (module docstring)."""

    curves: tuple                 # StribeckCurve per measured curve
    boundary_friction: float      # C_f,b of the simulated curves
    load: float                   # F_N [N]
    law: WaltherLaw

    def friction(self, k: int, speed, boundary_friction: float, viscosity: float):
        """C_f of curve ``k`` at ``speed`` [m/s] for C_f,b and mu_0 [Pa s]; and the mask of
        speeds whose Hersey number lies inside the simulated range (ends held outside)."""
        c = self.curves[k]
        order = np.argsort(c.speed)
        x = np.log(c.speed[order])
        u = np.log(np.asarray(speed, float) * viscosity / c.viscosity)
        inside = (u >= x[0]) & (u <= x[-1])
        u = np.clip(u, x[0], x[-1])
        hd = PchipInterpolator(x, c.hydrodynamic_friction[order])(u)
        con = PchipInterpolator(x, c.boundary_friction[order])(u) / self.boundary_friction
        return (hd + boundary_friction * con) / self.load, inside


def check_parameters(params) -> None:
    """Refuse an empty list or a name outside :data:`PARAMETERS`."""
    unknown = set(params) - set(PARAMETERS)
    if unknown or not params:
        raise InputError(f"unknown fit parameter(s) {sorted(unknown)}; choose from "
                         f"{list(PARAMETERS)}")


def fit_curves(model: FitModel, measured, params, *, start_temperatures) -> dict:
    """Fit ``params`` (a subset of :data:`PARAMETERS`) to the ``measured`` curves
    (:class:`MeasuredCurve`, one per ``model.curves``); ``start_temperatures`` [C] start the
    temperature of each curve; without ``temperature`` they are the known temperatures, or,
    when None, each simulated curve keeps its own viscosity (``model.law`` may be None).
    Returns ``{name: {"value", "low", "high"}}`` (``temperature_K`` and its
    ``viscosity_K`` per curve K from 1) with the residuals and the fit's statistics."""
    check_parameters(params)
    if len(measured) != len(model.curves):
        raise InputError(f"{len(measured)} measured curves for {len(model.curves)} simulated")
    names = (["boundary_friction"] if "boundary_friction" in params else []) + (
        [f"temperature_{k + 1}" for k in range(len(measured))] if "temperature" in params
        else [])
    if "temperature" in params and start_temperatures is None:
        raise InputError("fitting the temperature needs start temperatures [C]")
    x0 = np.array([model.boundary_friction] * ("boundary_friction" in params)
                  + list(start_temperatures or []) * ("temperature" in params), float)
    sigma = [_sigma(m) for m in measured]
    weighted = all(s is not None for s in sigma)

    def unpack(x):
        """C_f,b and the viscosity [Pa s] of each curve."""
        cfb = x[0] if "boundary_friction" in params else model.boundary_friction
        if "temperature" not in params:               # known temperatures, or the curves'
            return cfb, ([c.viscosity for c in model.curves] if start_temperatures is None
                         else [float(model.law.viscosity(t)) for t in start_temperatures])
        return cfb, [float(model.law.viscosity(t)) for t in x[-len(measured):]]

    def residuals(x):
        cfb, mus = unpack(x)
        out = []
        for k, m in enumerate(measured):
            cf, _ = model.friction(k, m.speed, cfb, mus[k])
            r = (cf - m.friction_coefficient) / model.boundary_friction
            out.append(r / (sigma[k] / model.boundary_friction) if weighted else r)
        return np.concatenate(out)

    n = sum(m.speed.size for m in measured)
    if n <= x0.size:
        raise InputError(f"{n} measured points cannot fit {x0.size} parameters")
    nb = int("boundary_friction" in params)          # C_f,b in (0, 1], T in [-30, 250] C
    lower, upper = [1e-4] * nb + [-30.0] * (x0.size - nb), [1.0] * nb + [250.0] * (x0.size - nb)
    sol = optimize.least_squares(residuals, x0, bounds=(lower, upper), x_scale="jac")
    if not sol.success:
        raise NotConverged(f"fit did not converge: {sol.message}", [float(sol.cost)])
    return _summary(model, measured, names, sol, weighted, unpack)


def _sigma(m: MeasuredCurve):
    if m.low is None or m.high is None:
        return None
    s = (np.asarray(m.high) - np.asarray(m.low)) / RANGE_OF_THREE
    return np.maximum(s, 1e-3 * np.abs(m.friction_coefficient).max())


def _summary(model, measured, names, sol, weighted, unpack) -> dict:
    n, p = sol.fun.size, sol.x.size
    dof = n - p
    scale = 1.0 if weighted else float(sol.fun @ sol.fun / dof)
    cov = np.linalg.pinv(sol.jac.T @ sol.jac) * scale
    half = stats.t.ppf(0.975, dof) * np.sqrt(np.diag(cov))
    out = {name: {"value": float(v), "low": float(v - h), "high": float(v + h)}
           for name, v, h in zip(names, sol.x, half)}
    cfb, mus = unpack(sol.x)
    for k in range(len(measured)):
        t = out.get(f"temperature_{k + 1}")
        if t is not None:                       # viscosity falls as temperature rises
            mu = model.law.viscosity([t["value"], t["high"], t["low"]])
            out[f"viscosity_{k + 1}"] = {"value": float(mu[0]), "low": float(mu[1]),
                                         "high": float(mu[2])}
    rows, outside = [], 0
    for k, m in enumerate(measured):
        cf, inside = model.friction(k, m.speed, cfb, mus[k])
        outside += int((~inside).sum())
        rows.append({"curve": k + 1, "speed_m_s": m.speed.tolist(),
                     "measured_cf": m.friction_coefficient.tolist(), "fitted_cf": cf.tolist(),
                     "cf_dev": ((cf - m.friction_coefficient)
                                / model.boundary_friction).tolist()})
    dev = np.concatenate([r["cf_dev"] for r in rows])
    out["fit"] = {"parameters": names, "points": n, "degrees_of_freedom": dof,
                  "weights": "measured scatter (cf_min/cf_max)" if weighted else "equal",
                  "rms_cf_dev": float(np.sqrt(np.mean(dev ** 2))),
                  "max_abs_cf_dev": float(np.abs(dev).max()),
                  "points_outside_simulated_range": outside,
                  "correlation": _correlation(cov).tolist(), "covariance": cov.tolist(),
                  "t_factor": float(stats.t.ppf(0.975, dof))}
    out["residuals"] = rows
    return out


def predict(model: FitModel, result: dict, speeds, temperature: float,
            nominal=None) -> dict:
    """C_f at ``speeds`` [m/s] for the oil at ``temperature`` [C] with the fitted parameters
    of ``result`` (:func:`fit_curves`), and its 95 % band from their covariance.

    With fitted temperatures and the ``nominal`` oil temperatures of the measured curves
    [C], the contact runs at ``temperature`` plus their mean offset (fitted minus nominal,
    e.g. frictional heating), whose uncertainty joins the band; without, at
    ``temperature``.  The simulated curve of the nearest viscosity is rescaled (Hersey);
    the band adds the spread of all the simulated curves so rescaled (the Hersey collapse's
    own error, when there are two or more) and their C_f error estimates (``cf_err``)."""
    names = result["fit"]["parameters"]
    x = np.array([result[n]["value"] for n in names])
    cov = np.asarray(result["fit"]["covariance"])
    temps = [i for i, n in enumerate(names) if n.startswith("temperature_")]

    def cf(x, k=None):
        cfb = x[names.index("boundary_friction")] if "boundary_friction" in names \
            else model.boundary_friction
        offset = (np.mean([x[i] - t for i, t in zip(temps, nominal)])
                  if temps and nominal is not None else 0.0)
        mu = float(model.law.viscosity(temperature + offset))
        if k is None:
            k = int(np.argmin([abs(np.log(c.viscosity / mu)) for c in model.curves]))
        return model.friction(k, speeds, cfb, mu)

    value, inside = cf(x)
    discretisation = _error_at(model, speeds) + _collapse_error(model, cf, x)
    grad = np.stack([(cf(x + step)[0] - value) / step[i]
                     for i, step in enumerate(np.diag(np.maximum(1e-6 * np.abs(x), 1e-6)))],
                    axis=1)
    half = result["fit"]["t_factor"] * np.sqrt(np.einsum("ij,jk,ik->i", grad, cov, grad))
    half = half + discretisation                  # the twin's own error (cf_err), when known
    return {"speed_m_s": np.asarray(speeds, float), "cf": value, "cf_low": value - half,
            "cf_high": value + half, "cf_err": discretisation,
            "inside_simulated_range": inside}


def _collapse_error(model: FitModel, cf, x) -> np.ndarray:
    """Largest spread of the simulated curves rescaled to the same viscosity (eq 46)."""
    if len(model.curves) < 2:
        return 0.0
    values = np.array([cf(x, k)[0] for k in range(len(model.curves))])
    return values.max(axis=0) - values.min(axis=0)


def _error_at(model: FitModel, speeds) -> np.ndarray:
    """The simulated curves' C_f error estimate at ``speeds`` (the largest over the curves;
    0 without estimates)."""
    curves = [c for c in model.curves if c.friction_error is not None]
    if not curves:
        return np.zeros(np.shape(speeds))
    out = []
    for c in curves:
        order = np.argsort(c.speed)
        out.append(np.interp(np.log(speeds), np.log(c.speed[order]), c.friction_error[order]))
    return np.max(out, axis=0)


def _correlation(cov):
    d = np.sqrt(np.diag(cov))
    return cov / np.outer(d, d)


def plot_fit(result: dict, path, labels=None):
    """Measured and fitted C_f against speed, one colour per curve."""
    import matplotlib.pyplot as plt

    from ..io.figure import save_figure
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for i, row in enumerate(result["residuals"]):
        label = labels[i] if labels else f"curve {row['curve']}"
        (line,) = ax.loglog(row["speed_m_s"], row["fitted_cf"], "-", label=f"fitted, {label}")
        ax.loglog(row["speed_m_s"], row["measured_cf"], "s", color=line.get_color(), ms=4,
                  label=f"measured, {label}")
    fitted = ", ".join(f"{k} = {v['value']:.4g} [{v['low']:.4g}, {v['high']:.4g}]"
                       for k, v in result.items() if k in result["fit"]["parameters"])
    ax.set_title(fitted, fontsize="small")
    ax.set_xlabel("sliding speed $U$ [m/s]")
    ax.set_ylabel("$C_f$ [-]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="x-small")
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)
