"""Traction curves: C_f versus the slide-to-roll ratio at one entrainment speed, the curve a
mini-traction machine (MTM) measures.

Each point is a mixed-lubrication operating point (:func:`fem_twin.macro.solve_mixed`) of a
ball on a disk at entrainment speed ``u_m`` and sliding speed ``u_r = SRR u_m``, with the
flow factors carried to that SRR (:mod:`fem_twin.micro.rolling`); the points warm-start from
one another (from the largest SRR down), are checkpointed like the Stribeck points, and
carry the estimate of their discretisation error (:mod:`fem_twin.macro.estimate`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..checks import check, plausible
from ..errors import InputError
from ..io.checkpoint import made_for
from ..io.figure import save_figure
from ..io.table import write_csv
from ..macro import solve_point
from ..macro.estimate import FILM, friction_error, is_current
from ..numerics.threads import one_thread
from .request import RollingSliding, SweepRequest
from .sweep import load_point, point_file

#: the CSV header of each column of ``traction.csv``: its name with the SI unit
HEADERS = {"slide_to_roll": "slide_to_roll", "sliding_speed": "sliding_speed_m_s",
           "entrainment": "entrainment_m_s", "viscosity": "viscosity_Pa_s",
           "friction_coefficient": "friction_coefficient", "friction_error": "cf_err",
           "film_sensitivity": "cf_film",
           "hydrodynamic_friction": "hydrodynamic_friction_N",
           "boundary_force": "boundary_force_N",
           "contact_load_fraction": "contact_load_fraction", "h_d": "h_d_m"}
#: the MTM's usual sweep: pure rolling to 100 % sliding (SRR = u_r / u_m)
DEFAULT_RATIOS = (0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0)


@dataclass(frozen=True, eq=False)
class TractionCurve:
    """C_f versus SRR at one entrainment speed ``entrainment`` [m/s] and viscosity mu_0
    [Pa s]; arrays over ``slide_to_roll`` (increasing): friction_coefficient [-] with its
    estimated discretisation error friction_error and its sensitivity to the boundary film
    film_sensitivity [-] (:mod:`fem_twin.macro.estimate`), the F_T parts
    hydrodynamic_friction and boundary_force [N], contact_load_fraction [-] and the
    separation h_d [m]."""

    slide_to_roll: np.ndarray
    entrainment: float
    viscosity: float
    friction_coefficient: np.ndarray
    friction_error: np.ndarray
    film_sensitivity: np.ndarray
    hydrodynamic_friction: np.ndarray
    boundary_force: np.ndarray
    contact_load_fraction: np.ndarray
    h_d: np.ndarray

    @property
    def sliding_speed(self) -> np.ndarray:
        """u_r = SRR u_m [m/s]."""
        return self.slide_to_roll * self.entrainment


@one_thread
def traction_sweep(request: SweepRequest, slide_to_roll=DEFAULT_RATIOS,
                   progress: bool = False) -> TractionCurve:
    """C_f at each slide-to-roll ratio (SRR in [0, 2]) of the ball-on-disk ``request``
    (:class:`~fem_twin.stribeck.request.RollingSliding`) at its one speed, the
    entrainment speed u_m [m/s]; every point is checkpointed in its ``checkpoint`` folder
    (keyed by all inputs, as :func:`~fem_twin.stribeck.stribeck_sweep`)."""
    check("traction_sweep: request", request, SweepRequest)
    ratios = np.unique(np.asarray(slide_to_roll, float))
    if ratios.size == 0 or np.any(~np.isfinite(ratios)):
        raise InputError(f"slide-to-roll ratios must be finite numbers, got {slide_to_roll}")
    plausible("slide-to-roll ratios", ratios, "slide_to_roll")
    if ratios[0] < 0:
        raise InputError(f"slide-to-roll ratios: a traction curve runs from pure rolling (0) "
                         f"up, the disk the slower surface; got {ratios[0]:g}")
    if not isinstance(request.motion, RollingSliding) or request.speeds.size != 1:
        raise InputError("a traction curve is a ball's (motion RollingSliding) at one "
                         f"entrainment speed, got {request.motion} at {request.speeds.size} "
                         "speeds")
    r, entrainment = request, float(request.speeds[0])
    key = r.key_with(("traction", entrainment))
    folder = None if r.checkpoint is None else Path(r.checkpoint)
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
    rolling = r.operating_point(entrainment)
    results, previous = {}, None
    for srr in tqdm(ratios[::-1], desc=f"traction mu0={r.lubricant.viscosity:g}",
                    disable=not progress, unit="point"):
        path = None if folder is None else point_file(folder, key, srr)
        res = None if path is None else load_point(path, key, srr)
        point = replace(rolling, speed=float(srr * entrainment))
        if res is None:
            res = solve_point(point, initial=previous)
        if not is_current(res.meta, r.settings):                       # new, or an older estimate
            res = replace(res, meta={**res.meta, "error_estimate": friction_error(res, point),
                                     **made_for(key, srr)})
            if path is not None:
                res.save(path)
        results[srr] = previous = res
    load, lubricant = r.face_load, r.lubricant
    get = lambda name: np.array([getattr(results[s], name) for s in ratios])  # noqa: E731
    return TractionCurve(
        slide_to_roll=ratios, entrainment=float(entrainment), viscosity=lubricant.viscosity,
        friction_coefficient=get("friction_coefficient"),
        friction_error=np.array([results[s].meta["error_estimate"]["total"] for s in ratios]),
        film_sensitivity=np.array([results[s].meta["error_estimate"].get(FILM, np.nan)
                                   for s in ratios]),
        hydrodynamic_friction=get("hydrodynamic_friction"),
        boundary_force=get("boundary_force"),
        contact_load_fraction=get("contact_load") / load, h_d=get("h_d"))


def write_traction_csv(path, curves) -> Path:
    """The traction curves, one row per (viscosity, SRR), SI units in the header."""
    cols = {HEADERS[name]: np.concatenate([np.broadcast_to(getattr(c, name),
                                                           c.slide_to_roll.shape)
                                           for c in curves])
            for name in HEADERS}
    return write_csv(path, cols)


def plot_traction(curves, path, labels=None):
    """C_f versus SRR [%] per curve, each point with its estimated discretisation error."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for i, c in enumerate(curves):
        label = labels[i] if labels else f"$\\mu_0$ = {c.viscosity:g} Pa s"
        ax.errorbar(100 * c.slide_to_roll, c.friction_coefficient, yerr=c.friction_error,
                    marker="o", ms=4, capsize=2, label=label)
    ax.set_xlabel("slide-to-roll ratio SRR = $u_r / u_m$ [%]")
    ax.set_ylabel("traction coefficient $C_f$ [-]")
    ax.set_title(f"traction at $u_m$ = {curves[0].entrainment:g} m/s")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    return save_figure(fig, path)
