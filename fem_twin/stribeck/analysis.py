"""Analysis of Stribeck curves: the patch scatter band (Figure 13), the speeds where a curve
turns (for refinement), the Hersey collapse of curves at several viscosities (eq 46) and
the knee, where the asperities carry half the load."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..checks import arguments
from ..errors import InputError
from .curve import StribeckCurve, friction_deviation


@arguments(patch_curves=[[StribeckCurve]])
def patch_band(patch_curves) -> list:
    """(cf_min, cf_max) per lubricant over single-patch curves [patch][lubricant]."""
    cf = np.array([[c.friction_coefficient for c in per_mu] for per_mu in patch_curves])
    return [(cf[:, k].min(axis=0), cf[:, k].max(axis=0)) for k in range(cf.shape[1])]


@arguments(patch_curves=[[StribeckCurve]], fine=[StribeckCurve], coarse=[StribeckCurve])
def defect_corrected(patch_curves, fine, coarse) -> list:
    """Single-patch curves swept on a coarsened macro grid H, each brought to the fine grid
    h by the average curve's relative grid change: ``C_f,i(h) ~ C_f,i(H) C_f(h) / C_f(H)``
    (``fine`` and ``coarse`` are the average-factor curves per lubricant on the two grids,
    at the patch curves' speeds).  Relative, because the patches' grid errors scale with
    their C_f: against the band swept on the full grid it leaves about half the error of
    adding the average's change ``C_f(h) - C_f(H)`` (docs/accuracy.md).  Only C_f is
    corrected: the band (:func:`patch_band`) reads nothing else."""
    out = []
    for per_mu in patch_curves:
        out.append([replace(c, friction_coefficient=c.friction_coefficient
                            * f.friction_coefficient / g.friction_coefficient)
                    for c, f, g in zip(per_mu, fine, coarse, strict=True)])
    return out


@arguments(curves=[StribeckCurve], step="number")
def transition_speeds(curves, step: float) -> np.ndarray:
    """Geometric midpoints of neighbouring speeds between which C_f of any curve changes by
    more than ``step`` (where the Stribeck curve turns, from full film to boundary)."""
    extra = []
    for c in curves:
        order = np.argsort(c.speed)
        u, cf = c.speed[order], c.friction_coefficient[order]
        jump = np.abs(np.diff(cf)) > step
        extra.extend(np.sqrt(u[:-1] * u[1:])[jump])
    return np.unique(np.round(extra, 12))


@arguments(curves=[StribeckCurve], boundary_friction="number")
def hersey_collapse(curves, boundary_friction: float) -> float:
    """``max |C_f,dev|`` (eq 35, relative to ``boundary_friction`` = C_f,b) between the first curve
    and the others over the Hersey numbers where they overlap (the others' points, interpolated
    on the first curve)."""
    ref = curves[0]
    devs = []
    for c in curves[1:]:
        cf_ref = ref.at_hersey(c.hersey)
        ok = np.isfinite(cf_ref)
        devs.extend(np.abs(friction_deviation(c.friction_coefficient[ok], cf_ref[ok],
                                              boundary_friction)))
    return float(max(devs)) if devs else float("nan")


#: the asperity share of the load that marks a curve's knee (:func:`knee_speed`)
KNEE_SHARE = 0.5


@arguments(curve=StribeckCurve, share="number")
def knee_speed(curve, share: float = KNEE_SHARE) -> float:
    """The sliding speed [m/s] where the asperities carry ``share`` of the load
    (``contact_load_fraction``), linear in log speed between the points around it; NaN
    where the curve does not cross it."""
    if not 0 < share < 1:
        raise InputError(f"knee_speed: share is a fraction of the load in (0, 1), got {share}")
    order = np.argsort(curve.speed)
    u, s = np.log(curve.speed[order]), np.asarray(curve.contact_load_fraction)[order] - share
    cross = np.flatnonzero((s[:-1] >= 0) & (s[1:] < 0))
    if not cross.size:
        return float("nan")
    i = cross[-1]
    return float(np.exp(u[i] + (u[i + 1] - u[i]) * s[i] / (s[i] - s[i + 1])))
