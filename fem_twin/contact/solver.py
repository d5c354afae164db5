"""Dry elastic-perfectly-plastic contact on the regular grid by CG-FFT (paper 2.2.1).

Polonsky & Keer (1999) conjugate gradients with the pressure bounded to ``[p_min, H]``
(hardness cap, Sainsot & Lubrecht); imposed load (the separation is the Lagrange
multiplier of the load constraint) or imposed rigid-body separation (Rey et al. 2017 /
Akchurin et al. 2015 variant without the load constraint).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..checks import as_field, as_pair, plausible
from ..errors import InputError, NotConverged
from .elastic import elastic_operator

_REFRESH = 16          # CG iterations between exact deformations K p (round-off drift)


class ContactNotConverged(NotConverged):
    """The CG-FFT iteration did not reach the tolerance; ``history`` holds the residuals."""


@dataclass(frozen=True, eq=False)
class ContactResult:
    """Converged dry contact state (SI units, arrays shaped like the grid).

    pressure : contact pressure [Pa] in ``[p_min, H]``
    deformation : elastic normal deformation K p [m] (opens the gap)
    gap : deformed gap ``separation + shape + deformation`` truncated below ``gap_floor`` [m]
    raw_gap : the same without truncation (negative where plastically interpenetrating)
    separation : rigid-body separation h0 [m]
    load : ``sum(pressure) dx1 dx2`` [N]
    contact_fraction, plastic_fraction : area fractions with p > p_min and p = H
    iterations, history : CG iterations and relative residual per iteration
    """

    pressure: np.ndarray
    deformation: np.ndarray
    gap: np.ndarray
    raw_gap: np.ndarray
    separation: float
    load: float
    contact_fraction: float
    plastic_fraction: float
    iterations: int
    history: tuple


#: the largest height range [m] of a contact's shape: a pin on its holder, 1 mm below
#: the face, is 1e-3; micrometres typed as metres land far above
MAX_RISE = 1e-2


def solve(shape, spacing, e_reduced, *, load=None, separation=None, hardness=np.inf,
          periodic=False, p_min=0.0, gap_floor=1e-9, initial_pressure=None, tol=1e-10,
          max_iter=2000) -> ContactResult:
    """Dry contact of a rigid-body ``shape`` [m] (ny, nx; x1 along the columns) against an
    elastic half-space of E' ``e_reduced`` [Pa] (eq 22) on a grid of ``spacing`` [m].

    Exactly one of ``load`` [N] and ``separation`` h0 [m]; ``hardness`` H caps the pressure
    [Pa] (inf: elastic), ``p_min`` floors it [Pa]; ``periodic``: a roughness cell; the
    deformed gap reported floored at ``gap_floor`` [m]; ``initial_pressure`` warm-starts;
    converged at a relative pressure change ``tol``.  The gap is ``separation + shape + K p``
    with KKT: ``p = p_min`` where it is open, 0 where ``p_min < p < H``, <= 0 at ``p = H``.
    Under a load: Polonsky-Keer's load-constrained CG with the cap, else (no convergence or
    a missed load) a bracketed root search (Brent) on the load of separation-controlled
    solves.  An iteration costs one or two single-precision FFT pairs on the loaded points
    (an exact double pair every ``_REFRESH``), against two double pairs in the textbook.
    """
    rise = float(np.ptp(as_field("shape [m]", shape)))
    if rise > MAX_RISE:
        raise InputError(f"shape [m]: its height range {rise:.3g} m is above {MAX_RISE:g} m: "
                         "heights must be given in metres (1 um is 1e-6)")
    plausible("spacing [m]", as_pair("spacing [m]", spacing), "pitch")
    plausible("reduced modulus e_reduced [Pa]", e_reduced, "reduced_modulus")
    if np.isfinite(hardness):                          # inf: purely elastic
        plausible("hardness [Pa]", hardness, "hardness")
    kw = dict(hardness=hardness, periodic=periodic, p_min=p_min, gap_floor=gap_floor,
              tol=tol, max_iter=max_iter)
    if load is not None and np.isfinite(hardness) and separation is None:
        try:                            # Polonsky-Keer with the cap (one CG, usually enough)
            r = _cg(shape, spacing, e_reduced, load=load, separation=None,
                    initial_pressure=initial_pressure, **kw)
            if abs(r.load / load - 1) < 1e-8:
                return r
        except ContactNotConverged:
            pass                        # a cycling plastic set: the safe route below
        return _solve_load_by_separation(shape, spacing, e_reduced, load, initial_pressure, kw)
    return _cg(shape, spacing, e_reduced, load=load, separation=separation,
               initial_pressure=initial_pressure, **kw)


def _solve_load_by_separation(shape, spacing, e_reduced, load, initial_pressure, kw):
    s = np.asarray(shape, dtype=float)
    elastic = _cg(s, spacing, e_reduced, load=load, separation=None,
                  initial_pressure=initial_pressure, **{**kw, "hardness": np.inf})
    if elastic.pressure.max() <= kw["hardness"]:
        return _cg(s, spacing, e_reduced, load=None, separation=elastic.separation,
                   initial_pressure=elastic.pressure, **kw)
    state = {"p": np.minimum(elastic.pressure, kw["hardness"]), "calls": 0, "result": None}
    history = []

    def excess(h0):
        r = _cg(s, spacing, e_reduced, load=None, separation=h0, initial_pressure=state["p"], **kw)
        state.update(result=r, calls=state["calls"] + r.iterations)
        if r.load > 0:                              # warm start only from a loaded state
            state["p"] = r.pressure
        history.append(r.load / load - 1)
        return r.load / load - 1

    hi = -s.min()                                   # no overlap: no load
    lo, step = elastic.separation, max(hi - elastic.separation, 1e-12)
    while excess(lo) < 0:                           # more approach until the load is reached
        lo -= step
        step *= 2
        if len(history) > 60:
            raise ContactNotConverged(
                f"could not bracket the separation for the load {load} N: the hardness "
                f"{kw['hardness']:.3g} Pa caps the load at what the surfaces reach; check the "
                "load [N], the hardness [Pa] and the heights [m]", history)
    h0 = brentq(excess, lo, hi, xtol=1e-16 * max(abs(lo), abs(hi), 1e-9), rtol=1e-15, maxiter=100)
    r = state["result"]
    if r is None or r.separation != h0:
        excess(h0)
        r = state["result"]
    if abs(r.load / load - 1) > 1e-8:
        raise ContactNotConverged(f"load {r.load} N missed the imposed {load} N", history)
    return ContactResult(**{**r.__dict__, "iterations": state["calls"],
                            "history": tuple(history)})


def _cg(shape, spacing, e_reduced, *, load, separation, hardness, periodic, p_min, gap_floor,
        initial_pressure, tol, max_iter) -> ContactResult:
    """Polonsky-Keer CG (load) or its separation-controlled variant, pressure in [p_min, H].

    Only the loaded points (a few per cent of a rough contact) carry the CG vectors, as
    index sets into the grid.  The gap ``G = shape + K p`` is carried from the step's ``K t``
    and the ``K c`` of the bounds' corrections (single precision, about 1e-6 of the
    increment) and recomputed exactly every ``_REFRESH`` iterations."""
    s = np.asarray(shape, dtype=float)
    dx1, dx2 = np.broadcast_to(np.asarray(spacing, float), (2,))
    area = dx1 * dx2
    _check(s, area, load, separation, hardness, p_min)
    op = elastic_operator(s.shape, (dx1, dx2), e_reduced, periodic)
    p = _initial(s, area, load, separation, hardness, p_min, initial_pressure).ravel().copy()
    grid, n, by_load = s.shape, s.size, load is not None
    deform = lambda q, exact=True: (  # noqa: E731  (flat in, flat out; single: float32)
        (op if exact else op.single)(q.reshape(grid)).ravel())
    floor = lambda k: abs(p_min) * (n - k)   # noqa: E731  (|p| summed over unloaded points)
    h0 = 0.0 if separation is None else float(separation)
    is_loaded = p > p_min
    loaded = np.flatnonzero(is_loaded)
    t32, c32 = np.zeros(n, np.float32), np.zeros(n, np.float32)
    t_at, was_wrong, delta, g_old, G, fresh = loaded[:0], loaded[:0], 0.0, 1.0, None, 0
    history, size_old = [], floor(loaded.size) + np.abs(p[loaded]).sum()
    for it in range(1, max_iter + 1):
        if G is None or fresh >= _REFRESH:
            (G, delta), fresh = _exact_gap(s, p, deform, G, t_at, g_old, delta), 0
            loaded.sort()
        pl = p[loaded]
        fi = loaded[pl < hardness]                 # the free set
        h0, g_old, tf, kt, tau = _direction(G, fi, h0, by_load, delta, g_old, t32, t_at,
                                            deform)
        t_at = fi
        wrong, low = _wrong_points(G, h0, is_loaded, loaded[pl >= hardness])
        cand = np.concatenate([loaded, low])       # every point whose pressure may change
        p_was = p[cand]
        pf = p[fi] - tau * tf
        bounded = fi.size > 0 and (pf.min() < p_min or pf.max() > hardness)
        p[fi] = np.clip(pf, p_min, hardness, out=pf)
        _move_wrong(p, wrong, G, h0, tau, was_wrong, deform, c32, p_min, hardness)
        new = cand[p[cand] > p_min]
        factor = _load_kept(p, new, load / area - p_min * (n - new.size), p_min,
                            hardness) if by_load else 1.0
        diff = p[cand] - p_was
        size_new = floor(new.size) + np.abs(p[new]).sum()
        change = np.abs(diff).sum() / max(size_new, size_old, 1e-14 * e_reduced * n)
        history.append(change)
        corrected = bounded or wrong.size > 0 or factor != 1.0
        _carry_gap(G, kt, tau, t32, c32, cand, diff if corrected else None, deform)
        is_loaded[cand] = False
        is_loaded[new] = True
        loaded, was_wrong, delta, size_old = new, wrong, 0.0 if wrong.size else 1.0, size_new
        fresh += 1
        if change < tol:
            break
    else:
        raise ContactNotConverged(f"contact did not converge in {max_iter} iterations "
                                  f"(tol {tol})", history)
    p = p.reshape(grid)
    return _result(s, op(p), p, h0, by_load, area, p_min, hardness, gap_floor, it, history)


def _exact_gap(s, p, deform, G, t_at, g_old, delta):
    """``(G, delta)``: the gap without the separation recomputed exactly, and the CG's
    conjugation switched off (0) when the carried gap ``G`` had drifted past 1 % of the
    free-set gap at the last direction's points ``t_at`` (the directions no longer
    conjugate)."""
    exact = s.ravel() + deform(p)
    if G is not None:
        jump = exact[t_at] - G[t_at]
        if jump @ jump > 1e-4 * g_old:
            delta = 0.0
    return exact, delta


def _load_kept(p, new, mean, p_min, hardness) -> float:
    """Scale the loaded points ``new`` of ``p`` in place to the mean pressure ``mean`` they
    must carry (:func:`_rescale`); the factor."""
    pl = p[new]
    factor = _rescale(pl, mean, p_min, hardness)
    p[new] = pl
    return factor


def _direction(G, fi, h0, by_load, delta, g_old, t32, t_at, deform):
    """One CG direction on the free set ``fi``: ``(h0, g_old, t, K t, tau)`` with the
    separation (under load: the free set's mean gap), the squared gap for the next
    conjugation, the direction as transformed (single precision, ``t32`` updated in place
    and cleared at the previous direction's points ``t_at``), its deformation and the step."""
    gf = G[fi]
    if by_load and fi.size:
        h0 = -gf.mean()
    gf += h0
    gg = float(gf @ gf)
    tf = gf + delta * (gg / g_old) * t32[fi] if delta else gf   # t = m (g + beta t)
    g_old = gg if gg > 0 else 1.0
    t32[t_at] = 0.0
    t32[fi] = tf
    tf = t32[fi].astype(float)                     # the direction as transformed
    kt = deform(t32, exact=False)
    ktf = kt[fi].astype(float)
    rt = float(ktf @ tf)                           # (K t - its free-set mean) . t under load
    if by_load and fi.size:
        rt -= ktf.mean() * tf.sum()
    tau = float(gf @ tf) / rt if rt > 0 else 0.0
    return h0, g_old, tf, kt, tau


def _wrong_points(G, h0, is_loaded, plastic):
    """Points off the free set whose gap asks to move: unloaded with overlap (``low``) and
    plastic with the gap open; returns (all of them, the unloaded ones)."""
    low = np.flatnonzero(np.greater(G < -h0, is_loaded))
    return np.concatenate([low, plastic[G[plastic] > -h0]]), low


def _move_wrong(p, wrong, G, h0, tau, was_wrong, deform, scratch, p_min, hardness):
    """Give the wrong points, in place, the pressure that closes a uniform overlap on them:
    the CG step; when some were wrong last time too, no larger than the set's joint
    stiffness allows (one point's step made points released from and pressed back to the
    cap cycle forever; the extra single-precision FFT pair is paid only then)."""
    if not wrong.size:
        return
    step = tau
    if tau <= 0 or np.intersect1d(wrong, was_wrong).size:
        scratch[wrong] = 1.0
        joint = 1.0 / deform(scratch, exact=False).max()
        scratch[wrong] = 0.0
        step = min(joint, tau) if tau > 0 else joint
    p[wrong] = np.clip(p[wrong] - step * (G[wrong] + h0), p_min, hardness)


def _carry_gap(G, kt, tau, t32, c32, cand, diff, deform):
    """``G += K (p - p_old)`` in place from the step's ``K t``: ``- tau K t``, plus, when
    the bounds moved points (``diff = p - p_old`` on ``cand``, else None), ``K c`` of the
    correction ``c = diff + tau t`` (a single-precision pair)."""
    kt *= np.float32(-tau)
    if diff is not None:
        c32[cand] = diff + tau * t32[cand]
        kt += deform(c32, exact=False)
        c32[cand] = 0.0
    G += kt


def _check(s, area, load, separation, hardness, p_min):
    """Clear errors before the work: shape, one control, bounds, a load the grid carries."""
    if s.ndim != 2 or not np.all(np.isfinite(s)):
        raise InputError("shape must be a finite 2D array [m]")
    if (load is None) == (separation is None):
        raise InputError("give exactly one of load [N] or separation [m]")
    if not hardness > p_min:
        raise InputError(f"hardness {hardness} must exceed p_min {p_min}")
    if load is not None:
        if not load > p_min * s.size * area:
            raise InputError(f"load {load} N must exceed the floor load p_min * area")
        if load >= hardness * s.size * area:
            raise InputError(f"load {load} N exceeds what the hardness can carry on this grid")


def _rescale(p, total, p_min, hardness):
    """Scale, in place, the pressure above the floor of the points below the cap so that
    ``sum(p) = total``; the uniform factor when one scaling did it, else None."""
    capped = np.isfinite(hardness)
    floor = p_min * p.size
    for k in range(50):
        plastic = np.flatnonzero(p >= hardness) if capped else np.zeros(0, int)
        held = (hardness - p_min) * plastic.size if plastic.size else 0.0   # stay at H
        target = total - floor - held
        current = float(p.sum()) - floor - held
        if target <= 0 < current + held:
            # the capped points alone carry more than the load: lower every point alike
            # (the CG then frees the ones whose gap opens)
            _scale_above(p, p_min, (total - floor) / (current + held))
            return None
        if current <= 0:
            break
        factor = target / current
        _scale_above(p, p_min, factor)
        p.ravel()[plastic] = hardness
        if not capped or p.max() <= hardness:
            return factor if k == 0 and plastic.size == 0 else None
        np.minimum(p, hardness, out=p)
    np.minimum(p, hardness, out=p)
    return None


def _scale_above(p, p_min, factor):
    """``p = p_min + factor (p - p_min)`` in place."""
    if p_min:
        p -= p_min
    p *= factor
    if p_min:
        p += p_min


def _result(s, u, p, h0, by_load, area, p_min, hardness, gap_floor, it, history):
    """The :class:`ContactResult` of the converged pressure; under a load the separation is
    the mean over the free set (where the gap closes)."""
    if by_load:
        free = (p > p_min) & (p < hardness)
        pts = free if free.any() else p > p_min
        h0 = -(s + u)[pts].mean() if pts.any() else -(s + u).min()
    raw = h0 + s + u
    return ContactResult(pressure=p, deformation=u, gap=np.maximum(raw, gap_floor), raw_gap=raw,
                         separation=float(h0), load=float(p.sum() * area),
                         contact_fraction=float(np.mean(p > p_min)),
                         plastic_fraction=float(np.mean(p >= hardness)), iterations=it,
                         history=tuple(history))


def _initial(s, area, load, separation, hardness, p_min, initial_pressure):
    if initial_pressure is not None:
        p = np.clip(np.asarray(initial_pressure, float), p_min, hardness)
        if p.shape != s.shape:
            raise InputError(f"initial_pressure shape {p.shape} != shape {s.shape}")
        if load is not None:
            p = p if p.sum() > 0 else np.full(s.shape, 1.0)
            _rescale(p, load / area, p_min, hardness)
        return p
    if load is not None:
        p = np.full(s.shape, 1.0)
        _rescale(p, load / area, p_min, hardness)
        return p
    # separation control: start from the points that overlap the rigid surface
    return np.where(s + separation < 0, min(hardness, 1e6 + p_min), p_min)
