"""The statistics of a least-squares fit (:mod:`.fit`): 95 % intervals clipped to the
parameters' bounds, the parameters' covariance and correlation, and the warnings on
fitted contact temperatures."""

from __future__ import annotations

import numpy as np

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
