"""Adaptive choice of the separations h0 at which the cell problems are solved.

The macro scale reads the flow factors between the computed separations by monotone cubic
interpolation in ``log h0`` (:meth:`FlowFactors.at`), so the separations are a subset of a
dense candidate set (default: the paper's 100 values): a coarse start bisected once, then,
while the interpolant through the other points misses a point by more than the relative
tolerance (leave one out), the gaps on either side of it are bisected, down to
neighbouring candidates.  The largest miss next to skipped candidates is the error
estimate (it overstates the final interpolant's error, by 2-4x).  Misses are relative to
the local value, floored at ``FLOOR`` times the largest magnitude; a miss within
``JITTER`` times the time-sampling error of the point or a neighbour
(:mod:`fem_twin.micro.estimate`) is not refined: in contact the factors jitter between
separations as pixels enter contact between instants, which is error of the time average,
not information (docs/accuracy.md, "Flow factors")."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .estimate import QUANTITIES
from .flow_factors import ARRAYS

#: separations of the coarse start (4 intervals: 9 points after the first bisection).
#: Measured on the paper case's six patch pairs (100 candidates, tol 0.01): 183 solved
#: against 191 with a start of 9, the same h0 bounds; the bisection adds the points where
#: the factors turn, so the start need only be dense enough not to step over a turn
#: (9 points over a decade: ratio 1.33)
START = 5
#: misses are relative to ``max(|f|, FLOOR max |f|)`` per quantity ...
FLOOR = 0.01
#: ... and for d1 to at least 1/3, its weight beside the sliding term of eq 31
#: (-6 u_m d + u_r e1 with u_r = 2 u_m on a pin-on-disk: 3 (1/3 - d))
SCALES = {"d1": 1.0 / 3.0}
#: a leave-one-out miss within this multiple of the points' time-sampling error is jitter:
#: the point is compared with its neighbours' interpolant, each with an error of its own
#: (independent errors e give misses up to about 3 e; the half-pass difference is >= e)
JITTER = 2.0


def adaptive_separations(h0, factors_at, tol: float, start: int = START,
                         quantities=tuple(QUANTITIES)):
    """Indices into the sorted candidates ``h0`` [m] where the factors are needed, for the
    ``quantities`` of :data:`~fem_twin.micro.estimate.QUANTITIES` watched.

    ``factors_at(indices)`` returns the :class:`FlowFactors` at ``h0[indices]`` (sorted
    indices; it computes what it does not hold yet) and those over every other instant
    (the time-error estimate; None when not available).  Returns ``(indices, estimate)``:
    the chosen sorted indices and ``{quantity: bound}``, the largest relative miss of the
    leave-one-out test over the chosen points next to skipped candidates."""
    if not 0 < tol < 1:
        raise InputError(f"the h0 tolerance is relative, in (0, 1); got {tol}")
    n = len(h0)
    chosen = sorted({int(i) for i in np.linspace(0, n - 1, min(start, n)).round()})
    chosen = sorted(set(chosen) | set(_midpoints(chosen, range(len(chosen)))))
    while True:
        misses = leave_one_out(*factors_at(chosen), quantities=quantities)
        worst = np.max(np.array(list(misses.values())), axis=0)
        new = set(_midpoints(chosen, np.flatnonzero(worst > tol) + 1))
        if not new:
            break
        chosen = sorted(set(chosen) | new)
    gaps = np.diff(chosen)
    open_ = np.maximum(gaps[:-1], gaps[1:]) > 1          # interior points next to a gap
    return chosen, {q: float(m[open_].max(initial=0.0)) for q, m in misses.items()}


def _midpoints(chosen, positions):
    """Midpoints of the gaps on either side of ``chosen[p]`` for ``p`` in ``positions``
    (a gap shared by two positions is listed twice)."""
    out = []
    for p in positions:
        for a, b in ((p - 1, p), (p, p + 1)):
            if 0 <= a and b < len(chosen) and chosen[b] - chosen[a] > 1:
                out.append((chosen[a] + chosen[b]) // 2)
    return out


def leave_one_out(full, half=None, quantities=tuple(QUANTITIES)) -> dict:
    """Relative miss per quantity at each interior point of ``full`` (a
    :class:`FlowFactors`) of the interpolant through all the others, ``|f - I f| /
    max(|f|, FLOOR max |f|)`` (for d1 at least 1/3), zero where it is within ``JITTER`` times the
    time-sampling error ``|f - f_half|`` of that point or a neighbour (``half``: the
    factors over every other instant; one point's estimate may be small by chance where its
    neighbours' are not), for the named ``quantities``."""
    inner = np.arange(1, len(full) - 1)
    local = [_without(full, k).at(full.h0[k:k + 1]) for k in inner]
    out = {}
    for name in quantities:
        get = QUANTITIES[name]
        f = get(full)[inner]
        miss = np.abs(f - np.concatenate([get(loc) for loc in local]))
        if half is not None:
            jitter = np.abs(get(full) - get(half))
            jitter = np.maximum(np.maximum(jitter[:-2], jitter[1:-1]), jitter[2:])
            miss = np.where(miss > JITTER * jitter, miss, 0.0)
        out[name] = _relative(name, miss, f, get(full))
    return out


def _relative(name, miss, f, over):
    floor = max(FLOOR * np.abs(over).max(), SCALES.get(name, 0.0))
    return miss / np.maximum(np.abs(f), floor) if floor > 0 else 0.0 * f


def _without(factors, k):
    keep = np.arange(len(factors)) != k
    return type(factors)(**{name: getattr(factors, name)[keep] for name in ARRAYS})
