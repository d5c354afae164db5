"""What measured curves can tell apart: the shear law's tau_0 and alpha (docs/model.md,
"Boundary friction").

The law's force is ``(tau_0 A_r + alpha W) s = W (alpha + tau_0 / p_r) s`` with ``p_r = W /
A_r`` the asperities' mean real pressure.  Where p_r hardly changes over the measured
points (a resolved contact's real pressure is nearly independent of the load), only
``alpha + tau_0 / p_r`` is identified.  :func:`separability` solves the linear problem of
the two at the measured points, the film friction and the other parameters at their
start values, from the twin's own real area and asperity load there: the spread of p_r,
the two's correlation and 95 % intervals, and the identifiable ``alpha_eff``."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..macro.laws.boundary_laws import fitted_law

#: the shear law's pair that one Stribeck curve set may not separate
PAIR = ("shear_strength", "pressure_coefficient")


def separability(model, measured, viscosities, sigma) -> dict:
    """The identifiability of tau_0 and alpha (module docstring) at the ``measured`` points
    (inside the simulated speeds) of ``model`` (a :class:`.fit.FitModel`) for the curves'
    oils of ``viscosities`` [Pa s], weighted by the measured scatter ``sigma`` per curve
    (None: equal weights, the residuals' variance): ``real_pressure`` min, mean and max
    [Pa], ``correlation``, ``intervals`` (95 %, per name) and ``alpha_eff`` [-] with the
    ``mean`` p_r it holds at."""
    base = fitted_law(PAIR).start(model.section, model.boundary_friction)
    cols, rhs, weights = [], [], []
    for k, (m, mu) in enumerate(zip(measured, viscosities)):
        c, load = model.curves[k], model.loads[k] if model.loads else model.load
        at, _ = model.reader(c, m.speed, mu)
        s = base.speed_factor(m.speed) / load
        cols.append(np.column_stack([at(c.real_contact_area) * s, at(c.asperity_load) * s]))
        rhs.append(m.friction_coefficient - at(c.hydrodynamic_friction) / load)
        weights.append(np.ones(m.speed.size) if sigma[k] is None else 1 / sigma[k])
    J, y, w = np.vstack(cols), np.concatenate(rhs), np.concatenate(weights)
    area, force = J[:, 0], J[:, 1]
    touching = area > 0
    if touching.sum() < 3:
        raise InputError("tau_0 and alpha: fewer than three measured points where the twin's "
                         "asperities touch; measure the slow end, or fit one of them")
    pressure = force[touching] / area[touching]
    x, *_ = np.linalg.lstsq(J * w[:, None], y * w, rcond=None)
    dof = y.size - 2
    inv = np.linalg.pinv((J * w[:, None]).T @ (J * w[:, None]))
    scale = 1.0 if all(v is not None for v in sigma) else float(
        np.sum((w * (y - J @ x)) ** 2) / max(dof, 1))
    from scipy import stats
    half = stats.t.ppf(0.975, max(dof, 1)) * np.sqrt(np.diag(inv) * scale)
    corr = float(inv[0, 1] / np.sqrt(inv[0, 0] * inv[1, 1]))
    mean = float(force.sum() / area.sum())
    alpha_eff = float(np.sum(w * w * force * y) / np.sum((w * force) ** 2))
    return {"real_pressure": [float(pressure.min()), mean, float(pressure.max())],
            "correlation": corr, "alpha_eff": alpha_eff,
            "intervals": {n: [float(v - h), float(v + h)] for n, v, h in zip(PAIR, x, half)}}


def check_separable(found: dict) -> None:
    """Refuse tau_0 and alpha together where the data do not tell them apart: the 95 %
    interval of either reaches 0 (``found``: :func:`separability`), naming the identifiable
    ``alpha + tau_0 / p_r`` and how to fit it."""
    low, mean, high = (p / 1e9 for p in found["real_pressure"])
    reach = [f"{n} {lo:.3g} to {hi:.3g}" for n, (lo, hi) in found["intervals"].items()
             if lo <= 0]
    if reach:
        raise InputError(
            f"shear_strength and pressure_coefficient cannot be told apart by these curves: "
            f"the twin's mean real pressure p_r = W / A_r runs only from {low:.3g} to "
            f"{high:.3g} GPa over the measured points, their correlation is "
            f"{found['correlation']:.4f} and the 95 % interval reaches 0 ("
            + "; ".join(reach) + f"). The data identify alpha + tau_0 / p_r = "
            f"{found['alpha_eff']:.4g} at p_r = {mean:.3g} GPa: fit pressure_coefficient "
            "alone with [boundary] shear_strength = 0, which then carries it")


def check_pair(model, measured, params, viscosities, sigma) -> dict:
    """Where ``params`` fit tau_0 and alpha together: their :func:`separability`, refused
    unless separable (:func:`check_separable`), as ``{"identifiability": ...}`` for the
    fit's record; else nothing."""
    if not set(PAIR) <= set(params):
        return {}
    found = separability(model, measured, viscosities, sigma)
    check_separable(found)
    return {"identifiability": found}
