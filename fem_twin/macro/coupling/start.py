"""Cold starts of the macro iteration: the rigid separations that begin it (eqs 28-30).

Before any elastic deformation is known the load balance is solved on the rigid gap:
:func:`dry_separation` (contact alone) and :func:`rigid_separation` (film and contact, the
Anderson and PID couplings; the Newton coupling's start is :func:`.newton.rigid_start`).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from ...errors import MixedNotConverged


def dry_separation(factors, h_g, area, load, s):
    """h_d at which the rigid contact alone carries the load (Brent), or at which the
    surfaces touch (``h0 = gap_floor``) if the contact pressure cannot carry it."""
    def excess(h_d):
        p = factors.contact_pressure(np.maximum(h_d + h_g, s.gap_floor))
        return float(np.sum(area * p)) - load

    touch = s.gap_floor - float(h_g.min())
    hi = float(factors.h0[-1]) - float(h_g.min())       # first contact at h0_max
    if excess(hi) >= 0:
        return hi
    if excess(touch) < 0:
        return touch
    return brentq(excess, touch, hi, xtol=1e-18)


def rigid_separation(excess, h_free, h_dry, step, rtol=1e-3):
    """h_d at which the rigid, isoviscous film and contact carry the load: the start.

    ``excess(h_d) = F_N - F_N,imp`` decreases with ``h_d``.  The search starts at
    ``h_free`` (first asperity contact) and brackets the root by doubling steps upward (a
    lifting film) or by halving the distance to the dry separation ``h_dry`` (mixed
    regime), then refines it by Brent's method to ``rtol`` of ``max(h_d, step)``.
    """
    lo, f_lo, hi, f_hi = _bracket(excess, h_free, h_dry, step)
    if f_hi == 0 or f_lo <= 0:       # a root at the bracket, or none above the dry state
        return hi if f_hi == 0 else lo
    known = {lo: f_lo, hi: f_hi}               # Brent starts by evaluating the bracket

    def f(h_d):
        return known.pop(h_d) if h_d in known else excess(h_d)

    return brentq(f, lo, hi, xtol=rtol * step, rtol=rtol)


def _bracket(excess, h_free, h_dry, step):
    """``(lo, f_lo, hi, f_hi)`` with ``f_lo > 0 >= f_hi`` (see :func:`rigid_separation`)."""
    f_free = excess(h_free)
    if f_free <= 0:
        hi, f_hi, lo = h_free, f_free, h_dry
        for _ in range(30):                      # approach the dry state from above
            mid = (hi + lo) / 2
            f_mid = excess(mid)
            if f_mid > 0:
                return mid, f_mid, hi, f_hi
            hi, f_hi = mid, f_mid
        return h_dry, excess(h_dry), hi, f_hi
    lo, f_lo = h_free, f_free
    hi, f_hi = lo + step, excess(lo + step)
    while f_hi > 0:
        lo, f_lo = hi, f_hi
        step *= 2
        if step > 1e-3:
            raise MixedNotConverged("no separation below 1 mm balances the load", [])
        hi, f_hi = lo + step, excess(lo + step)
    return lo, f_lo, hi, f_hi
