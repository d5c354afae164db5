"""Homogenised mixed elasto-hydrodynamic operating point (paper 2.2.2, eqs 17-34).

One operating point (imposed load F_N,imp, sliding speed U) of the pin-on-disk contact:

* homogenised Reynolds with JFO cavitation (eqs 17-18) on the macro grid, with the flow
  factors ``A, b`` and the mean gap ``h_m`` of the micro scale at the local separation
  ``h0`` (:meth:`FlowFactors.at`), Roelands viscosity (eq 23) and Dowson-Higginson density
  (eq 24) at the current pressure;
* ``h0 = h_d + h_g + h_el`` (eq 19), ``h_el`` from ``p_tot - p_amb = p_hd + p_con - p_amb``
  by the non-periodic FFT half-space operator (eqs 20-22);
* the mean asperity contact pressure ``p_con(h0)`` (eqs 25-27) and the load balance on
  ``h_d`` (eqs 28-30);
* friction from eqs 31-34 over the pin face.

Two couplings reach the same state:

``"anderson"`` (default)
    the fixed point ``(h_el, h_d) -> (op(p_tot - p_amb), h_d + dF/k)`` with ``p_con``
    taken at the current ``h0`` (no under-relaxation), accelerated by Anderson mixing
    (Walker and Ni 2011).  ``k`` is a load-stiffness estimate (contact stiffness from the
    slope of ``p_con(h0)`` plus ``2 F_hd / h``); Anderson mixing corrects it.
``"pid"``
    the paper's scheme: ``p_con`` under-relaxed with ``alpha_pcon`` (eq 26), the
    incremental PID controller of eq 29 on ``h_d``, and ``h_el`` under-relaxed (the
    paper's EHL-FBNS solves the elastic coupling inside its Newton system; a plain
    fixed point on ``h_el`` oscillates here, so it is relaxed with ``relaxation_elastic``).

Each iteration solves the Reynolds complementarity problem to 1e-10 at frozen
coefficients (warm-started).  Converged when, between two iterations, all of the
following are below ``tol`` (1e-6): the change of ``h_el`` / h_ref, the update of
``p_con`` / p_ref (eq 27), the change of ``p`` / p_ref (lagged viscosity and density) and
the load residual (eq 30).  Otherwise :class:`MixedNotConverged` carries the history.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from .. import tables as T
from ..anderson import Anderson
from ..contact.elastic import elastic_operator
from ..errors import MixedNotConverged
from ..io.atomic import atomic_path
from ..micro.flow_factors import FlowFactors
from ..threads import one_thread
from .friction import BOUNDARY_FRICTION, boundary_shear, hydrodynamic_shear
from . import newton
from .lubricant import Lubricant
from .reynolds_fv import fvm_poiseuille
from .start import dry_separation, rigid_separation
from .reynolds import (ReynoldsNotConverged, complementarity_solver, fe_poiseuille,
                       trapezoid_weights, upwind_couette)


#: ``coupling="auto"`` takes the Newton coupling when the first iterate's elastic
#: deformation exceeds this multiple of the thinnest loaded film (measured: sample pin at
#: 32^2 and 128^2, 0.003-1 m/s: 0.2-6.4; smooth balls 25-4000 for M = 10-1000)
ELASTIC_RATIO = 15.0

#: Newton iterations per load of the ``"newton"`` coupling (it converges in 5-20), at most
#: ``MacroSettings.max_iter``
NEWTON_MAX_ITER = 60

#: Cold starts on grids of at least twice this size begin with a solve on the coarser grid.
COARSE_START = 48


@dataclass(frozen=True)
class MacroSettings:
    """Settings of the macro solver (Table 6 defaults, SI units)."""

    ambient_pressure: float = T.AMBIENT_PRESSURE
    cavitation_pressure: float = T.CAVITATION_PRESSURE
    e_reduced: float = T.E_REDUCED
    boundary_friction: float = BOUNDARY_FRICTION
    method: str = "fe"                       # Poiseuille term: "fe" or "fvm"
    coupling: str = "auto"                   # "anderson", "newton" or "pid" (the paper's)
    complementarity: str = "switch"          # or "fb" (the paper's FBNS; slower)
    relaxation_pcon: float = T.RELAXATION_PCON   # alpha_pcon of eq 26 ("pid")
    relaxation_elastic: float = 0.1          # under-relaxation of h_el ("pid")
    gains: tuple = T.MACRO_GAINS             # K_P, K_I, K_D of eq 29 ("pid")
    anderson_depth: int = 8
    p_ref: float = 100e6
    h_ref: float = 1e-6
    tol: float = 1e-6
    max_iter: int = 300
    gap_floor: float = 1e-9                  # h0 passed to the flow factors [m]

    def __post_init__(self):
        if self.method not in ("fe", "fvm"):
            raise ValueError(f"method must be 'fe' or 'fvm', got {self.method!r}")
        if self.coupling not in ("auto", "anderson", "pid", "newton"):
            raise ValueError("coupling must be 'auto', 'anderson', 'pid' or 'newton', got "
                             f"{self.coupling!r}")
        if self.ambient_pressure < self.cavitation_pressure:
            raise ValueError("ambient pressure must not be below the cavitation pressure [Pa]")
        if self.complementarity not in ("switch", "fb"):
            raise ValueError(f"complementarity must be 'switch' or 'fb', got "
                             f"{self.complementarity!r}")
        if not 0 < self.relaxation_pcon <= 1:
            raise ValueError("relaxation_pcon must be in (0, 1]")


_FIELDS = ("pressure", "contact_pressure", "cavity_fraction", "h0", "mean_gap",
           "elastic_deformation", "viscosity", "density_ratio", "shear_stress", "face")


@dataclass(frozen=True, eq=False)
class MixedResult:
    """A converged operating point (SI units).

    Scalars: ``speed`` U [m/s], ``imposed_load`` F_N,imp and ``normal_load`` F_N (eq 28) [N],
    ``h_d`` [m], ``friction_force`` F_T (eq 33) with its ``hydrodynamic_friction`` and
    ``boundary_friction`` parts [N], ``friction_coefficient`` C_f (eq 34),
    ``contact_load`` (integral of p_con) [N].
    Fields (ny, nx): ``pressure`` p_hd, ``contact_pressure`` p_con [Pa], ``cavity_fraction``,
    ``h0``, ``mean_gap`` h_m, ``elastic_deformation`` h_el [m], ``viscosity`` [Pa s],
    ``density_ratio`` rho/rho_0, ``shear_stress`` tau_tot [Pa], ``face`` (pin face mask).
    ``history``: rows (iteration, r_hel, r_pcon, r_p, r_F, h_d, newton steps).
    """

    speed: float
    imposed_load: float
    normal_load: float
    h_d: float
    friction_force: float
    hydrodynamic_friction: float
    boundary_friction: float
    friction_coefficient: float
    contact_load: float
    spacing: tuple
    pressure: np.ndarray
    contact_pressure: np.ndarray
    cavity_fraction: np.ndarray
    h0: np.ndarray
    mean_gap: np.ndarray
    elastic_deformation: np.ndarray
    viscosity: np.ndarray
    density_ratio: np.ndarray
    shear_stress: np.ndarray
    face: np.ndarray
    iterations: int = 0
    history: np.ndarray = field(default_factory=lambda: np.zeros((0, 7)))
    meta: dict = field(default_factory=dict)

    def fields(self) -> dict:
        """The grid fields by name (for VTU output)."""
        return {k: np.asarray(getattr(self, k), float) for k in _FIELDS}

    def scalars(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)
                if f.name not in _FIELDS and f.name not in ("history", "meta")}

    def save(self, path) -> Path:
        """Write ``.npz`` (fields, history, scalars and meta as JSON) atomically."""
        path = Path(path)
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as f:
                np.savez(f, **self.fields(), history=self.history,
                         scalars=np.array(json.dumps(self.scalars())),
                         meta=np.array(json.dumps(self.meta, sort_keys=True)))
        return path

    @classmethod
    def load(cls, path) -> "MixedResult":
        with np.load(path) as data:
            scalars = json.loads(str(data["scalars"]))
            scalars["spacing"] = tuple(scalars["spacing"])
            arrays = {k: data[k] for k in _FIELDS}
            arrays["face"] = arrays["face"].astype(bool)
            return cls(**scalars, **arrays, history=data["history"],
                       meta=json.loads(str(data["meta"])))

    def write_vtu(self, path, origin=(0.0, 0.0)) -> Path:
        """Fields on the structured grid for ParaView (:func:`fem_twin.io.mesh.write_vtu`),
        SI units; ``pressure`` is absolute (its minimum is p_cav), ``pressure_gauge`` is
        ``pressure - p_amb``; ``face`` is 1 on the pin face (threshold on it in ParaView)."""
        from ..io.mesh import grid_mesh, write_vtu
        gm = grid_mesh(self.pressure.shape, self.spacing, origin)
        p_amb = self.meta.get("settings", {}).get("ambient_pressure", 0.0)
        return write_vtu(path, gm, {**self.fields(), "pressure_gauge": self.pressure - p_amb})


@one_thread
def solve_mixed(gap, spacing, factors: FlowFactors, *, load: float, speed: float,
                entrainment: float | None = None,
                lubricant: Lubricant, face=None, settings: MacroSettings = MacroSettings(),
                initial: MixedResult | None = None, progress=None) -> MixedResult:
    """Solve one operating point of the homogenised mixed-EHL problem.

    Parameters
    ----------
    gap : (ny, nx) rigid gap ``h_g = x3_up - x3_low`` of the macro geometry [m]; x1 (the
        sliding direction of the disk) along the columns
    spacing : (dx1, dx2) [m]
    factors : flow factors of the micro scale (patch average)
    load : imposed normal load F_N,imp [N]
    speed : sliding speed U of the disk [m/s] (``u_r = U``; ``u_m = U/2`` on a pin)
    entrainment : mean speed ``u_m`` of the surfaces [m/s] when it is not ``U/2``: a ball on
        a disk at slide-to-roll ratio ``SRR = u_r / u_m`` has ``speed = SRR u_m`` (eq 17 takes
        u_m, the shear of eq 31 both); a pure rolling contact is approached with a small SRR
    lubricant : mu_0 and the constants of eqs 23-24
    face : (ny, nx) bool, the pin face for the friction integral (eq 33); all if None
    initial : a result to warm-start from (e.g. the neighbouring speed of a sweep)
    progress : optional callable ``progress(iteration, residual)``
    """
    h_g = np.asarray(gap, float)
    if h_g.ndim != 2 or min(h_g.shape) < 3:
        raise ValueError(f"gap must be a 2D field of at least 3 x 3 nodes, got {h_g.shape}")
    if not np.all(np.isfinite(h_g)):
        raise ValueError("gap contains NaN or inf: repair the topography first")
    if not (load > 0 and np.isfinite(load)):
        raise ValueError(f"load must be a positive force [N], got {load}")
    if not (speed > 0 and np.isfinite(speed)):
        raise ValueError(f"speed must be positive [m/s], got {speed}")
    u_m = speed / 2 if entrainment is None else float(entrainment)
    if not (u_m > 0 and np.isfinite(u_m)):
        raise ValueError(f"entrainment speed must be positive [m/s], got {entrainment}")
    dx = tuple(float(v) for v in np.broadcast_to(np.asarray(spacing, float), (2,)))
    face = np.ones(h_g.shape, bool) if face is None else np.asarray(face, bool)
    if face.shape != h_g.shape:
        raise ValueError(f"face mask {face.shape} does not match the gap {h_g.shape}")
    s = settings
    t0 = time.perf_counter()
    op = elastic_operator(h_g.shape, dx, s.e_reduced)
    boundary = np.zeros(h_g.shape, bool)
    boundary[[0, -1], :] = boundary[:, [0, -1]] = True
    area = trapezoid_weights(h_g.shape, dx)

    def poiseuille(g, A):
        if s.method == "fe":
            return fe_poiseuille(g, dx, A)
        return fvm_poiseuille(g, dx, A)

    if initial is None and min(h_g.shape) >= 2 * COARSE_START:
        # cold start on the grid coarsened by 2 (recursively), to a looser tolerance
        coarse = replace(s, tol=max(s.tol, 1e-4))
        try:
            initial = solve_mixed(h_g[::2, ::2], (2 * dx[0], 2 * dx[1]), factors, load=load,
                                  speed=speed, entrainment=entrainment,
                                  lubricant=lubricant, face=face[::2, ::2],
                                  settings=coarse)
        except MixedNotConverged:
            initial = None          # too coarse to resolve the contact: start on this grid
    if initial is not None:
        initial = _on_grid(initial, h_g.shape, dx)
    P = newton.Problem(h_g, dx, factors, lubricant, s, poiseuille, op, area,
                       np.flatnonzero(~boundary.ravel()), speed, u_m)
    if s.coupling == "newton" or (s.coupling == "auto" and initial is not None
                                  and initial.meta.get("coupling") == "newton"):
        return _solve_newton(P, load, face, initial, progress, t0)
    try:
        return _solve_fixed_point(P, load, face, initial, progress, t0)
    except (MixedNotConverged, _Concentrated):
        if s.coupling != "auto":
            raise
        return _solve_newton(P, load, face, initial, progress, t0)


class _Concentrated(Exception):
    """The ``"auto"`` coupling's signal: the contact needs the Newton coupling."""


def _solve_fixed_point(P, load, face, initial, progress, t0):
    """The ``"anderson"`` and ``"pid"`` couplings (see the module docstring)."""
    h_g, dx, factors, lubricant, s = P.gap, P.spacing, P.factors, P.lubricant, P.settings
    op, poiseuille, area = P.elastic, P.poiseuille, P.area
    boundary = P.boundary
    u_m = P.entrainment
    p_amb_rel = s.ambient_pressure - s.cavitation_pressure
    scale = s.p_ref                                     # theta = -phi / scale in cavities
    state = {"phi": None, "p": np.full(h_g.shape, p_amb_rel), "newton": 0}
    solver = complementarity_solver(s.complementarity)
    if initial is not None:
        state["p"] = initial.pressure - s.cavitation_pressure
        theta0 = initial.cavity_fraction
        state["phi"] = np.where(theta0 > 0, -theta0 * scale, np.maximum(state["p"], 0)).ravel()

    def evaluate(h_el, h_d, p_con=None):
        """Reynolds at the current state; returns everything the updates need."""
        h0 = np.maximum(h_d + h_g + h_el, s.gap_floor)
        loc = factors.at(h0)
        p_prev = state["p"]
        p_coef = np.minimum(p_prev, newton.MAX_COEFFICIENT_PRESSURE)
        mu = lubricant.viscosity_at(p_coef)
        rho = lubricant.density_ratio(p_coef)
        g = rho * loc.h_m ** 3 / (12 * mu)
        q = rho * loc.h_m * u_m
        K = poiseuille(g, loc.A)
        B = upwind_couette(q * loc.b[..., 0], q * loc.b[..., 1], dx)
        phi, its, _ = solver(K, B, boundary, p_amb_rel, scale, phi0=state["phi"])
        state["phi"], state["newton"] = phi, its
        p = np.maximum(phi, 0).reshape(h_g.shape)
        theta = (np.maximum(-phi, 0) / scale).reshape(h_g.shape)
        state["p"] = p
        p_con_target = loc.p_con
        p_con_used = p_con_target if p_con is None else p_con
        p_tot = p + s.cavitation_pressure + p_con_used
        F = float(np.sum(area * (p_tot - s.ambient_pressure)))
        return dict(h0=h0, loc=loc, mu=mu, rho=rho, p=p, theta=theta, p_prev=p_prev,
                    p_con_target=p_con_target, p_con=p_con_used, F=F,
                    F_hd=float(np.sum(area * (p + s.cavitation_pressure - s.ambient_pressure))),
                    h_el_new=op(p_tot - s.ambient_pressure))

    # initial state
    if initial is not None:
        h_el, h_d = initial.elastic_deformation.copy(), float(initial.h_d)
        p_con = initial.contact_pressure.copy()
    else:
        h_el = np.zeros(h_g.shape)
        def excess(hd):
            state["phi"] = None                    # cold inner start: the states differ a lot
            state["p"] = np.full(h_g.shape, p_amb_rel)
            return evaluate(h_el, hd)["F"] - load

        h_free = float(factors.h0[-1]) - float(h_g[face].min())
        h_d = rigid_separation(excess, h_free, dry_separation(factors, h_g, area, load, s),
                                float(factors.h0[-1]))
        state["p"] = np.full(h_g.shape, p_amb_rel)
        p_con = factors.contact_pressure(np.maximum(h_d + h_g, s.gap_floor))
    history = []
    r_prev = [0.0, 0.0]
    mixer = Anderson(s.anderson_depth)
    p_con_prev = p_con
    good, retries, best, stall = None, 0, np.inf, 0
    for it in range(1, s.max_iter + 1):
        try:
            ev = evaluate(h_el, h_d, p_con if s.coupling == "pid" else None)
        except ReynoldsNotConverged as err:
            # an over-long step (gap far too thin): halve it and restart the mixing
            retries += 1
            if good is None or retries > 12:
                raise MixedNotConverged(f"the Reynolds solve failed at iteration {it}: {err}",
                                        history) from err
            h_el, h_d = (h_el + good[0]) / 2, (h_d + good[1]) / 2
            state["phi"], state["p"] = good[2], good[3]
            mixer = Anderson(s.anderson_depth)
            history.append((it, np.nan, np.nan, np.nan, np.nan, h_d, -1))
            continue
        retries = 0
        if it == 1 and s.coupling == "auto" and elastic_ratio(ev, op, s) > ELASTIC_RATIO:
            raise _Concentrated
        good = (h_el, h_d, state["phi"], ev["p_prev"])
        stall += 1
        r_F = (ev["F"] - load) / load
        r_hel = float(np.abs(ev["h_el_new"] - h_el).max() / s.h_ref)
        r_p = float(np.abs(ev["p"] - ev["p_prev"]).max() / s.p_ref)
        if s.coupling == "pid":
            delta = ev["p_con_target"] - p_con                     # eq 25
            r_pcon = float(np.abs(delta).max() / s.p_ref)          # eq 27
        else:
            r_pcon = float(np.abs(ev["p_con_target"] - p_con_prev).max() / s.p_ref)
            p_con_prev = ev["p_con_target"]
        res = max(r_hel, r_pcon, r_p, abs(r_F))
        history.append((it, r_hel, r_pcon, r_p, r_F, h_d, state["newton"]))
        if progress is not None:
            progress(it, res)
        if res < s.tol and it > 1:
            break
        if res < 0.5 * best:
            best, stall = res, 0
        elif stall > 25:                   # Anderson mixing stagnates: restart its history
            mixer, best, stall = Anderson(s.anderson_depth), res, 0
        if s.coupling == "pid":
            p_con = p_con + s.relaxation_pcon * delta               # eq 26
            kp, ki, kd = s.gains
            r1, r2 = r_prev
            h_d += (kp * (r_F - r1) + ki * r_F + kd * (r_F - 2 * r1 + r2)) * 1e-6   # eq 29
            r_prev = [r_F, r1]
            h_el = h_el + s.relaxation_elastic * (ev["h_el_new"] - h_el)
        else:
            k = _load_stiffness(factors, ev, area, s)
            g_hel = ev["h_el_new"]
            g_hd = h_d + (ev["F"] - load) / k
            x = np.r_[h_el.ravel(), h_d] / s.h_ref
            f = np.r_[g_hel.ravel(), g_hd] / s.h_ref - x
            step = mixer.step(x, f) - x
            # trust region: no step moves the surfaces by more than half the thinnest film
            bound = 0.5 * max(float(ev["h0"][face].min()), 1e-8) / s.h_ref
            step *= min(1.0, bound / max(float(np.abs(step).max()), 1e-300))
            x = (x + step) * s.h_ref
            h_el, h_d = x[:-1].reshape(h_g.shape), float(x[-1])
    else:
        raise MixedNotConverged(
            f"macro iteration ({s.coupling}) did not reach residuals below {s.tol} in "
            f"{s.max_iter} iterations (last: h_el {r_hel:.2e}, p_con {r_pcon:.2e}, "
            f"p {r_p:.2e}, load {r_F:.2e})", history)
    return _result(ev, h_el, h_d, P, load, face, it, history,
                   time.perf_counter() - t0)


def _solve_newton(P, load, face, initial, progress, t0):
    """The ``"newton"`` coupling (:mod:`.newton`): warm from ``initial``, else by load
    continuation from the rigid film."""
    s = P.settings
    max_iter = min(s.max_iter, NEWTON_MAX_ITER)
    if initial is None:
        x, ev, it, history = newton.continuation(P, load, tol=s.tol, max_iter=max_iter,
                                                 progress=progress)
    else:
        x, ev, it, history = newton.solve(P, newton.state_from(initial, s), load, tol=s.tol,
                                          max_iter=max_iter, progress=progress)
    return _result(ev, x.w, x.h_d, P, load, face, it, history, time.perf_counter() - t0,
                   coupling="newton")


def elastic_ratio(ev, op, s) -> float:
    """Largest elastic deformation by the film pressure over the thinnest film under
    pressure, at the first iterate: large for a concentrated contact (smooth balls:
    25-4000), small for a conformal pin (0.2-6.4)."""
    p_gauge = ev["p"] + s.cavitation_pressure - s.ambient_pressure
    loaded = p_gauge > 0
    if not loaded.any():
        return 0.0
    return float(np.abs(op(np.maximum(p_gauge, 0))).max()) / float(ev["h0"][loaded].min())


def _result(ev, h_el, h_d, P, load, face, it, history, seconds, coupling=None):
    s, dx, area, speed, lubricant = P.settings, P.spacing, P.area, P.speed, P.lubricant
    loc = ev["loc"]
    p_hd = ev["p"] + s.cavitation_pressure
    tau_hd = hydrodynamic_shear(p_hd, loc.h_m, ev["theta"], ev["mu"], loc.C, loc.d, dx, speed,
                                entrainment=P.entrainment,
                                eyring_stress=lubricant.eyring_stress)
    tau_con = boundary_shear(ev["p_con"], s.boundary_friction)
    cell = dx[0] * dx[1]
    F_hd = float(tau_hd[face].sum() * cell)
    F_con = float(tau_con[face].sum() * cell)
    F_N = ev["F"]
    return MixedResult(
        speed=float(speed), imposed_load=float(load), normal_load=F_N, h_d=float(h_d),
        friction_force=F_hd + F_con, hydrodynamic_friction=F_hd, boundary_friction=F_con,
        friction_coefficient=(F_hd + F_con) / F_N,
        contact_load=float(np.sum(area * ev["p_con"])), spacing=dx,
        pressure=p_hd, contact_pressure=ev["p_con"], cavity_fraction=ev["theta"],
        h0=ev["h0"], mean_gap=loc.h_m, elastic_deformation=h_el,
        viscosity=ev["mu"], density_ratio=ev["rho"], shear_stress=tau_hd + tau_con,
        face=face, iterations=it, history=np.array(history),
        meta={"settings": {k: (list(v) if isinstance(v, tuple) else v)
                           for k, v in s.__dict__.items()},
              "lubricant": lubricant.__dict__.copy(), "seconds": seconds,
              "coupling": coupling or ("anderson" if s.coupling == "auto" else s.coupling),
              "entrainment": P.entrainment})


def _on_grid(result: MixedResult, shape, dx) -> MixedResult:
    """``result`` interpolated (linearly, by coordinates from the first node) onto a grid."""
    if result.pressure.shape == tuple(shape) and np.allclose(result.spacing, dx):
        return result
    from scipy.ndimage import map_coordinates
    rows = np.arange(shape[0]) * dx[1] / result.spacing[1]
    cols = np.arange(shape[1]) * dx[0] / result.spacing[0]
    where = np.meshgrid(rows, cols, indexing="ij")

    def interp(f):
        return map_coordinates(np.asarray(f, float), where, order=1, mode="nearest")

    return replace(result, spacing=tuple(dx), **{k: interp(getattr(result, k))
                                                 for k in _FIELDS if k != "face"},
                   face=interp(result.face) > 0.5)


def _load_stiffness(factors, ev, area, s):
    """-dF/dh_d estimate [N/m]: contact slope of p_con(h0) plus 2 F_hd / h (hydrodynamic)."""
    h0 = ev["h0"]
    eps = 1e-3 * h0
    dp = (factors.contact_pressure(h0 - eps) - factors.contact_pressure(h0 + eps)) / (2 * eps)
    k_con = float(np.sum(area * np.maximum(dp, 0)))
    loaded = ev["p"] > ev["p"].max() * 0.1 if ev["p"].max() > 0 else np.ones(h0.shape, bool)
    h_char = float(np.average(h0[loaded], weights=ev["p"][loaded] + 1e-30))
    k_hd = 2 * max(ev["F_hd"], 0.0) / max(h_char, s.gap_floor)
    return max(k_con + k_hd, 1e-3 * abs(ev["F"]) / s.h_ref + 1e-300)
