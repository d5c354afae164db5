"""The partitioned couplings of the macro scale, fixed-point iterations over the film and
the solid: ``"anderson"`` and the paper's ``"pid"`` (the monolithic one: :mod:`.newton`).

Each iteration solves the Reynolds complementarity problem (eqs 17-18) at the previous
pressure's coefficients (lagged viscosity and density, warm-started), then updates the
elastic deformation ``h_el`` (eqs 20-22), the contact pressure ``p_con`` (eqs 25-27) and the
separation ``h_d`` (eqs 28-30).  ``"anderson"``: the fixed point ``(h_el, h_d) ->
(op(p_tot - p_amb), h_d + dF/k)`` with ``p_con`` at the current ``h0``, ``k`` a load
stiffness estimate, accelerated by damped Anderson mixing (Walker and Ni 2011), seeded
from a coarser grid's last differences (:class:`Secants`).  ``"pid"``: the paper's
under-relaxed ``p_con`` (eq 26), PID on ``h_d`` (eq 29) and under-relaxed ``h_el``.
Converged when the changes of ``h_el``, ``p_con`` and ``p`` and the load residual (eq 30),
scaled, are all below ``tol``; far from it the Reynolds solves are inexact (``INEXACT``,
``SETTLE``), and convergence is accepted only after an exact one.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...errors import MixedNotConverged
from ...numerics.anderson import Anderson
from ..film.cavitation import cavitation_model
from ..film.couette import couette_matrix
from ..film.reynolds import ReynoldsNotConverged
from .evaluation import PartitionedEvaluation
from .result import resampled
from .start import dry_separation, rigid_separation

#: ``coupling="auto"`` takes the Newton coupling when the first iterate's elastic
#: deformation exceeds this multiple of the thinnest loaded film (:func:`elastic_ratio`)
ELASTIC_RATIO = 15.0
#: halvings of an over-long step (the Reynolds solve failed) before giving up
RETRIES = 12
#: Anderson iterations without halving the residual before its history is restarted
STAGNATION = 25
#: the inner Reynolds solves stop after ``MacroSettings.inner_steps`` Newton steps while the
#: coupling residual exceeds this multiple of ``tol``: about twice as fast as exact inner
#: solves, C_f the same to 3e-7 C_f,b (``python benchmarks/run.py macro``)
INEXACT = 10.0
#: the last Anderson differences of a coarser grid's solve that seed a finer one's
#: (:class:`Secants`; sample pin 1 at 0.03 m/s, cold nested points: the 512^2 grid 10
#: coupling iterations against 14, the 256^2 one 12 against 15; 1024^2 9 against 10;
#: 2 to 6 pairs did as well, 1 and 8 worse)
SEED_PAIRS = 4
#: the first Reynolds solve of a coupling stops at the first Newton step that switches at
#: most this fraction of the nodes its first step switched (``settle`` of
#: :func:`.switch.solve_complementarity`), instead of solving to convergence: from a coarser
#: grid's film the last steps switch a handful of nodes each and cost a fifth of the fine
#: level; 0.01 saves it without more coupling iterations (``python benchmarks/run.py
#: scale``)
SETTLE = 0.01


@dataclass(frozen=True, eq=False)
class Secants:
    """The last Anderson differences of a converged coupling: ``dx``, ``df`` ``(m, N + 1)``,
    each row an elastic deformation on the grid ``shape`` of ``spacing`` [m], flattened,
    then ``h_d``, both over ``h_ref`` (oldest first)."""

    shape: tuple
    spacing: tuple
    dx: np.ndarray
    df: np.ndarray

    def on(self, shape, spacing) -> tuple:
        """``(dx, df)`` interpolated (linearly) onto the grid ``shape`` of ``spacing``."""
        def moved(rows):
            return np.stack([np.r_[resampled(row[:-1].reshape(self.shape), self.spacing,
                                             shape, spacing).ravel(), row[-1]]
                             for row in rows])
        if tuple(shape) == tuple(self.shape) or not len(self.dx):
            return self.dx, self.df
        return moved(self.dx), moved(self.df)


class Concentrated(Exception):
    """The ``"auto"`` coupling's signal: the contact needs the Newton coupling."""


def solve_partitioned(P, load: float, face, initial=None, progress=None, secants=None):
    """Iterate the ``P.point.settings.coupling`` fixed point (``"auto"`` means ``"anderson"``, and
    raises :class:`Concentrated` at the first iterate of an elastically dominated contact);
    ``secants`` (:class:`Secants`, of a coarser grid's solve) seed the Anderson history.
    Returns ``(ev, h_el, h_d, iterations, history, secants)``, the last this solve's own
    (None for ``"pid"``); raises :class:`MixedNotConverged`."""
    s = P.point.settings
    inner = _Reynolds(P, initial)
    h_el, h_d, p_con = _start(P, inner, load, face, initial)
    outer = _Pid(s) if s.coupling == "pid" else _Mixing(P, load, face, secants)
    history, good, retries, row, res = [], None, 0, (np.nan,) * 4, np.inf
    for it in range(1, s.max_iter + 1):
        exact = (not s.inner_steps or res < INEXACT * s.tol
                 or (it == 1 and not inner.model.settles))
        settle = SETTLE if it == 1 and not exact else 0.0
        try:
            ev = inner.evaluate(h_el, h_d, p_con if s.coupling == "pid" else None,
                                steps=None if exact or settle else s.inner_steps,
                                settle=settle)
        except ReynoldsNotConverged as err:     # an over-long step (gap far too thin)
            retries += 1
            if good is None or retries > RETRIES:
                raise MixedNotConverged(f"the Reynolds solve failed at iteration {it}: {err}",
                                        history) from err
            h_el, h_d = (h_el + good[0]) / 2, (h_d + good[1]) / 2
            inner.phi, inner.p = good[2], good[3]
            outer.restart()
            history.append((it, np.nan, np.nan, np.nan, np.nan, h_d, -1))
            continue
        retries = 0
        if it == 1 and s.coupling == "auto" and elastic_ratio(ev, P.elastic, s) > ELASTIC_RATIO:
            raise Concentrated
        good = (h_el, h_d, inner.phi, ev.p_prev)
        row = _changes(ev, h_el, p_con, load, s)
        res = max(map(abs, row))
        history.append((it, *row, h_d, inner.newton))
        if progress is not None:
            progress(it, res)
        if res < s.tol and it > 1 and exact:
            return ev, h_el, h_d, it, history, outer.secants()
        h_el, h_d, p_con = outer.update(ev, h_el, h_d, p_con, row, res)
        del ev                      # not alive beside the next one (~200 B a node)
    raise MixedNotConverged(
        f"macro iteration ({s.coupling}) did not reach residuals below {s.tol} in "
        f"{s.max_iter} iterations (last: h_el {row[0]:.2e}, p_con {row[1]:.2e}, "
        f"p {row[2]:.2e}, load {row[3]:.2e})", history)


def _changes(ev, h_el, p_con, load, s) -> tuple:
    """``(r_hel, r_pcon, r_p, r_F)``: the changes of ``h_el`` / h_ref, ``p_con`` / p_ref
    (eq 27) and ``p`` / p_ref in this iteration, and the load residual (eq 30)."""
    return (float(np.abs(ev.h_el_new - h_el).max() / s.h_ref),
            float(np.abs(ev.p_con_target - p_con).max() / s.p_ref),
            float(np.abs(ev.p - ev.p_prev).max() / s.p_ref),
            (ev.F - load) / load)


class _Reynolds:
    """Reynolds (eqs 17-18) at the coefficients of the previous pressure, warm-started from
    the previous switch ``phi``: the inner problem of the fixed point."""

    def __init__(self, P, initial):
        s = P.point.settings
        self.P, self.model = P, cavitation_model(s.complementarity)
        self.p_amb_rel = s.ambient_pressure - s.cavitation_pressure
        self.phi, self.p, self.newton = None, np.full(P.shape, self.p_amb_rel), 0
        if initial is not None:
            self.p = initial.pressure - s.cavitation_pressure
            self.phi = self.model.unknown(self.p, initial.cavity_fraction, s.p_ref).ravel()

    def reset(self):
        """A cold inner start (the state is far from the last one)."""
        self.phi, self.p = None, np.full(self.P.shape, self.p_amb_rel)

    def evaluate(self, h_el, h_d, p_con=None, steps=None, settle=0.0) -> PartitionedEvaluation:
        """Solve at ``h0 = h_d + h_g + h_el`` (eq 19); ``p_con`` [Pa] is used in the load and
        the deformation when given (``"pid"``), else ``p_con(h0)``; ``steps`` cuts the solve
        to that many Newton steps, ``settle`` stops it once its active set has settled
        (inexact inner solves).  Returns every field the updates and the result need."""
        P, s = self.P, self.P.point.settings
        h0 = np.maximum(h_d + P.point.gap + h_el, s.gap_floor)
        p_prev = self.p
        loc, mu, rho, g, q = P.coefficients(p_prev, h0)
        K = P.poiseuille(g, loc.A)
        B = couette_matrix(q * loc.b[..., 0], q * loc.b[..., 1], P.point.spacing, s.couette)
        # of the factors the result needs h_m and p_con: A, b, g and q are not kept through
        # the solve (64 B a node)
        loc = replace(loc, A=None, b=None)
        del g, q
        cut = {} if steps is None else dict(max_iter=steps, inexact=True)
        if settle:
            cut = dict(settle=settle)
        phi, its, _ = self.model.solve(K, B, P.boundary, self.p_amb_rel, s.p_ref,
                                       phi0=self.phi, **cut)
        del K, B
        self.phi, self.newton = phi, its
        p, theta = (v.reshape(P.shape) for v in self.model.split(phi, s.p_ref))
        self.p = p
        p_con_used = loc.p_con if p_con is None else p_con
        p_tot = p + s.cavitation_pressure + p_con_used
        return PartitionedEvaluation(
            h0=h0, loc=loc, mu=mu, rho=rho, p=p, p_prev=p_prev, theta=theta,
            p_con_target=loc.p_con, p_con=p_con_used,
            F=float(np.sum(P.area * (p_tot - s.ambient_pressure))),
            F_hd=float(np.sum(P.area * (p + s.cavitation_pressure - s.ambient_pressure))),
            h_el_new=P.elastic(p_tot - s.ambient_pressure))


def _start(P, inner, load, face, initial):
    """``(h_el, h_d, p_con)`` to begin with: ``initial``'s, or the rigid film and contact
    that carry the load (:func:`.start.rigid_separation`)."""
    if initial is not None:
        return (initial.elastic_deformation.copy(), float(initial.h_d),
                initial.contact_pressure.copy())
    s, factors, h_g = P.point.settings, P.factors, P.point.gap
    h_el = np.zeros(P.shape)

    def excess(h_d):
        inner.reset()
        return inner.evaluate(h_el, h_d).F - load

    h_free = float(factors.h0[-1]) - float(h_g[face].min())
    h_d = rigid_separation(excess, h_free, dry_separation(factors, h_g, P.area, load, s),
                           float(factors.h0[-1]))
    inner.p = np.full(P.shape, inner.p_amb_rel)
    return h_el, h_d, factors.contact_pressure(np.maximum(h_d + h_g, s.gap_floor))


class _Pid:
    """The paper's updates: eq 26 on ``p_con``, the PID controller of eq 29 on ``h_d``,
    under-relaxation on ``h_el``."""

    def __init__(self, s):
        self.s, self.r_prev = s, (0.0, 0.0)

    def restart(self):
        pass

    def secants(self):
        return None

    def update(self, ev, h_el, h_d, p_con, row, res):
        s, r_F = self.s, row[3]
        p_con = p_con + s.relaxation_pcon * (ev.p_con_target - p_con)       # eq 26
        kp, ki, kd = s.gains
        r1, r2 = self.r_prev
        h_d += (kp * (r_F - r1) + ki * r_F + kd * (r_F - 2 * r1 + r2)) * 1e-6   # eq 29
        self.r_prev = (r_F, r1)
        return h_el + s.relaxation_elastic * (ev.h_el_new - h_el), h_d, p_con


class _Mixing:
    """Anderson mixing of ``(h_el, h_d)`` with ``p_con`` at the current ``h0``; a trust
    region keeps every step below half the thinnest film."""

    def __init__(self, P, load, face, secants=None):
        self.P, self.load, self.face = P, load, face
        self.best, self.stall = np.inf, 0
        self.restart()
        if secants is not None:
            self.mixer.seed(*secants.on(P.shape, P.point.spacing))

    def restart(self):
        s = self.P.point.settings
        self.mixer = Anderson(s.anderson_depth, s.anderson_damping)

    def secants(self) -> Secants:
        """This solve's last :data:`SEED_PAIRS` Anderson differences."""
        return Secants(self.P.shape, self.P.point.spacing, *self.mixer.pairs(SEED_PAIRS))

    def update(self, ev, h_el, h_d, p_con, row, res):
        P, s = self.P, self.P.point.settings
        self.stall += 1
        if res < 0.5 * self.best:
            self.best, self.stall = res, 0
        elif self.stall > STAGNATION:
            self.restart()
            self.best, self.stall = res, 0
        k = _load_stiffness(P.factors, ev, P.area, s)
        x = np.r_[h_el.ravel(), h_d] / s.h_ref
        f = np.r_[ev.h_el_new.ravel(), h_d + (ev.F - self.load) / k] / s.h_ref - x
        step = self.mixer.step(x, f) - x
        bound = 0.5 * max(float(ev.h0[self.face].min()), 1e-8) / s.h_ref
        step *= min(1.0, bound / max(float(np.abs(step).max()), 1e-300))
        x = (x + step) * s.h_ref
        return x[:-1].reshape(P.shape), float(x[-1]), ev.p_con_target


def elastic_ratio(ev, op, s) -> float:
    """Largest elastic deformation by the film pressure over the thinnest film under
    pressure, at the first iterate: large for a concentrated contact, small for a conformal
    pin.  Nodes at the gap floor (``MacroSettings.gap_floor``: the rigid start's contact)
    have no film and are left out: one such node under pressure made the ratio 25-252 on
    the 63^2 coarse start of sample pin 1 at 500, 999 and 1997 px (0.003 and 0.03 m/s),
    whose levels then all took the Newton coupling, and a 1997^2 point ran out of 24 GB.
    Without them smooth balls give 11-241 and the sample pin 0.22-13.3
    (``python benchmarks/run.py scale`` and ``newton``)."""
    p_gauge = ev.p + s.cavitation_pressure - s.ambient_pressure
    film = ev.h0[(p_gauge > 0) & (ev.h0 > 2 * s.gap_floor)]
    if not film.size:
        return 0.0
    return float(np.abs(op(np.maximum(p_gauge, 0))).max()) / float(film.min())


def _load_stiffness(factors, ev, area, s):
    """-dF/dh_d estimate [N/m]: contact slope of p_con(h0) plus 2 F_hd / h (hydrodynamic)."""
    h0 = ev.h0
    eps = 1e-3 * h0
    dp = (factors.contact_pressure(h0 - eps) - factors.contact_pressure(h0 + eps)) / (2 * eps)
    k_con = float(np.sum(area * np.maximum(dp, 0)))
    loaded = ev.p > ev.p.max() * 0.1 if ev.p.max() > 0 else np.ones(h0.shape, bool)
    h_char = float(np.average(h0[loaded], weights=ev.p[loaded] + 1e-30))
    k_hd = 2 * max(ev.F_hd, 0.0) / max(h_char, s.gap_floor)
    return max(k_con + k_hd, 1e-3 * abs(ev.F) / s.h_ref + 1e-300)
