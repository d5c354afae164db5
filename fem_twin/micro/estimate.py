"""A-posteriori estimates of the discretisation errors of flow factors (eqs 11-16).

Time: the result over ``N_t`` instants is compared with the pass of ``N_t / 2`` instants,
every other one.  With the exact squeeze term that is the same run's moments (no extra
solve): the time average is the trapezoidal rule of a periodic function, whose error falls
at least as fast as the roughness spectrum at the wavelength ``L_r1 / N_t``.  With the
paper's backward difference the even instants are solved again with the difference over
the doubled step (+50 % cell solves), since its error is the same at every instant and
sampling alone would not see it.  ``|f_N - f_{N/2}|`` estimates the error of ``f_N`` when
it falls at first order in ``1 / N_t`` and bounds it when faster.

Grid: the same problem on the cell coarsened by two (every other pixel, exact for a
periodic cell) at every separation, with half the instants (the same pixels per step),
against the pass of as many instants of the run itself (about an eighth of the run's
cost).  Coarsening a measured patch also drops its shortest wavelengths, and the flow factors then change at first order in the pixel size (measured on
the bundled patches), so ``|f_h - f_{2h}|`` estimates the error of ``f_h``; where they
converge at second order (a smooth or fully resolved surface) it is 3x the error.

Each estimate is normwise per quantity: the largest difference over the separations
relative to the largest magnitude over the range (``max |f - g| / max |f|``), so a factor
that vanishes at one end of the range (``A`` at percolation, ``p_con`` out of contact,
``d`` without roughness) is not judged by its relative error where it is negligible.

What the macro scale needs is the effect of these errors on the friction coefficient: the
estimate also keeps, per kind, the factors with that error added (:func:`variants`), which
the macro scale solves again (:mod:`fem_twin.macro.estimate`): ``"time"`` the factors over
every other instant, ``"grid"`` the factors plus the difference to the coarsened cell,
``"h0"`` the factors at every other computed separation (read by the interpolant between),
``"film_thin"`` and ``"film_thick"`` the friction factor with half and twice the boundary
film (the film friction's cut-off at contact edges, a model sensitivity rather than a
discretisation error, estimate kind ``"film"``; it moves only the friction, so the macro
scale re-evaluates the friction instead of solving again).
"""

from __future__ import annotations

from dataclasses import fields

import numpy as np

from ..errors import InputError

#: the quantities estimated, with how each is read from a FlowFactors
QUANTITIES = {"A11": lambda f: f.A[:, 0, 0], "A22": lambda f: f.A[:, 1, 1],
              "b1": lambda f: f.b[:, 0], "C11": lambda f: f.C[:, 0, 0],
              "d1": lambda f: f.d[:, 0], "sC": lambda f: f.friction_factor,
              "p_con": lambda f: f.p_con,
              "h_m": lambda f: f.h_m}
#: the quantities only the force on the pin reads (``[macro] friction = "pin"``)
FORCE_QUANTITIES = ("sC",)


def watched(friction: str) -> tuple:
    """The quantities whose interpolation error chooses the adaptive separations for a
    friction law (``"paper"``: eq 31's, which leaves the paper's sample as it was)."""
    return tuple(q for q in QUANTITIES if friction != "paper" or q not in FORCE_QUANTITIES)


#: the kinds of estimate, in the order of the variants
KINDS = ("time", "grid", "h0", "film")
#: the variants of the boundary film (half, twice), estimate kind "film"
FILM_VARIANTS = ("film_thin", "film_thick")


def discrepancy(fine, coarse) -> dict:
    """Normwise relative difference per quantity over the separations of ``coarse`` (both
    :class:`~fem_twin.micro.FlowFactors`; those of ``coarse`` among those of ``fine``)."""
    idx = np.searchsorted(fine.h0, coarse.h0)
    if np.any(idx >= fine.h0.size) or not np.allclose(fine.h0[idx], coarse.h0, rtol=1e-12):
        raise InputError("the coarse separations must be among the fine ones")
    out = {}
    for name, get in QUANTITIES.items():
        ref, other = get(fine), get(coarse)
        scale = np.abs(ref).max()
        out[name] = float(np.abs(ref[idx] - other).max() / scale) if scale > 0 else 0.0
    return out


def grid_separations(h0: np.ndarray, count: int = 3) -> np.ndarray:
    """The separations at which the grid error is estimated: smallest, middle, largest."""
    return np.unique(np.asarray(h0)[np.linspace(0, len(h0) - 1, count).round().astype(int)])


def variants(factors, half=None, grid=None, films=(None, None)) -> dict:
    """``{kind: {array: list}}``: ``factors`` (a :class:`FlowFactors`) with each estimated
    error added, as JSON-able arrays: ``half`` (the factors over every other instant),
    ``grid`` (the factors plus the coarsened cell's difference), ``films`` (the friction
    factor with half and twice the boundary film, :data:`FILM_VARIANTS`) and, from five
    separations on, the factors at every other separation (the ends kept)."""
    arrays = [f.name for f in fields(factors) if f.name != "meta"]     # h0 first
    out = {"time": half, "grid": grid, **dict(zip(FILM_VARIANTS, films))}
    if len(factors) >= 5:
        keep = sorted(set(range(0, len(factors), 2)) | {len(factors) - 1})
        out["h0"] = type(factors)(**{n: getattr(factors, n)[keep] for n in arrays})
    return {kind: {n: getattr(f, n).tolist() for n in arrays}
            for kind, f in out.items() if f is not None}


def combine(estimates) -> dict:
    """Estimate of a patch average: the largest error of its members, per quantity."""
    estimates = [e for e in estimates if e]
    if not estimates:
        return {}
    out = {}
    for kind in KINDS:
        parts = [e[kind] for e in estimates if kind in e]
        if parts:
            out[kind] = {q: max(p[q] for p in parts) for q in parts[0]}
    return out
