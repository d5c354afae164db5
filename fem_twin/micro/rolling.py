"""Rolling-sliding kinematics: the flow factors when both rough surfaces move.

The pin (or ball, the lower surface) moves at ``u_1`` and the disk at ``u_2`` along x1;
``u_m = (u_1 + u_2) / 2`` is the entrainment speed, ``u_r = u_2 - u_1`` the sliding speed
and ``SRR = u_r / u_m`` the slide-to-roll ratio (the mini-traction machine's convention; 2:
the pin at rest, the paper's tribometer; 0: pure rolling).

Derivation.  The local flux is ``q = -h^3 grad p / (12 mu) + u_m h e1`` and the Reynolds
equation ``div q + dh/dt = 0``.  In the pin's frame (``x' = x1 - u_1 t``) the pin is at rest
and the disk slides at ``u_r``; the equation keeps its form with ``u_m' = u_r / 2`` and
``q' = q - u_1 h e1``, and that is the problem the paper's cell solves (eqs 8-16): its cell
average is ``<q'> = -A h_m^3 grad p / (12 mu) + (u_r / 2) h_m b``.  The cell mean of a field
does not change when the field translates over the periodic cell, so in the laboratory

    <q> = <q'> + u_1 h_m e1 = -A h_m^3 grad p / (12 mu)
          + u_m h_m e1 + (u_r / 2) h_m (b - e1).

The entrainment speed's Couette factor is exactly ``e1``; the sliding speed carries
``b - e1``, the shear flow factor of Patir and Cheng (1979) in homogenised form.  Per
surface: ``u_m h_m b(SRR) = u_1 h_m (e1 - b/2) + u_2 h_m b/2``.  The pressure fluctuation is
the same field seen from either frame, ``u_m chi_1(SRR) = (u_r / 2) chi_1``, so eq 16's
``d(SRR) = (SRR / 2) d``, and ``A``, ``C``, ``h_m``, ``p_con`` do not depend on the speeds.
In eq 17's form (``u_m`` times the Couette factor), with the factors at SRR = 2:

    b(SRR) = e1 + (SRR / 2) (b - e1),      d(SRR) = (SRR / 2) d,

and eq 31's Couette shear on the pin, ``(mu / h_m) (-6 u_m d(SRR) + u_r)``, becomes
``(mu u_r / h_m) (1 - 3 d_1)``: it vanishes in pure rolling, as the local shear
``mu u_r / h`` does.

The cell with both surfaces moving (:class:`~fem_twin.micro.CellSettings`'s
``slide_to_roll``, :func:`~fem_twin.micro.sliding.sliding_pass`) solves eq 8 in the
laboratory with the squeeze term of both translations.  Its factors are linear in the two
speeds, ``b(SRR) = (1 - SRR/2) b_0 + (SRR/2) b``, with ``b_0`` the pure rolling cell, which
is ``e1`` exactly and to the spatial discretisation error in the cell (its Couette term and
the central difference of the squeeze term differ at second order).  :func:`at_slide_to_roll`
uses the exact ``e1``, so the micro stage runs once, at SRR = 2, for every SRR of the
macro scale.

The pure rolling cell's ``b_0 - e1`` and ``d_0`` are a discretisation error of the pin's
frame, and at the edges of contact spots a large one.  The default cell therefore solves in
the mean-speed frame (:mod:`.sliding`, ``moving="both"``), whose factors are
``b - b_0 + e1`` and ``d - d_0`` of the pin's frame by the same linearity.  Measured on a
64^2 random pair (Sq 0.14 um) refined by periodic bilinear resampling, 32 instants, d1:

=======  ========  =====================  =====================
h0       contact   pin's frame FE / FVM   mean-speed frame FE / FVM
=======  ========  =====================  =====================
0.2 um   3 %       0.202 / 0.274 (64^2)   0.155 / 0.150 (64^2)
                   0.173 / 0.232 (128^2)  0.160 / 0.149 (128^2)
                   0.154 / 0.181 (256^2)  0.153 / 0.149 (256^2)
0.1 um   14 %      0.267 / 0.438 (64^2)   0.185 / 0.164 (64^2)
                   0.195 / 0.313 (128^2)  0.162 / 0.149 (128^2)
                   0.178 / 0.228 (256^2)  0.161 / 0.156 (256^2)
=======  ========  =====================  =====================
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
