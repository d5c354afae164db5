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

from ..errors import NotConverged
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


def solve(shape, spacing, e_reduced, *, load=None, separation=None, hardness=np.inf,
          periodic=False, p_min=0.0, gap_floor=1e-9, initial_pressure=None, tol=1e-10,
          max_iter=2000) -> ContactResult:
    """Dry contact of a rigid-body ``shape`` [m] against an elastic half-space.

    Parameters
    ----------
    shape : (ny, nx) array
        Undeformed gap geometry [m] up to the rigid-body separation, x1 along columns.
    spacing : (dx1, dx2) [m]
    e_reduced : E' of eq 22 [Pa]
    load : imposed normal load [N]; or
    separation : imposed rigid-body separation h0 [m] (exactly one of the two).
    hardness : pressure cap H [Pa] (paper: 6.99e9); ``inf`` for purely elastic.
    periodic : periodic (roughness cell) or non-periodic (zero-padded) elasticity.
    p_min : pressure floor [Pa] (default 0).
    gap_floor : truncation of the reported deformed gap [m] (paper: 1 nm).
    initial_pressure : warm start [Pa].
    tol : relative pressure change at convergence.

    The gap is ``separation + shape + K p``; contact where it closes.  KKT: ``p = p_min``
    where the gap is open, gap 0 where ``p_min < p < H``, gap <= 0 where ``p = H``.

    Under an imposed load, Polonsky-Keer's load-constrained CG, with the cap too (the load
    kept by scaling the points below it); should that not converge or miss the load, the
    separation is found by a bracketed root search (Brent) on the load of warm-started
    separation-controlled solves.  While no pressure bound is hit, the deformation is
    updated from the step's K t, so most iterations cost one FFT pair instead of two.
    """
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

    One loop of about 60 lines: the CG state (direction, free set, the deformation carried
    from ``K t``) is shared by every line of an iteration, so it is not split further."""
    s = np.asarray(shape, dtype=float)
    dx1, dx2 = np.broadcast_to(np.asarray(spacing, float), (2,))
    area = dx1 * dx2
    _check(s, area, load, separation, hardness, p_min)
    op = elastic_operator(s.shape, (dx1, dx2), e_reduced, periodic)
    p = _initial(s, area, load, separation, hardness, p_min, initial_pressure)

    history = []
    by_load, capped = load is not None, bool(np.isfinite(hardness))
    t, g, gm, m, spare = (np.zeros_like(s) for _ in range(5))   # no allocation in the loop
    g_old, delta, was_wrong = 1.0, 0.0, np.zeros(s.shape, bool)
    h0 = 0.0 if separation is None else float(separation)
    u, fresh, precise = None, 0, False
    dot = lambda a, b: float(np.dot(a.ravel(), b.ravel()))  # noqa: E731  (BLAS, no copies)
    size = (lambda q: q.sum()) if p_min >= 0 else (lambda q: np.abs(q).sum())  # noqa: E731
    size_old = size(p)
    for it in range(1, max_iter + 1):
        if u is None or fresh >= _REFRESH:
            u, fresh = op(p), 0
        np.add(s, u, out=g)
        free = p > p_min
        if capped:
            free &= p < hardness
        np.copyto(m, free)                         # free-set mask as numbers: masked sums
        n_free = float(np.count_nonzero(free))     # are dot products, without index copies
        if by_load and n_free:
            h0 = -dot(g, m) / n_free
        g += h0
        np.multiply(g, m, out=gm)
        gg = dot(gm, gm)
        t *= delta * (gg / g_old)                  # t = m (g + beta t)
        t *= m
        t += gm
        g_old = gg if gg > 0 else 1.0
        kt = op(t) if precise else op.single(t)
        rt = dot(kt, t)                            # (K t - its free-set mean) . t under load
        if by_load and n_free:
            rt -= dot(kt, m) / n_free * float(t.sum())
        tau = dot(g, t) / rt if rt > 0 else 0.0
        p_old, p = p, spare
        np.multiply(t, -tau, out=p)
        p += p_old
        linear = p.min() >= p_min and (not capped or p.max() <= hardness)  # K p = u - tau K t
        if not linear:
            np.clip(p, p_min, hardness, out=p)
        wrong = _wrong_set(p, p_old, g, free, was_wrong, tau, op, p_min, hardness, capped)
        any_wrong = wrong.any()
        delta = 0.0 if any_wrong else 1.0
        was_wrong = wrong
        factor = 1.0
        if by_load:
            factor = _rescale(p, load / area, p_min, hardness)
            linear &= factor is not None and (factor == 1.0 or p_min == 0.0)
        # the next deformation from this iteration's K t (one FFT pair per iteration instead
        # of two) while no bound was hit; recomputed every _REFRESH iterations against drift
        if linear and not any_wrong and precise:
            kt *= -tau
            u += kt
            u *= factor
            fresh += 1
        else:
            u = None
        precise = linear and not any_wrong
        # relative change, with a floor of 1e-14 E' per point (no contact: nothing to resolve)
        size_new = size(p)
        scale = max(size_new, size_old, 1e-14 * e_reduced * p.size)
        np.subtract(p, p_old, out=gm)
        change = float(np.abs(gm, out=gm).sum()) / scale
        history.append(change)
        spare, size_old = p_old, size_new
        if change < tol:
            break
    else:
        raise ContactNotConverged(f"contact did not converge in {max_iter} iterations "
                                  f"(tol {tol})", history)
    return _result(s, op(p), p, h0, by_load, area, p_min, hardness, gap_floor, it, history)


def _check(s, area, load, separation, hardness, p_min):
    """Clear errors before the work: shape, one control, bounds, a load the grid carries."""
    if s.ndim != 2 or not np.all(np.isfinite(s)):
        raise ValueError("shape must be a finite 2D array [m]")
    if (load is None) == (separation is None):
        raise ValueError("give exactly one of load [N] or separation [m]")
    if not hardness > p_min:
        raise ValueError(f"hardness {hardness} must exceed p_min {p_min}")
    if load is not None:
        if not load > p_min * s.size * area:
            raise ValueError(f"load {load} N must exceed the floor load p_min * area")
        if load >= hardness * s.size * area:
            raise ValueError(f"load {load} N exceeds what the hardness can carry on this grid")


def _wrong_set(p, p_old, g, free, was_wrong, tau, op, p_min, hardness, capped):
    """Points off the free set whose gap asks to move (p_min with overlap, H with the gap
    open), moved in place in ``p``; returns their mask.

    They get the pressure that closes a uniform overlap on the wrong set: the CG step; when
    the same points are wrong again, no larger than the set's joint stiffness allows (one
    point's step made points released from and pressed back to the cap cycle forever; the
    extra FFT pair is paid only then)."""
    if capped:
        wrong = ((p_old <= p_min) & (g < 0)) | ((p_old >= hardness) & (g > 0))
    else:                                   # off the free set = at the floor
        wrong = np.greater(g < 0, free)
    if wrong.any():
        step = tau
        if tau <= 0 or (wrong & was_wrong).any():
            joint = 1.0 / op(wrong.astype(float)).max()
            step = min(joint, tau) if tau > 0 else joint
        idx = np.flatnonzero(wrong)
        flat = p.ravel()
        flat[idx] = np.clip(flat[idx] - step * g.ravel()[idx], p_min, hardness)
    return wrong


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
            raise ValueError(f"initial_pressure shape {p.shape} != shape {s.shape}")
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
