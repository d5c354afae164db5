"""The discretisation error of an operating point's friction coefficient C_f (eq 34).

Both scales contribute, and each part is a change of C_f [-]:

``"macro"``
    the point solved again on the macro grid coarsened by two (every other node; the face
    mask likewise), warm-started from the converged state:
    ``|C_f(h) - C_f(2h)| / (2^p - 1)`` with ``p = MACRO_ORDER``.  The Couette flux and the
    Poiseuille term are second order (:mod:`.couette`), so with ``p = 1.5`` the estimate is
    1 to 3 times the error wherever the observed order lies between 1.5 and 2.6.
``"time"``, ``"grid"``, ``"h0"``
    the flow factors' own error estimates carried into C_f: the point solved with each
    variant of the factors (:meth:`FlowFactors.variants`: every other instant, the
    coarsened cell's difference added, every other separation), on the coarse grid and
    warm from the coarse point, minus the coarse point.  The sensitivity of C_f to the
    factors needs no finer grid than that: the coarse grid changes C_f itself by a few
    tenths of a per cent of C_f,b.  The ``"h0"`` variant's interpolation error is that of
    twice the spacing, ``H0_SPACING_RATIO`` times the error of the computed sample.

``"total"`` is the sum of the parts' magnitudes: their root sum of squares (independent
errors of unknown sign), tried on 2026-11-26, fell to 0.62-0.87 of the truth on the
paper-grade patch pair in heavy contact, where the parts' errors add with one sign
(``benchmarks/README.md``). ``"signed"`` keeps each part with its sign as an estimate of
``C_f - C_f,converged`` (macro: ``(C_f(2h) - C_f(h)) / (2^p - 1)``; the others: the
variant's change, which is the error of the run's own factors where they converge at first
order), kept for studies of how the parts combine; the total does not use it, as the signs
are reliable only in the asymptotic range. A part that could not be estimated is NaN, left
out of the total and named in ``"missing"`` (factors computed without their error
estimate), with the reason in ``"failed"`` when its solve did not converge. Smooth factors
have no micro parts (0).
"""

from __future__ import annotations

import numpy as np

from ..errors import MixedNotConverged
from .mixed import solve_mixed
from .nested import coarsened

#: the order assumed in ``|C_f(h) - C_f(2h)| / (2^p - 1)``.  The scheme's is 2 (bundled
#: pin at 0.03 m/s: 1.97, 1.95 on 128 -> 255 -> 509 -> 1017 px refined in place), but
#: between grids resampled from the measured pin the face edge moves by a pixel, and the
#: mixed regime converges at order 0.8-1.15 from 64 to 128 px.  With 1.5 the bundled
#: case's macro part is 1.2-2.5 times its change to a 256 px run (mixed regime) and
#: 1.2-1.7 times it in full film.
MACRO_ORDER = 1.5
#: the C_f change of the interpolant through every other separation over the error of the
#: whole sample: 4, as for factors smooth in log h0 (:mod:`fem_twin.micro.sampling`).
#: Measured on the bundled case (16 h0 against 61, which is within 0.03 % C_f,b of 31): the
#: h0 part is 1.1-2.0 times the h0 error wherever that exceeds 0.2 % C_f,b (4.9 times at
#: one point where it is 0.11 %)
H0_SPACING_RATIO = 4.0
#: the parts of an estimate, in the order of the CSV and NetCDF outputs
PARTS = ("macro", "time", "grid", "h0")


def friction_error(result, gap, spacing, factors, *, load: float, lubricant, face=None,
                   settings, entrainment: float | None = None, coarse=None) -> dict:
    """Estimated discretisation error of ``result.friction_coefficient`` per part and in
    total (see the module docstring), for the point ``result`` that
    :func:`~fem_twin.macro.solve_mixed` returned for these arguments; ``coarse``: the same
    point already solved on the coarsened grid (:func:`.nested.solve_nested`'s), which is
    then not solved again."""
    face = np.ones(np.shape(gap), bool) if face is None else face
    gap2, spacing2, face2 = coarsened(gap, spacing, face)
    common = dict(load=load, speed=result.speed, entrainment=entrainment,
                  lubricant=lubricant, face=face2, settings=settings)
    out, failed = {}, []
    try:
        base = coarse or solve_mixed(gap2, spacing2, factors, initial=result, **common)
    except MixedNotConverged as err:
        return {**{part: np.nan for part in PARTS}, "total": np.nan,
                "failed": [f"coarse grid: {err.args[0]}"]}
    cf = base.friction_coefficient
    signed = {"macro": (cf - result.friction_coefficient) / (2 ** MACRO_ORDER - 1)}
    for kind, variant in factors.variants().items():
        try:
            moved = solve_mixed(gap2, spacing2, variant, initial=base, **common)
        except MixedNotConverged as err:
            out[kind] = np.nan
            failed.append(f"{kind}: {err.args[0]}")
            continue
        signed[kind] = (moved.friction_coefficient - cf) / (
            H0_SPACING_RATIO if kind == "h0" else 1.0)
    smooth = factors.meta.get("smooth", False)              # no roughness: no micro error
    for kind in set(PARTS) - set(signed):
        signed[kind] = out.get(kind, 0.0 if smooth else np.nan)
    out = {part: abs(float(signed[part])) for part in PARTS}
    out["total"] = float(np.nansum(list(out.values())))
    out["signed"] = {part: float(signed[part]) for part in PARTS}
    missing = [part for part in PARTS if np.isnan(out[part])]
    if missing:
        out["missing"] = missing
    if failed:
        out["failed"] = failed
    return out
