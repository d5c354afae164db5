"""Rolling-sliding kinematics: the flow factors when both rough surfaces move.

The pin (or ball) moves at ``u_1`` and the disk at ``u_2`` along x1: ``u_m = (u_1 +
u_2) / 2`` the entrainment speed, ``u_r = u_2 - u_1`` the sliding speed, ``SRR = u_r / u_m``
(2: the pin at rest, the paper's tribometer; 0: pure rolling).  The cell mean of a field
does not change when it translates over the periodic cell, so the laboratory's mean flux is
the pin frame's plus ``u_1 h_m e1``, and with the factors computed at SRR = 2

    b(SRR) = e1 + (SRR / 2) (b - e1),      d(SRR) = (SRR / 2) d,

while ``A``, ``C``, ``h_m``, ``p_con``, ``s_C`` and ``2 e1 - b`` do not depend on the speeds:
the micro stage runs once, at SRR = 2, for every SRR of the macro scale.  Eq 31's Couette
shear then vanishes in pure rolling, as the local shear ``mu u_r / h`` does.  The default
cell solves in the mean-speed frame, where the pure rolling cell's discretisation error
does not enter.  docs/rolling_sliding.md has the derivation and the measurements.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..checks import arguments, plausible
from ..errors import InputError
from .flow_factors import FlowFactors

#: the slide-to-roll ratio of the paper's cell: the pin at rest, the disk sliding over it
SLIDING = 2.0


def slide_to_roll_of(factors) -> float:
    """The SRR a :class:`~fem_twin.micro.FlowFactors` value was computed (or carried) at."""
    return float(factors.meta.get("slide_to_roll", SLIDING))


@arguments(factors=FlowFactors, slide_to_roll="number")
def at_slide_to_roll(factors, slide_to_roll: float):
    """``factors`` (a :class:`~fem_twin.micro.FlowFactors` at its own SRR, 2 unless its
    ``meta["slide_to_roll"]`` says otherwise) carried to ``slide_to_roll`` = u_r / u_m by
    the frame change of the module docstring: ``b -> e1 + k (b - e1)``, ``d -> k d`` with
    ``k = SRR_new / SRR_own``; the error-estimate variants likewise.  Smooth factors are
    unchanged."""
    plausible("slide_to_roll", slide_to_roll, "slide_to_roll")
    own = slide_to_roll_of(factors)
    if slide_to_roll == own:
        return factors
    if own == 0:
        raise InputError("flow factors of pure rolling (SRR 0) hold no sliding part: compute "
                         "them at SRR 2 (the pin at rest) to carry them to another SRR")
    k = slide_to_roll / own
    variants = {kind: {**arrays, **_moved(np.asarray(arrays["b"]), np.asarray(arrays["d"]), k,
                                          as_list=True)}
                for kind, arrays in factors.meta.get("variants", {}).items()}
    meta = {**factors.meta, "slide_to_roll": float(slide_to_roll)}
    if variants:
        meta["variants"] = variants
    return replace(factors, **_moved(factors.b, factors.d, k), meta=meta)


def _moved(b, d, k, as_list=False):
    e1 = np.array([1.0, 0.0])
    out = {"b": e1 + k * (b - e1), "d": k * d}
    return {n: v.tolist() for n, v in out.items()} if as_list else out
