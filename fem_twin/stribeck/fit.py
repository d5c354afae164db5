"""Fitting the twin's unknowns to measured Stribeck curves, with 95 % intervals.

Parameters, by their case-file keys (none re-runs the micro stage): ``boundary_friction``,
C_f,b of eq 32, from a simulated curve's force parts; ``temperature``, one oil temperature
per curve through the case's Walther law, the simulated curve at ``mu_S`` giving the one at
``mu`` at the speeds ``U mu / mu_S`` (the Hersey collapse, eq 46); ``load_share``, the pin
face's share of the load, the first viscosity swept at :data:`LOAD_SHARES`;
``bulk_resistance``, the thermal twin's R_b [K/W], every curve swept at
:data:`RESISTANCES` (both interpolated by PCHIP, per speed).

Least squares on C_f,dev (eq 35) at the measured speeds (PCHIP in log speed), weighted by
``sigma = (cf_max - cf_min) / 1.693`` where the measured CSV gives its scatter, else equal
weights with the HC3 covariance (:func:`_covariance`); intervals ``t_{0.975, n - p}`` times
its diagonal's root."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import PchipInterpolator

from ..errors import InputError, NotConverged
from ..macro.viscosity import WaltherLaw
from .curve import MeasuredCurve, StribeckCurve

#: the parameters :func:`fit_curves` can fit (case-file keys)
PARAMETERS = ("boundary_friction", "temperature", "load_share", "bulk_resistance")
#: the face's shares of the imposed load swept for a ``load_share`` fit (its bounds)
LOAD_SHARES = (0.5, 0.625, 0.75, 0.875, 1.0)
#: the rig's thermal resistances [K/W] swept for a ``bulk_resistance`` fit (its bounds)
RESISTANCES = (0.0, 1.0, 2.0, 4.0)
#: a fitted contact temperature this far [K] from its curve's oil temperature is flagged
TEMPERATURE_OFFSET = 15.0
#: expected range of three normal samples in standard deviations (d2 of n = 3)
RANGE_OF_THREE = 1.693


@dataclass(frozen=True)
class FitModel:
    """C_f of simulated curves at other C_f,b, oil temperatures and load shares (module
    docstring).  ``curves``: a StribeckCurve per measured curve, swept at ``load_share`` of
    the imposed ``load`` [N]; ``law``: the lubricant's viscosity-temperature law (None
    without temperatures); ``share_curves``: ``((share, StribeckCurve), ...)`` swept at one
    viscosity, ascending, that bracket ``load_share`` (empty: the share is not a parameter);
    ``resistance_curves``: per curve, ``((R_b, StribeckCurve), ...)`` ascending around the
    curves' own ``bulk_resistance`` [K/W] (empty: not a parameter).
    """

    curves: tuple
    boundary_friction: float      # C_f,b of the simulated curves
    load: float                   # F_N,imp [N]
    law: WaltherLaw | None
    load_share: float = 1.0
    share_curves: tuple = ()
    bulk_resistance: float = 0.0
    resistance_curves: tuple = ()

    def friction(self, k: int, speed, boundary_friction: float, viscosity: float,
                 share: float | None = None, resistance: float | None = None):
        """C_f of curve ``k`` at ``speed`` [m/s] for C_f,b, mu_0 [Pa s], the face's
        ``share`` of the load and the rig's thermal ``resistance`` [K/W] (None: the curves'
        own); and the mask of speeds whose Hersey number lies inside the simulated range
        (ends held outside)."""
        at = lambda c: self._at(c, speed, boundary_friction, viscosity)  # noqa: E731
        cf, inside = at(self.curves[k])
        for value, own, swept in ((share, self.load_share, self.share_curves),
                                  (resistance, self.bulk_resistance,
                                   self.resistance_curves[k] if self.resistance_curves
                                   else ())):
            if value is None or value == own or not swept:
                continue
            values = [at(c) for _, c in swept]
            grid = PchipInterpolator([s for s, _ in swept], np.stack([v[0] for v in values]),
                                     axis=0)
            cf = cf + grid(value) - grid(own)
            inside = inside & np.all([v[1] for v in values], axis=0)
        return cf, inside

    def _at(self, c: StribeckCurve, speed, boundary_friction: float, viscosity: float):
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


def fit_curves(model: FitModel, measured, params, *, start_temperatures,
               verbose: bool = False) -> dict:
    """Fit ``params`` (a subset of :data:`PARAMETERS`) to the ``measured`` curves
    (:class:`MeasuredCurve`, one per ``model.curves``); ``start_temperatures`` [C] start the
    temperature of each curve; without ``temperature`` they are the known temperatures, or,
    when None, each simulated curve keeps its own viscosity (``model.law`` may be None).
    Returns ``{name: {"value", "low", "high"}}`` (:func:`interval`; ``temperature_K`` and
    its ``viscosity_K`` per curve K from 1) with the residuals and the fit's statistics.
    ``verbose``: a line per iteration (scipy's).  Raises :class:`~fem_twin.errors.InputError`
    when no parameter set fits (:func:`check_misfit`)."""
    check_parameters(params)
    if len(measured) != len(model.curves):
        raise InputError(f"{len(measured)} measured curves for {len(model.curves)} simulated")
    if "temperature" in params and start_temperatures is None:
        raise InputError("fitting the temperature needs start temperatures [C]")
    if "load_share" in params and len(model.share_curves) < 2:
        raise InputError("fitting the load share needs sweeps at two or more load shares "
                         "(FitModel.share_curves)")
    if "bulk_resistance" in params and len(model.resistance_curves) != len(model.curves):
        raise InputError("fitting the thermal resistance needs every curve swept at two or "
                         "more resistances (FitModel.resistance_curves)")
    names, x0, lower, upper = _unknowns(model, params, len(measured), start_temperatures)

    def unpack(x):
        """C_f,b, the viscosity [Pa s] of each curve, the face's load share and R_b."""
        v = dict(zip(names, x))
        cfb = v.get("boundary_friction", model.boundary_friction)
        temps = [v.get(f"temperature_{k + 1}") for k in range(len(measured))]
        if temps[0] is None:                          # known temperatures, or the curves'
            mus = ([c.viscosity for c in model.curves] if start_temperatures is None
                   else [float(model.law.viscosity(t)) for t in start_temperatures])
        else:
            mus = [float(model.law.viscosity(t)) for t in temps]
        return cfb, mus, v.get("load_share"), v.get("bulk_resistance")

    measured, dropped = _inside(model, measured, *unpack(x0))
    sigma = [_sigma(m) for m in measured]
    weighted = all(s is not None for s in sigma)

    def residuals(x):
        cfb, mus, share, resistance = unpack(x)
        out = []
        for k, m in enumerate(measured):
            cf, _ = model.friction(k, m.speed, cfb, mus[k], share, resistance)
            r = (cf - m.friction_coefficient) / model.boundary_friction
            out.append(r / (sigma[k] / model.boundary_friction) if weighted else r)
        return np.concatenate(out)

    n = sum(m.speed.size for m in measured)
    if n <= x0.size:
        raise InputError(f"{n} measured points cannot fit {x0.size} parameters")
    from scipy import optimize  # imported here: the CLI reads PARAMETERS
    sol = optimize.least_squares(residuals, x0, bounds=(lower, upper), x_scale="jac",
                                 verbose=2 if verbose else 0)
    if not sol.success:
        raise NotConverged(f"fit did not converge: {sol.message}", [float(sol.cost)])
    out = _summary(model, measured, names, sol, weighted, unpack, (lower, upper))
    out["fit"]["points_not_counted"] = dropped
    out["fit"]["warnings"] += [f"curve {k + 1}: {n} measured point(s) outside the simulated "
                               "speeds not counted" for k, n in enumerate(dropped) if n]
    check_misfit(out, names, sol.x, lower, upper)
    return out


def _unknowns(model, params, n_curves, start_temperatures):
    """Names, start values and bounds of the unknowns: C_f,b in [1e-4, 1], a temperature
    per curve in [-30, 250] C, the load share over :attr:`FitModel.share_curves`."""
    rows = []
    if "boundary_friction" in params:
        rows.append(("boundary_friction", model.boundary_friction, 1e-4, 1.0))
    if "temperature" in params:
        rows += [(f"temperature_{k + 1}", float(t), -30.0, 250.0)
                 for k, t in zip(range(n_curves), start_temperatures)]
    if "load_share" in params:
        lo, hi = model.share_curves[0][0], model.share_curves[-1][0]
        rows.append(("load_share", min(max(model.load_share, lo), hi), lo, hi))
    if "bulk_resistance" in params:
        lo, hi = model.resistance_curves[0][0][0], model.resistance_curves[0][-1][0]
        rows.append(("bulk_resistance", min(max(model.bulk_resistance, lo), hi), lo, hi))
    names, x0, lower, upper = zip(*rows)
    return list(names), np.array(x0, float), list(lower), list(upper)


#: a fit is refused when its rms C_f,dev exceeds this share of C_f,b without measured
#: scatter (the paper's repeated tests scatter by about +-10 %)
MISFIT_RMS = 0.05
#: ... or, with the measured scatter as weights, when chi^2 is this improbable
MISFIT_P = 1e-3


def check_misfit(result: dict, names, x, lower, upper) -> None:
    """Refuse a fit that no parameter set achieves: C_f,b or a temperature pinned at its
    bound, or residuals beyond the measured scatter (chi^2 p-value below
    :data:`MISFIT_P`), or, without scatter, an rms C_f,dev above :data:`MISFIT_RMS`."""
    f = result["fit"]
    worst = max(((abs(d), r["curve"], u, d) for r in result["residuals"]
                 for u, d in zip(r["speed_m_s"], r["cf_dev"])))
    where = (f"rms C_f,dev {f['rms_cf_dev']:.1%} of C_f,b, largest {worst[3]:+.1%} at "
             f"{worst[2]:.3g} m/s on curve {worst[1]}")
    pinned = [n for n, v, lo, hi in zip(names, x, lower, upper)
              if n not in ("load_share", "bulk_resistance")
              and min(v - lo, hi - v) <= 1e-6 * (hi - lo)]
    if f["weights"] == "equal":
        bad = f["rms_cf_dev"] > MISFIT_RMS
    else:
        from scipy import stats
        bad = stats.chi2.sf(f["chi2"], f["degrees_of_freedom"]) < MISFIT_P
    if pinned or bad:
        raise InputError(f"no parameter set fits the measured curve(s): {where}"
                         + (f"; {', '.join(pinned)} at the bound of its range" if pinned
                            else "") + "; was it measured at the case's load, in m/s, with "
                         "the case's lubricant?")


def _inside(model: FitModel, measured, cfb, mus, share, resistance) -> tuple:
    """The ``measured`` curves cut to the points inside the simulated curves' Hersey range
    at the start values (C_f there would be held at the ends), and how many each lost;
    a curve with none inside is refused."""
    kept, dropped = [], []
    for k, m in enumerate(measured):
        inside = model.friction(k, m.speed, cfb, mus[k], share, resistance)[1]
        if not inside.any():
            raise InputError(f"measured curve {k + 1}: all {m.speed.size} points lie outside "
                             "the simulated speeds; sweep its speeds, or leave it out")
        cut = lambda a: None if a is None else np.asarray(a)[inside]  # noqa: E731
        kept.append(MeasuredCurve(m.speed[inside], m.friction_coefficient[inside],
                                  cut(m.low), cut(m.high)))
        dropped.append(int((~inside).sum()))
    return kept, dropped


def _sigma(m: MeasuredCurve):
    if m.low is None or m.high is None:
        return None
    s = (np.asarray(m.high) - np.asarray(m.low)) / RANGE_OF_THREE
    return np.maximum(s, 1e-3 * np.abs(m.friction_coefficient).max())


def interval(value: float, half: float, lower: float, upper: float) -> dict:
    """A fitted value with its 95 % interval ``value +- half``, clipped to the parameter's
    bounds ``[lower, upper]`` (a share above 1, a negative resistance); a clipped interval
    names the bounds (``"clipped_to_bounds"``)."""
    low, high = max(value - half, lower), min(value + half, upper)
    out = {"value": float(value), "low": float(low), "high": float(high)}
    if low > value - half or high < value + half:
        out["clipped_to_bounds"] = [float(lower), float(upper)]
    return out


def _summary(model, measured, names, sol, weighted, unpack, bounds) -> dict:
    n, p = sol.fun.size, sol.x.size
    dof = n - p
    size = np.linalg.norm(sol.jac, axis=0)
    blind = [name for name, s in zip(names, size) if not s > 1e-9 * max(size.max(), 1e-300)]
    if blind or dof < 1:
        raise InputError(f"the measured points do not constrain {', '.join(blind) or 'the fit'}"
                         f" ({n} residuals for {p} unknowns): they lie where C_f does not "
                         "depend on it (C_f,b in full film), or are too few; measure the "
                         "speeds where it acts")
    cov = _covariance(sol.jac, sol.fun, weighted)
    from scipy import stats
    half = stats.t.ppf(0.975, dof) * np.sqrt(np.diag(cov))
    out = {name: interval(v, h, lo, hi)
           for name, v, h, lo, hi in zip(names, sol.x, half, *bounds)}
    cfb, mus, share, resistance = unpack(sol.x)
    for k in range(len(measured)):
        t = out.get(f"temperature_{k + 1}")
        if t is not None:                       # viscosity falls as temperature rises
            mu = model.law.viscosity([t["value"], t["high"], t["low"]])
            out[f"viscosity_{k + 1}"] = {"value": float(mu[0]), "low": float(mu[1]),
                                         "high": float(mu[2])}
    rows, outside = [], 0
    for k, m in enumerate(measured):
        cf, inside = model.friction(k, m.speed, cfb, mus[k], share, resistance)
        outside += int((~inside).sum())
        rows.append({"curve": k + 1, "speed_m_s": m.speed.tolist(),
                     "measured_cf": m.friction_coefficient.tolist(), "fitted_cf": cf.tolist(),
                     "cf_dev": ((cf - m.friction_coefficient)
                                / model.boundary_friction).tolist()})
    dev = np.concatenate([r["cf_dev"] for r in rows])
    out["fit"] = {"parameters": names, "points": n, "degrees_of_freedom": dof,
                  "chi2": float(sol.fun @ sol.fun),
                  "weights": "measured scatter (cf_min/cf_max)" if weighted else "equal",
                  "rms_cf_dev": float(np.sqrt(np.mean(dev ** 2))),
                  "max_abs_cf_dev": float(np.abs(dev).max()),
                  "points_outside_simulated_range": outside,
                  "correlation": _correlation(cov).tolist(), "covariance": cov.tolist(),
                  "t_factor": float(stats.t.ppf(0.975, dof))}
    out["residuals"] = rows
    out["fit"]["warnings"] = _temperature_warnings(model, out, len(measured))
    return out


def _temperature_warnings(model: FitModel, out: dict, n: int) -> list[str]:
    """Fitted contact temperatures more than :data:`TEMPERATURE_OFFSET` from their curve's."""
    warnings = []
    for k in range(n):
        fitted = out.get(f"temperature_{k + 1}", {}).get("value")
        oil = None if fitted is None else float(model.law.temperature(model.curves[k].viscosity))
        if fitted is not None and abs(fitted - oil) > TEMPERATURE_OFFSET:
            warnings.append(f"curve {k + 1}: the fitted contact temperature is {fitted:.1f} C "
                            f"({oil:.1f} C in the case): frictional heating of a few K is "
                            "usual; a larger offset may stand for another load or lubricant "
                            "(the Hersey collapse trades the two)")
    return warnings


def predict(model: FitModel, result: dict, speeds, temperature: float | None,
            nominal=None, *, curve: int | None = None) -> dict:
    """C_f at ``speeds`` [m/s] for the oil at ``temperature`` [C] with the fitted parameters
    of ``result`` (:func:`fit_curves`), and its 95 % band from their covariance.

    With fitted temperatures and the ``nominal`` oil temperatures of the measured curves
    [C], the contact runs at ``temperature`` plus their mean offset (fitted minus nominal,
    e.g. frictional heating), whose uncertainty joins the band; without, at
    ``temperature`` (None: at the viscosity of the simulated ``curve``).  The simulated
    curve of the nearest viscosity, or ``curve``, is rescaled (Hersey); without ``curve``
    the band adds the spread of all the simulated curves so rescaled (the Hersey collapse's
    own error, when there are two or more); it adds their C_f error estimates
    (``cf_err``).  A fitted load share and thermal resistance move C_f along
    ``model.share_curves`` and ``model.resistance_curves``."""
    names = result["fit"]["parameters"]
    x = np.array([result[n]["value"] for n in names])
    cov = np.asarray(result["fit"]["covariance"])
    temps = [i for i, n in enumerate(names) if n.startswith("temperature_")]

    def cf(x, k=curve):
        v = dict(zip(names, x))
        offset = (np.mean([x[i] - t for i, t in zip(temps, nominal)])
                  if temps and nominal is not None else 0.0)
        mu = (model.curves[k].viscosity if temperature is None
              else float(model.law.viscosity(temperature + offset)))
        if k is None:
            k = int(np.argmin([abs(np.log(c.viscosity / mu)) for c in model.curves]))
        return model.friction(k, speeds, v.get("boundary_friction", model.boundary_friction),
                              mu, v.get("load_share"), v.get("bulk_resistance"))

    value, inside = cf(x)
    discretisation = _error_at(model, speeds) + (_collapse_error(model, cf, x)
                                                 if curve is None else 0.0)
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


def _covariance(jac, res, weighted: bool):
    """Covariance of the fitted parameters: ``(J^T J)^-1`` for residuals weighted by the
    measured scatter; without it, the heteroscedasticity-consistent sandwich estimator HC3
    (MacKinnon and White 1985), ``(J^T J)^-1 J^T diag(r_i^2 / (1 - h_i)^2) J (J^T J)^-1``
    with the leverages ``h_i``: the scatter of a measured C_f grows with C_f (a per cent of
    it), and one variance from all the residuals understates it where the parameters are
    decided (the boundary regime)."""
    inv = np.linalg.pinv(jac.T @ jac)
    if weighted:
        return inv
    leverage = np.einsum("ij,jk,ik->i", jac, inv, jac)
    meat = jac.T @ (jac * (res / np.maximum(1 - leverage, 1e-3))[:, None] ** 2)
    return inv @ meat @ inv


def _correlation(cov):
    d = np.sqrt(np.diag(cov))
    outer = np.outer(d, d)
    return np.divide(cov, outer, out=np.zeros_like(cov), where=outer > 0)


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
