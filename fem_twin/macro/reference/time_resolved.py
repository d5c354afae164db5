"""Time-resolved deterministic mixed lubrication of two rough bodies: the pin's roughness at
rest, the disk's sliding over it at U.  The reference of the twin's unsteady cells (eq 8
with its time term, both bodies rough), where every production run lives
(docs/accuracy.md, "Both bodies rough, the disk's roughness moving").

The disk's roughness is periodic along x1 with ``m`` pixels; at step ``n`` it has moved by
``n`` pixels, so ``dt = dx1 / U`` and one roughness period is ``m`` steps (``substeps`` steps
a pixel: ``dt = dx1 / (substeps U)``, the strip Fourier-shifted).  Each instant is
the steady solver's problem (:mod:`.deterministic`: Reynolds with JFO, the CG-FFT contact
with the hardness cap, the half-space deformed by the film and the contact pressure, eqs
23-24 at the local pressure) plus the squeeze term ``d(rho h (1 - theta)) / dt`` of the
transient, mass-conserving Reynolds equation, on the dual cells of the Couette flux, by the
second-order BDF (``scheme="bdf2"``, default) or implicit Euler (``"backward"``, first
order).  ``h_d`` is held over each period (the pin cannot follow a period of microseconds)
and moved between periods by the secant of the period-mean log load (first the steady
solution's ``d log W / d h_d``) until the period-mean load balances; the run starts from
the steady solution with the disk frozen at its first instant and ends when the period
means repeat (:class:`TimeSettings`).
Friction on the pin: :func:`.film_friction.pad_friction` plus the film pressure on the
disk's slopes (the pin's surface is the gap minus the disk's), and the boundary law's
force (:func:`.deterministic.boundary_force`)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ...checks import (
    arguments,
    as_field,
    check_choices,
    check_ranges,
    plausible,
    setting,
    whole,
)
from ...errors import InputError
from ..laws.lubricant import Lubricant
from .deterministic import (
    DeterministicNotConverged,
    DeterministicResult,
    DeterministicSettings,
    Pad,
    balance,
    boundary_force,
    checked_point,
    state_film,
    viscous_cut,
)
from .film_friction import film_force

__all__ = ["TimeResolvedResult", "TimeSettings", "disk_at", "solve_time_resolved"]

#: the time schemes: the weights of ``rho h (1 - theta)`` at the step and the steps before
#: it, ``d m / dt = (sum_k w_k m^(n - k)) / dt``
SCHEMES = {"bdf2": (1.5, -2.0, 0.5), "backward": (1.0, -1.0)}


@dataclass(frozen=True)
class TimeSettings:
    """The time integration of :func:`solve_time_resolved` (dimensionless)."""

    scheme: str = setting("bdf2", "the squeeze term by the second-order BDF, or the "
                          "implicit Euler of the cells' paper scheme", choices=tuple(SCHEMES))
    substeps: int = setting(1, "time steps per pixel the disk moves (more than one: the "
                            "strip moved by fractions of a pixel, Fourier-shifted)",
                            "time_steps")
    step_tol: float = setting(1e-4, "each instant's film-contact iteration: the film's "
                              "deformation per micrometre, log viscosity and density ratio "
                              "change by less", "solver_tolerance")
    period_tol: float = setting(1e-3, "the periodic state: the period means of C_f (over "
                                "C_f,b) and of the load share change by less, and the "
                                "period-mean log load residual is below it",
                                "solver_tolerance")
    min_periods: int = setting(2, "periods run at least (the start-up transient)",
                               "iterations")
    max_periods: int = setting(60, "periods run at most", "iterations")

    def __post_init__(self):
        check_choices(self)
        check_ranges(self)
        if not 1 <= self.min_periods <= self.max_periods:
            raise InputError("TimeSettings: need 1 <= min_periods <= max_periods")


@dataclass(frozen=True, eq=False)
class TimeResolvedResult(DeterministicResult):
    """A periodic state of the time-resolved pad: the loads, friction and separation of
    :class:`~fem_twin.macro.reference.deterministic.DeterministicResult` as means over the last
    roughness period, its fields at the period's last instant, and ``instants``: each
    step's ``contact_load``, ``film_load``, ``film_friction``, ``boundary_force`` [N] over
    that period; ``periods`` run; ``history``: per period ``(log load residual, change of
    the means)``; ``frozen_separation``: the steady start's, the disk frozen [m]."""

    periods: int = 0
    instants: dict = field(default_factory=dict)
    frozen_separation: float = 0.0


@arguments(shift="number")
def disk_at(disk, shift: float, nodes: int) -> np.ndarray:
    """The disk's heights [m] over the pad's ``nodes`` columns moved by ``shift`` pixels
    along +x1: the periodic strip ``disk`` (ny, m), whose column ``(j - shift) mod m`` lies
    over column ``j`` (a fraction of a pixel by the Fourier shift of the strip)."""
    nodes = whole("disk_at: nodes", nodes, "samples")
    disk = as_field("disk_at: disk [m]", disk, 1)
    m = disk.shape[1]
    pixels = int(np.floor(shift))
    if shift != pixels:
        k = np.fft.rfftfreq(m)
        disk = np.fft.irfft(np.fft.rfft(disk, axis=1) * np.exp(-2j * np.pi * k * (shift - pixels)),
                            n=m, axis=1)
    return disk[:, (np.arange(nodes) - pixels) % m]


def _slope(disk, dx1: float) -> np.ndarray:
    """``d z / dx1`` of the periodic strip [-] (central differences)."""
    return (np.roll(disk, -1, axis=1) - np.roll(disk, 1, axis=1)) / (2 * dx1)


def solve_time_resolved(surfaces, spacing, *, load: float, speed: float,
                        lubricant: Lubricant,
                        settings: DeterministicSettings = DeterministicSettings(),
                        time: TimeSettings | None = None,
                        initial: DeterministicResult | None = None) -> TimeResolvedResult:
    """The periodic state of the pad under the sliding rough disk (module docstring).

    ``surfaces``: ``(shape, disk)``, the pad's form minus the pin's roughness (ny, nx) [m]
    (what the gap has at zero separation besides the disk) and one period of the disk's
    heights along x1 (ny, m) [m], periodic; ``spacing`` (dx1, dx2) [m]; ``load`` [N];
    ``speed``: the disk's U [m/s]; ``settings``: the pad's materials and numerics (default:
    the paper's); ``time``: :class:`TimeSettings`; ``initial``: a neighbouring point
    whose separation starts the steady start's bracket (a time-resolved one's also moves
    the first period from the steady start as far as its own periodic state lay from its
    start).  Raises
    :class:`~fem_twin.macro.reference.deterministic.DeterministicNotConverged` with the history
    when the period means do not repeat within ``time.max_periods``."""
    if not (isinstance(surfaces, (tuple, list)) and len(surfaces) == 2):
        raise InputError("solve_time_resolved: surfaces: expected (shape, disk), the pad's "
                         f"gap shape and the disk's periodic strip [m], got "
                         f"{type(surfaces).__name__}")
    shape, disk = surfaces
    s, dx, load, speed = checked_point(shape, spacing, load, speed, (lubricant, settings))
    z = as_field("disk [m]", disk, 2)
    plausible("disk [m] (its largest height)", float(np.max(np.abs(z))) or 1e-8, "height")
    time = TimeSettings() if time is None else time
    if not isinstance(time, TimeSettings) or z.shape[0] != s.shape[0]:
        raise InputError("time must be TimeSettings and disk (ny, m) with the pad's ny rows")
    pad = Pad(s + disk_at(z, 0, s.shape[1]), dx, speed, lubricant,
               replace(settings, tol=time.step_tol))
    march = _March(pad, s, z, load, SCHEMES[time.scheme], time.substeps)
    offset = (initial.separation - initial.frozen_separation
              if isinstance(initial, TimeResolvedResult) else 0.0)
    march.start(None if initial is None else initial.separation, offset)
    history, means, held = [], None, []
    for period in range(1, time.max_periods + 1):
        before, (residual, means) = means, march.period()
        change = np.inf if before is None else float(np.max(np.abs(means - before)))
        history.append((residual, change))
        if period >= time.min_periods and max(abs(residual), change) < time.period_tol:
            return march.result(period, tuple(history))
        held.append((march.separation, residual))
        march.separation -= residual / _slope_of(held, march.slope)
    raise DeterministicNotConverged(f"the period means did not repeat in {time.max_periods} "
                                    "periods", history)


def _slope_of(held, steady: float) -> float:
    """``d log W / d h_d`` [1/m] for the next separation: the secant of the last two
    periods' ``(h_d, log load residual)`` where it agrees in sign with the steady start's
    ``steady`` within a factor 4 (the transient's drift can spoil it), else ``steady``."""
    if len(held) < 2 or held[-1][0] == held[-2][0]:
        return steady
    (h0, r0), (h1, r1) = held[-2:]
    secant = (r1 - r0) / (h1 - h0)
    return secant if 0.25 < secant / steady < 4 else steady


class _March:
    """The march over roughness periods at a separation moved between them: each step's
    warm start is the same instant of the period before."""

    def __init__(self, pad: Pad, shape, disk, load: float, weights, substeps: int):
        self.pad, self.shape, self.disk, self.load, self.weights = pad, shape, disk, load, weights
        self.substeps, self.nodes = substeps, shape.shape[1]
        self.steps = disk.shape[1] * substeps
        self.dt = pad.spacing[0] / (pad.speed * substeps)
        self.slopes = _slope(disk, pad.spacing[0])
        self.warm = [None] * self.steps
        self.separation = self.held = self.slope = self.frozen = None
        self.content = []                 # rho (1 - theta) and h of the latest steps, newest first
        self.last = None

    def start(self, guess, offset: float = 0.0):
        """The steady solution with the disk frozen at its first instant: its separation
        (the first period's moved by ``offset`` [m]), the load's slope and the film content
        before the first step."""
        h_d, state, _, self.slope = balance(self.pad, self.load, guess)
        self.frozen = self.held = h_d
        self.separation = h_d + offset
        self.content = [(state["rho"] * (1 - state["theta"]), state["gap"])] * (
            len(self.weights) - 1)

    def period(self):
        """One period at the current separation: ``(log load residual, means)``, the
        means of C_f / C_f,b and of the load share, and the records kept for the result."""
        moved, self.held = self.separation - self.held, self.separation
        self.content = [(c, np.maximum(h + moved, self.pad.settings.gap_floor))
                        for c, h in self.content]      # a new h_d is not a squeeze
        rows = [self.step(n) for n in range(self.steps)]
        self.instants = {k: np.array([r[k] for r in rows]) for k in rows[0]}
        i = self.instants
        total = i["contact_load"].mean() + i["film_load"].mean()
        cf = (i["film_friction"].mean() + i["boundary_force"].mean()) / total
        cfb = self.pad.settings.boundary_friction
        return float(np.log(total / self.load)), np.array(
            [cf / cfb, i["contact_load"].mean() / total])

    def step(self, n: int) -> dict:
        """Step ``n`` of the period: the instant's state from its warm start, its film
        content kept for the next steps; its loads and forces [N]."""
        pad = self.pad
        if self.warm[n] is not None:
            pad.p_con, pad.phi, pad.coupled = (None if v is None else v.copy()
                                               for v in self.warm[n])
        w = self.weights
        rate = w[0] * pad.area / self.dt
        source = -sum(wk * pad.area * c * h for wk, (c, h) in zip(w[1:], self.content)) / self.dt
        shift = n / self.substeps
        st = pad.at(self.separation, self.shape + disk_at(self.disk, shift, self.nodes),
                    (rate, source.ravel()))
        self.warm[n] = (pad.p_con, pad.phi.copy(), pad.coupled.copy())
        self.content = [(st["rho"] * (1 - st["theta"]), st["gap"])] + self.content[:len(w) - 2]
        self.last = st
        s, dx = pad.settings, pad.spacing
        flank = float(np.sum(pad.area * st["p"] * disk_at(self.slopes, shift, self.nodes)))
        film = film_force(state_film(st), dx, pad.speed, viscous_cut(s)) + flank
        return {"contact_load": st["contact_load"], "film_load": st["film_load"],
                "film_friction": film,
                "boundary_force": boundary_force(pad.area, st, s, pad.speed)}

    def result(self, periods: int, history: tuple) -> TimeResolvedResult:
        i, st, pad = self.instants, self.last, self.pad
        return TimeResolvedResult(
            pad.speed, self.load, float(self.separation), float(i["film_load"].mean()),
            float(i["contact_load"].mean()), float(i["film_friction"].mean()),
            float(i["boundary_force"].mean()), pad.spacing, st["p"], st["p_con"],
            st["theta"], st["gap"], history, periods=periods, instants=i,
            frozen_separation=float(self.frozen))
