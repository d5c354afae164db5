"""The statistics of a least-squares fit (:mod:`.fit`): 95 % intervals clipped to the
parameters' bounds, the parameters' covariance and correlation, the warnings on fitted
contact temperatures, and the summary of a solved fit (:func:`fit_summary`)."""

from __future__ import annotations

import numpy as np

from ..errors import InputError

#: a fitted contact temperature this far [K] from its curve's oil temperature is flagged
TEMPERATURE_OFFSET = 15.0


def interval(value: float, half: float, lower: float, upper: float) -> dict:
    """A fitted value with its 95 % interval ``value +- half``, clipped to the parameter's
    bounds ``[lower, upper]`` (a share above 1, a negative resistance); a clipped interval
    names the bounds (``"clipped_to_bounds"``)."""
    low, high = max(value - half, lower), min(value + half, upper)
    out = {"value": float(value), "low": float(low), "high": float(high)}
    if low > value - half or high < value + half:
        out["clipped_to_bounds"] = [float(lower), float(upper)]
    return out


def covariance(jac, res, weighted: bool):
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


def correlation(cov):
    """The correlation matrix of a covariance (0 where a variance is 0)."""
    d = np.sqrt(np.diag(cov))
    outer = np.outer(d, d)
    return np.divide(cov, outer, out=np.zeros_like(cov), where=outer > 0)


def temperature_warnings(model, out: dict, n: int) -> list[str]:
    """Fitted contact temperatures more than :data:`TEMPERATURE_OFFSET` from their curve's
    oil temperature (``model``: the :class:`.fit.FitModel`)."""
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


def fit_summary(model, measured, names, sol, weighted, unpack, bounds) -> dict:
    """The result of a solved least-squares fit ``sol`` of the unknowns ``names`` within
    ``bounds`` ``(lower, upper)`` to the ``measured`` curves of ``model`` (a
    :class:`.fit.FitModel`; ``unpack``: the unknowns' vector as the boundary law's values,
    the curves' viscosities, the load share and R_b): each value with its 95 % interval, the
    fitted temperatures' viscosities, the residuals and the fit's statistics (``"fit"``).
    Refuses unknowns the points do not constrain."""
    n, p = sol.fun.size, sol.x.size
    dof = n - p
    # each column over its parameter's range: C_f,b and tau_0 [Pa] differ by 1e9 in units
    size = np.linalg.norm(sol.jac * (np.array(bounds[1]) - np.array(bounds[0])), axis=0)
    blind = [name for name, s in zip(names, size) if not s > 1e-9 * max(size.max(), 1e-300)]
    if blind or dof < 1:
        raise InputError(f"the measured points do not constrain {', '.join(blind) or 'the fit'}"
                         f" ({n} residuals for {p} unknowns): they lie where C_f does not "
                         "depend on it (C_f,b in full film), or are too few; measure the "
                         "speeds where it acts")
    scale = np.array(bounds[1]) - np.array(bounds[0])      # unknowns of like size
    cov = covariance(sol.jac * scale, sol.fun, weighted) * np.outer(scale, scale)
    from scipy import stats
    half = stats.t.ppf(0.975, dof) * np.sqrt(np.diag(cov))
    out = {name: interval(v, h, lo, hi)
           for name, v, h, lo, hi in zip(names, sol.x, half, *bounds)}
    values, mus, share, resistance = unpack(sol.x)
    for k in range(len(measured)):
        t = out.get(f"temperature_{k + 1}")
        if t is not None:                       # viscosity falls as temperature rises
            mu = model.law.viscosity([t["value"], t["high"], t["low"]])
            out[f"viscosity_{k + 1}"] = {"value": float(mu[0]), "low": float(mu[1]),
                                         "high": float(mu[2])}
    rows, outside = [], 0
    for k, m in enumerate(measured):
        cf, inside = model.friction(k, m.speed, mus[k], values, share, resistance)
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
                  "correlation": correlation(cov).tolist(), "covariance": cov.tolist(),
                  "t_factor": float(stats.t.ppf(0.975, dof))}
    out["residuals"] = rows
    out["fit"]["warnings"] = temperature_warnings(model, out, len(measured))
    return out
