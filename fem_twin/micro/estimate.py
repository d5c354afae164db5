"""A-posteriori estimates of the discretisation errors of flow factors (eqs 11-16).

Time: the result over ``N_t`` instants against the pass of every other instant (the same
run's moments; the paper's backward difference solves the even instants again over the
doubled step): ``|f_N - f_{N/2}|`` estimates the error of ``f_N`` at first order and bounds
it when faster.  Grid: the cell coarsened by two with half the instants, against the pass
of as many instants of the run (a sixth of the cells' CPU on the bundled cases); a
measured patch's factors change at first order in the pixel size, so ``|f_h - f_{2h}|``
estimates the error of ``f_h``.  Each estimate is normwise per quantity (``max |f - g| /
max |f|`` over the separations).  For the macro scale (:mod:`fem_twin.macro.estimate`)
:func:`variants` keeps the factors with each error added: ``"time"``, ``"grid"``, ``"h0"``
(every other separation) and ``"film_thin"``/``"film_thick"`` (the friction factor at half
and twice the boundary film, a model sensitivity; docs/accuracy.md)."""

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
