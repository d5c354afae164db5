"""How accurate a computed Stribeck curve is: its points' estimated C_f errors, summarised.

Each point of a sweep run with ``error_estimate=True`` carries the estimated discretisation
error of its friction coefficient (:mod:`fem_twin.macro.estimate`): its parts (macro grid;
the flow factors' time, grid and h0 sampling), their sum with signs (the estimate) and of
magnitudes (the bound, ``cf_err``), and beside them C_f's sensitivity to the boundary film.
Here they are put relative to the boundary friction coefficient C_f,b, the scale of eq 35's
deviations, and the points above a tolerance are named.  :func:`range_summary` checks what
the estimate cannot see: contact carried at separations below the micro scale's range,
where p_con is extrapolated."""

from __future__ import annotations

import logging

import numpy as np

from ..macro.estimate import PARTS

log = logging.getLogger("fem_twin")


#: where a case sets its macro grid: a pin's from its maps, a ball's on its own
MACRO_GRID_KEYS = {False: "[preprocessing] resolution", True: "[macro] grid"}


def error_summary(curves, boundary_friction: float, tolerance: float,
                  ball: bool = False) -> dict:
    """The largest estimated C_f error of ``curves`` over C_f,b: the signed estimate, the
    bound ``cf_err`` and its parts, and the film's sensitivity (a model part no refinement
    reduces).  Points whose signed estimate exceeds ``tolerance`` (a fraction of C_f,b; the
    bound where a curve has no signed estimate) are logged in a warning naming the worst
    and the keys to refine (``ball``: its macro grid's); those where the bound alone does,
    in an info line."""
    def largest(values):
        values = np.abs(np.concatenate(values)) / boundary_friction
        return float(np.nanmax(values)) if np.isfinite(values).any() else float("nan")

    def over(get):
        return [(abs(e) / boundary_friction, c.viscosity, u) for c in curves
                for u, e in zip(c.speed, get(c)) if abs(e) > tolerance * boundary_friction]

    points = sum(c.speed.size for c in curves)
    above = over(lambda c: c.friction_error if c.friction_error_signed is None
                 else c.friction_error_signed)
    bound = over(lambda c: c.friction_error)
    if above:
        worst = max(above)
        log.warning("C_f: estimated discretisation error above %.2g %% of C_f,b at %d of %d "
                    "points (largest %.2f %% at mu_0 = %g Pa s, U = %.3g m/s; its parts in "
                    "summary.json): refine %s (the macro grid) or [micro] resolution, "
                    "steps or h0_count", 100 * tolerance, len(above), points,
                    100 * worst[0], worst[1], worst[2], MACRO_GRID_KEYS[ball])
    if len(bound) > len(above):
        log.info("C_f: the error bound cf_err exceeds %.2g %% of C_f,b at %d of %d points "
                 "where its parts' signs leave the estimate below it", 100 * tolerance,
                 len(bound) - len(above), points)
    signed = [c.friction_error_signed for c in curves if c.friction_error_signed is not None]
    films = [c.film_sensitivity for c in curves if c.film_sensitivity is not None]
    return {"max_relative": largest([c.friction_error for c in curves]),
            "max_signed_relative": largest(signed) if signed else float("nan"),
            "parts_max_relative": {part: largest([c.friction_error_parts[part]
                                                  for c in curves]) for part in PARTS},
            "film_max_relative": largest(films) if films else float("nan"),
            "tolerance": tolerance, "points_above": len(above),
            "bound_points_above": len(bound)}


#: the share of a point's load that may be carried by extrapolated contact pressure (h0
#: below the micro scale's smallest separation) before the run warns
EXTRAPOLATED_LOAD = 0.01


def range_summary(shares, h0_min: float) -> dict:
    """The largest share of the load carried where h0 < ``h0_min`` [m] over the points'
    ``shares`` (an iterable of ``(share, label)``: the main curves' and the band's points,
    :meth:`~fem_twin.macro.MixedResult.contact_load_below`), with a logged warning naming
    the worst point when it exceeds :data:`EXTRAPOLATED_LOAD`: below its range
    :meth:`FlowFactors.at` continues p_con linearly, which no error estimate covers."""
    shares = list(shares)
    worst, where = max(shares, default=(0.0, ""))
    above = sum(share > EXTRAPOLATED_LOAD for share, _ in shares)
    if above:
        log.warning("C_f: %d of %d points carry more than %.2g %% of their load at separations "
                    "below [micro] h0_min = %.3g m (largest %.1f %% at %s), where p_con is "
                    "extrapolated: lower h0_min", above, len(shares), 100 * EXTRAPOLATED_LOAD,
                    h0_min, 100 * worst, where)
    return {"h0_min_m": float(h0_min), "max_load_share_below": float(worst),
            "worst_point": where, "tolerance": EXTRAPOLATED_LOAD, "points": len(shares),
            "points_above": int(above)}


def error_clause(err: dict) -> str:
    """The largest error of an :func:`error_summary` ``err``: the signed estimate's and the
    bound's (``cf_err``, whose parts follow it in the summary line and report)."""
    signed = err.get("max_signed_relative", float("nan"))
    estimate = f"at most {signed:.2%} of C_f,b, " if np.isfinite(signed) else ""
    return f"{estimate}its bound cf_err at most {err['max_relative']:.2%} of C_f,b"


def film_clause(err: dict) -> str:
    """The clause on the largest sensitivity to the boundary film of an
    :func:`error_summary` ``err``, for the run's summary line and report ("" without)."""
    film = err.get("film_max_relative", float("nan"))
    if not np.isfinite(film):
        return ""
    return (f"; the boundary film's model sensitivity (cf_film, not in cf_err) at most "
            f"{film:.2%} of C_f,b")
