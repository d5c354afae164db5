"""Roughness-scale homogenisation of one pin/disk patch pair (paper 2.2.1, eqs 8-16).

For every rigid-body separation h0 the disk patch slides periodically along x1 over the pin
patch in ``n_steps`` time steps; at each step a periodic dry contact at imposed h0 gives the
asperity pressure and the deformed gap, then the three cell problems are solved and their
averages accumulated over space and time.

Kinematics.  The pin is at rest and the disk moves at ``U = 2 u_m``.  One pass of the disk
over the period ``L_r1`` takes ``T_r = L_r1 / U``; in ``N_t`` instants the disk patch shifts
by ``s = L_r1 / N_t`` each.  The gap is ``h = h0 + z_up(x1 - U t, x2) - z_low + w`` with the
contact deformation ``w``, so the time term of eq 8 is, exactly,

    tau = (1 / u_m) dh/dt = -2 d z_up / dx1 + (1 / u_m) dw/dt,

free of u_m.  The default ``time_derivative="exact"`` evaluates it at every instant (the
deformation rate from the tangent of the contact problem), so only the quadrature of the
time average over the ``N_t`` instants remains: the trapezoidal rule of a periodic function.
The paper's implicit Euler ``2 (h^n - h^(n-1)) / s`` (``time_derivative="backward"``) is
first order in ``1 / N_t`` and kept to reproduce the paper.  (The paper's
``dt = L_r1 / (N_t u_m)`` with a shift of ``L_r1 / N_t`` would be a disk moving at ``u_m``,
i.e. half the squeeze term.)

Frame identities (tested).  ``moving="lower"`` computes the same physics in the disk's frame:
the pin slides at ``-U`` and ``u_m -> -u_m``, and ``tau = -2 d(-z_low)/dx1 + ...``.  In that
frame the right-hand side of eq 8 is ``dh/dx1 + tau' = -(dh/dx1 + tau)`` (the sum is
``2 d h/dx1 - 2 d(h_rigid + w)/dx1 = 0``), so ``chi_1' = -chi_1`` and

    A' = A,  C' = C,  h_m' = h_m,  p_con' = p_con  (eqs 9, 10 do not see the motion),
    b' = 2 e1 - b  (from eq 14: <h (1 + h^2 d chi_1/dx1)> / h_m = 2 e1 - b),
    d' = -d        (eq 16 is linear in chi_1).

The same holds for a rough surface moving over a smooth one against the same surface at
rest under the smooth one.  Without contact the FVM satisfies these identities to
round-off (its Couette flux difference is the central difference used for ``tau``), the FE
to its second-order spatial error; with contact, to the discretisation of the contact edge.
"""

from __future__ import annotations

import json
import os
import time
from concurrent.futures import as_completed
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .. import __version__
from ..contact import contact_rate
from ..contact import solve as contact_solve
from ..contact.levelling import TABLE4
from ..checks import plausible
from ..errors import InputError
from ..io.atomic import atomic_path
from ..io.checkpoint import input_key, load_or_none
from ..threads import one_thread, process_pool, stop_pool, worker_heap
from ..topography import Topography
from ..topography.plausibility import check_patch
from .cell_fv import CellSolverFV
from .estimate import discrepancy, variants
from .flow_factors import ARRAYS, FlowFactors
from .sampling import adaptive_separations

#: the paper's separations: 100 values geometrically spaced in [0.1, 1] um
DEFAULT_H0 = np.geomspace(1e-7, 1e-6, 100)


@dataclass(frozen=True)
class CellSettings:
    """Everything besides the surfaces and h0 that the result depends on (SI units)."""

    n_steps: int = 32
    e_reduced: float = TABLE4["e_reduced"]
    hardness: float = TABLE4["hardness"]
    gap_floor: float = 1e-9
    method: str = "fe"
    moving: str = "upper"
    first_step: str = "steady"
    contact_tol: float = 1e-10
    time_derivative: str = "exact"
    rate_tol: float = 1e-6      # contact-rate CG: tau to 1e-6, far below time and grid errors
    time_tol: float | None = None   # adaptive instants per h0 (exact scheme), see _refine

    def __post_init__(self):
        if int(self.n_steps) != self.n_steps or self.n_steps < 1:
            raise InputError(f"n_steps must be a positive integer, got {self.n_steps}")
        if self.method not in ("fe", "fvm"):
            raise InputError(f"method must be 'fe' or 'fvm', got {self.method!r}")
        if self.moving not in ("upper", "lower"):
            raise InputError(f"moving must be 'upper' (disk) or 'lower' (pin), got {self.moving!r}")
        if self.time_derivative not in ("exact", "backward"):
            raise InputError("time_derivative must be 'exact' or 'backward' (paper), got "
                             f"{self.time_derivative!r}")
        if self.time_tol is not None and not (0 < self.time_tol < 1
                                              and self.time_derivative == "exact"):
            raise InputError("time_tol is a relative tolerance in (0, 1), with "
                             "time_derivative='exact' only")
        if self.first_step not in ("steady", "periodic"):
            raise InputError(f"first_step must be 'steady' or 'periodic', got {self.first_step!r}")
        if not (self.e_reduced > 0 and self.hardness > 0 and self.gap_floor > 0):
            raise InputError("e_reduced, hardness and gap_floor must be positive (Pa, Pa, m)")


@one_thread
def homogenise(pin: Topography, disk: Topography, h0=None, *, n_steps: int = 32,
               e_reduced: float = TABLE4["e_reduced"], hardness: float = TABLE4["hardness"],
               method: str = "fe", moving: str = "upper", time_derivative: str = "exact",
               first_step: str = "steady", gap_floor: float = 1e-9, workers: int = 1,
               executor=None, checkpoint=None, progress: bool = False, patch_id=None,
               error_estimate: bool = True, time_tol: float | None = None,
               h0_tol: float | None = None) -> FlowFactors:
    """Flow factors of a roughness patch pair versus h0 (eqs 11-16).

    Parameters
    ----------
    pin, disk : Topography
        Periodic roughness cells on the same grid, both with zero mean plane: ``pin`` the
        lower surface, ``disk`` the upper one already flipped over the pin (as
        :func:`fem_twin.topography.prepare.prepare_patch` with ``upper=True`` gives).  The gap
        is ``h0 + disk - pin + deformation``.
    h0 : rigid-body separations [m] (default: 100 values geometrically in [0.1, 1] um).
    n_steps : time steps N_t of one sliding pass (paper: 32).
    e_reduced, hardness : E' of eq 22 and the pressure cap H [Pa] (Table 4).
    method : ``"fe"`` (Q1 finite elements) or ``"fvm"`` (the paper's finite volumes).
    moving : ``"upper"``: the disk slides at ``+U`` over the pin at rest (the tribometer);
        ``"lower"``: the same seen from the disk (the pin slides at ``-U``).
    time_derivative : ``"exact"`` (default): the squeeze term of eq 8 at every instant from
        the translating surface and the contact rate, no time-step error (see
        :func:`sliding_squeeze`); ``"backward"``: the paper's implicit Euler difference.
    first_step : with ``"backward"`` only: ``"steady"`` (paper: no time term at the first
        step) or ``"periodic"`` (the last configuration precedes the first).
    workers : processes for the h0 values (1: in this process); ``executor``: any
        ``concurrent.futures``-style executor instead (e.g. ``dask.distributed``'s), with
        ``workers`` the processes serving it.  The h0 values go out as ``4 workers`` tasks
        (each warm-starts along its own h0 values), so a 64-worker cluster gets 100 tasks
        of one h0 from the paper's 100 values; with ``h0_tol``, the new points of each round
        of the adaptive sample go out so (9 to start with, then the bisected gaps).
    checkpoint : folder that keeps one file per finished h0; a rerun resumes from it.
    progress : show a progress bar (or a tqdm-like bar to advance, shared by several runs).
    patch_id : recorded in the metadata.
    error_estimate : estimate the time and grid errors (``meta["error_estimate"]``, see
        :mod:`fem_twin.micro.estimate`; about ``3 / (4 len(h0))`` of the run's cost).
    time_tol : adaptive instants (exact scheme): at each h0 the midpoints are added while
        A11 or b1 change by more than this relative tolerance from every other instant to
        all, up to one pixel per step; ``n_steps`` is then the smallest count
        (``meta["steps_used"]`` per h0).  0 or None (off, as in the case file): ``n_steps``
        everywhere.
    h0_tol : adaptive separations: ``h0`` is the dense candidate set and only the subset
        :func:`fem_twin.micro.sampling.adaptive_separations` needs is solved, so that the
        interpolant in log h0 misses the factors at the skipped candidates by less than
        this relative tolerance (its bound: ``meta["error_estimate"]["h0"]``).  0 or None
        (off, as in the case file): every ``h0``.
    """
    time_tol, h0_tol = time_tol or None, h0_tol or None       # 0 means off, as in the case
    settings = CellSettings(int(n_steps), float(e_reduced), float(hardness), float(gap_floor),
                            method, moving, first_step, time_derivative=time_derivative,
                            time_tol=time_tol)
    z_low, z_up, spacing = _check_patches(pin, disk)
    plausible("reduced modulus e_reduced [Pa]", e_reduced, "reduced_modulus")
    plausible("hardness [Pa]", hardness, "hardness")
    h0 = _check_separations(DEFAULT_H0 if h0 is None else h0)
    if h0_tol is not None and not 0 < h0_tol < 1:
        raise InputError(f"h0_tol is a relative tolerance in (0, 1), got {h0_tol}")
    key = _key(z_low, z_up, spacing, settings)
    args = dict(z_low=z_low, z_up=z_up, spacing=spacing, settings=settings,
                folder=None if checkpoint is None else str(checkpoint), key=key,
                half_pass=error_estimate)
    own_bar = not hasattr(progress, "update")
    bar = _progress(len(h0), progress, patch_id, h0_tol is not None) if own_bar else progress
    points = _Separations(h0, args, workers, executor, bar)
    try:
        if h0_tol is None:
            chosen, bound = list(range(len(h0))), None
        else:
            chosen, bound = adaptive_separations(h0, points.factors, h0_tol)
        moments = points.moments(chosen)
        bar.update(len(h0) - len(chosen))             # the candidates interpolated
        coarse = (_coarse_moments(points, chosen, z_low, z_up, spacing, settings, checkpoint)
                  if error_estimate else None)
    except BaseException:
        points.close(failed=True)
        raise
    else:
        points.close()
    finally:
        if own_bar:
            bar.close()
    meta = {"patch_id": patch_id, "shape": list(z_low.shape), "spacing": list(spacing),
            "e_reduced": settings.e_reduced, "hardness": settings.hardness,
            "gap_floor": settings.gap_floor, "n_steps": settings.n_steps,
            "method": settings.method, "moving": settings.moving,
            "first_step": settings.first_step, "time_derivative": settings.time_derivative,
            "version": __version__, "checkpoint_keys": [key], "time_tol": settings.time_tol,
            "h0_tol": h0_tol, "h0_candidates": len(h0),
            "steps_used": [int(m.get("n_steps", settings.n_steps)) for m in moments],
            "sq": float(np.hypot(z_low.std(), z_up.std())),
            "pin": pin.meta.get("sample", pin.meta.get("source")),
            "disk": disk.meta.get("sample", disk.meta.get("source")),
            "seconds": points.seconds()}
    factors = factors_from_moments(h0[chosen], moments, meta)
    if not error_estimate:
        return factors
    estimate = estimate_errors(factors, moments, coarse, settings)
    if bound is not None:
        estimate["h0"] = bound
    keys = meta["checkpoint_keys"] + estimate.pop("checkpoint_keys", [])
    moved = estimate.pop("variants")
    return replace(factors, meta={**meta, "error_estimate": estimate, "checkpoint_keys": keys,
                                  "variants": moved})


def _check_separations(h0) -> np.ndarray:
    h0 = np.asarray(h0, dtype=float)
    if h0.ndim != 1 or h0.size == 0 or not np.all(np.isfinite(h0)) or np.any(h0 <= 0):
        raise InputError("h0 must be a non-empty 1D array of positive separations [m]")
    if np.unique(h0).size != h0.size:
        raise InputError("h0 values must be distinct")
    return np.sort(h0)


class _Separations:
    """The moments at the separations ``h0[i]`` of one run: resumed from the checkpoint
    folder or computed (in this process, or as ``4 workers`` chunks on a pool or
    ``executor``, each large to small so that contact warm-starts along h0)."""

    def __init__(self, h0, args, workers, executor, bar):
        self.h0, self.args, self.workers, self.executor, self.bar = (h0, args, workers,
                                                                     executor, bar)
        self.done, self.computed, self.own = {}, [], False

    def factors(self, indices):
        """Eqs 11-16 at ``h0[indices]`` (sorted), and over every other instant (None
        without the time-error estimate)."""
        moments = self.moments(indices)
        half = (factors_from_moments(self.h0[indices], moments, {}, prefix="half_")
                if all("half_h" in m for m in moments) else None)
        return factors_from_moments(self.h0[indices], moments, {}), half

    def moments(self, indices) -> list:
        todo = [i for i in sorted(indices, reverse=True) if i not in self.done]
        folder = self.args["folder"]
        for i in todo:
            m = None if folder is None else _load_point(Path(folder), self.args["key"],
                                                        self.h0[i])
            if m is not None:
                self.done[i] = m
                self.bar.update(1)
        todo = [i for i in todo if i not in self.done]
        serial = self.workers <= 1 and self.executor is None
        chunks = [[(i, self.h0[i]) for i in c]
                  for c in _chunks(todo, 1 if serial else 4 * max(self.workers, 2))]
        for i, m in (self._serial(chunks) if serial else self._parallel(chunks)):
            self.done[i] = m
            self.computed.append(i)
            self.bar.update(1)
        return [self.done[i] for i in indices]

    def _serial(self, chunks):
        for chunk in chunks:
            yield from _run_chunk(chunk, **self.args)

    def _parallel(self, chunks):
        if self.executor is None:            # one own pool for all the calls of a run
            self.executor, self.own = process_pool(self.workers), True
        futures = [self.executor.submit(_chunk_task, (c, self.args)) for c in chunks]
        try:
            for fut in as_completed(futures):
                yield from fut.result()
        except BaseException:
            for fut in futures:
                fut.cancel()
            raise

    def close(self, failed: bool = False):
        if self.own:
            stop_pool(self.executor, failed)

    def seconds(self) -> dict:
        """CPU seconds of contact and cells over the computed (not resumed) separations."""
        done = [self.done[i] for i in self.computed]
        return {"contact": sum(m.get("seconds_contact", 0.0) for m in done),
                "cell": sum(m.get("seconds_cell", 0.0) for m in done),
                "computed_h0": len(done)}


def prune_checkpoints(folder, keep) -> int:
    """Delete the h0 checkpoints in ``folder`` (and ``folder/coarse``) whose key is not in
    ``keep`` (``FlowFactors.meta["checkpoint_keys"]``): left by other settings or surfaces.
    Returns the number of files removed."""
    removed = 0
    for path in (*Path(folder).glob("*_h0_*.json"), *Path(folder).glob("coarse/*_h0_*.json")):
        if path.name.split("_h0_")[0] not in keep:
            path.unlink()
            removed += 1
    return removed


def _coarse_moments(points, indices, z_low, z_up, spacing, settings, checkpoint):
    """``(moments, settings, key, shape)`` of the cell coarsened by two (every other pixel) at the
    separations ``h0[indices]``, with half the instants when the run has its half pass
    (the same pixels per step), on the run's workers; None for a small or odd cell."""
    if min(z_low.shape) < 16 or z_low.shape[0] % 2 or z_low.shape[1] % 2:
        return None
    low, up = z_low[::2, ::2].copy(), z_up[::2, ::2].copy()
    wide = (2 * spacing[0], 2 * spacing[1])
    if settings.n_steps % 2 == 0:
        settings = replace(settings, n_steps=settings.n_steps // 2)
    key = _key(low, up, wide, settings)
    args = dict(z_low=low, z_up=up, spacing=wide, settings=settings, key=key,
                folder=None if checkpoint is None else str(Path(checkpoint) / "coarse"),
                half_pass=False)
    runner = _Separations(points.h0, args, points.workers, points.executor,
                          _progress(len(indices), False))
    try:
        out = runner.moments(indices), settings, key, list(low.shape)
    except BaseException:
        runner.close(failed=True)            # only a pool of its own (the run's stays)
        raise
    runner.close()
    return out


def estimate_errors(factors, moments, coarse, settings) -> dict:
    """Time and grid error estimates (see :mod:`fem_twin.micro.estimate`): every other
    instant of this run, and the coarsened cell (``coarse``, from :func:`_coarse_moments`,
    compared with the pass of as many instants); ``"variants"``: the factors with each
    error added (:func:`fem_twin.micro.estimate.variants`)."""
    out, half, grid = {}, None, None
    if all("half_h" in m for m in moments):
        half = factors_from_moments(factors.h0, moments, {}, prefix="half_")
        out["time"] = discrepancy(factors, half)
        out["time_steps"] = [settings.n_steps, settings.n_steps // 2]
    if coarse is not None:
        coarse_moments, coarse_settings, key, shape = coarse
        other = factors_from_moments(factors.h0, coarse_moments, {})
        same = half if coarse_settings.n_steps != settings.n_steps else factors
        out["grid"] = discrepancy(same, other)
        out["grid_shape"], out["grid_steps"] = shape, coarse_settings.n_steps
        grid = replace(factors, meta={}, **{k: getattr(factors, k) + getattr(other, k)
                                            - getattr(same, k) for k in ARRAYS[1:]})
        out["checkpoint_keys"] = [key]
    out["variants"] = variants(factors, half, grid)
    return out


def factors_from_moments(h0, moments, meta, prefix: str = "") -> FlowFactors:
    """Eqs 11-16 from space-time averaged moments (see :meth:`CellSolver.moments`);
    ``prefix="half_"`` takes the averages over every other instant."""
    def get(key):
        return np.array([m[prefix + key] for m in moments])

    h_m = get("h")
    return FlowFactors(h0=np.asarray(h0, float), h_m=h_m, p_con=get("p_con"),
                       A=get("h3_grad") / h_m[:, None, None] ** 3,
                       b=np.array([1.0, 0.0]) - get("h3_g1") / h_m[:, None],
                       C=get("h_grad") / h_m[:, None, None], d=get("h_g1") * h_m[:, None],
                       contact_fraction=get("contact_fraction"), meta=meta)


# -- one patch pair, a chunk of separations ------------------------------------------------
@dataclass(frozen=True, eq=False)
class SlidingPass:
    """One periodic pass of the moving surface over the cell, in ``N_t`` instants.

    Attributes
    ----------
    shapes
        undeformed gap geometry ``z_up - z_low`` at each instant [m]
    moving
        the moving surface's part of that geometry at each instant (``z_up`` shifted for
        the disk, ``-z_low`` shifted for the pin in the disk's frame) [m]
    um_dt
        ``u_m dt`` between instants [m], ``+s/2`` (disk moving) or ``-s/2`` (pin)
    rigid_rate
        ``-2 d(moving)/dx1`` at each instant, the rigid part of the squeeze term of eq 8
        (central difference, the discrete derivative of the Couette flux) [-]
    """

    shapes: list
    moving: list
    um_dt: float
    rigid_rate: list


def sliding_pass(z_low, z_up, spacing, settings: CellSettings, n_steps: int | None = None,
                 offset: float = 0.0) -> SlidingPass:
    """The moving surface shifts by ``s = L_r1 / N_t`` per step (``+s`` for the disk, ``-s``
    for the pin in the disk's frame); ``u_m dt = (shift_up + shift_low) / 2``.  The instants
    are ``(k + offset) s`` for ``k < N_t`` (``offset = 1/2``: the midpoints)."""
    nx = z_low.shape[1]
    n_steps = settings.n_steps if n_steps is None else n_steps
    px = nx / n_steps                            # pixels per step
    n = [(k + offset) * px for k in range(n_steps)]
    if settings.moving == "upper":
        moving = [_shift(z_up, k) for k in n]
        shapes, um_dt = [m - z_low for m in moving], px * spacing[0] / 2
    else:
        moving = [-_shift(z_low, -k) for k in n]
        shapes, um_dt = [z_up + m for m in moving], -px * spacing[0] / 2
    return SlidingPass(shapes, moving, um_dt, [-2.0 * _d_dx1(m, spacing[0]) for m in moving])


def _shift(z, px):
    """Periodic translation of ``z`` by ``px`` pixels along x1 (Fourier for fractions)."""
    if px == 0:
        return z
    if float(px).is_integer():
        return np.roll(z, int(px), axis=1)
    k = np.fft.rfftfreq(z.shape[1])
    return np.fft.irfft(np.fft.rfft(z, axis=1) * np.exp(-2j * np.pi * k * px), n=z.shape[1],
                        axis=1)


def _d_dx1(z, dx1):
    """Periodic central difference along x1 (the Couette flux difference of the FVM)."""
    return (np.roll(z, -1, axis=1) - np.roll(z, 1, axis=1)) / (2 * dx1)


def _cell_solver(shape, spacing, method):
    if method == "fe":
        from .cell import CellSolver
        return CellSolver(shape, spacing)
    return CellSolverFV(shape, spacing)


def sliding_contacts(shapes, spacing, settings: CellSettings, h0: float, warm=None):
    """Periodic contact at imposed ``h0`` for each step's shape; ``warm`` (a list, one
    pressure or None per step) is used as the initial guess and updated in place."""
    warm = [None] * len(shapes) if warm is None else warm
    results = []
    for n, s in enumerate(shapes):
        r = contact_solve(s, spacing, settings.e_reduced, separation=h0,
                          hardness=settings.hardness, periodic=True,
                          gap_floor=settings.gap_floor, initial_pressure=warm[n],
                          tol=settings.contact_tol)
        warm[n] = r.pressure if r.load > 0 else None
        results.append(r)
    return results


def sliding_squeeze(contacts, sliding: SlidingPass, spacing, settings: CellSettings):
    """The squeeze term ``tau = (1/u_m) dh/dt`` of eq 8 at each instant (None: steady).

    ``"exact"``: the moving surface translates at ``V = 2 u_m``, so the rate of the rigid
    geometry is ``sliding.rigid_rate`` exactly at every instant; the contact deformation
    adds ``K p'`` from
    :func:`fem_twin.contact.contact_rate`; ``tau = 0`` where the gap sits at the floor.
    No time-step error: the time average of eqs 11-16 over the ``N_t`` instants is then the
    trapezoidal rule of a periodic function.
    ``"backward"`` (paper): ``(h^n - h^(n-1)) / (u_m dt)``, the first step steady
    (``first_step="steady"``) or preceded by the last (``"periodic"``); first order.
    """
    if settings.time_derivative == "backward":
        gaps = [r.gap for r in contacts]
        steady = settings.first_step == "steady"
        return [None if (n == 0 and steady) else (h - gaps[n - 1]) / sliding.um_dt
                for n, h in enumerate(gaps)]
    out = []
    for r, rigid in zip(contacts, sliding.rigid_rate):
        _, elastic = contact_rate(r, rigid, spacing, settings.e_reduced,
                                  hardness=settings.hardness, periodic=True,
                                  tol=settings.rate_tol)
        out.append(np.where(r.raw_gap > settings.gap_floor, rigid + elastic, 0.0))
    return out


def sliding_cells(gaps, squeezes, solver):
    """Cell solutions of each step for its gap and squeeze term."""
    for h, tau in zip(gaps, squeezes):
        yield solver.solve(h, tau)


@one_thread
def _chunk_task(job):
    """``_run_chunk`` as one positional argument: executors may own keywords (Dask's
    ``submit`` takes ``key`` for itself)."""
    worker_heap()
    points, args = job
    return _run_chunk(points, **args)


def _run_chunk(points, *, z_low, z_up, spacing, settings, folder, key, resume=False,
               half_pass=True):
    """Moments for ``points = [(index, h0), ...]`` in order, warm-starting contact."""
    solver = _cell_solver(z_low.shape, spacing, settings.method)
    sliding = sliding_pass(z_low, z_up, spacing, settings)
    warm, midpoints = [None] * settings.n_steps, {}
    out = []
    for i, h0 in points:
        if resume and folder is not None:
            m = _load_point(Path(folder), key, h0)
            if m is not None:
                out.append((i, m))
                continue
        contacts, steps, seconds = _instants(sliding, h0, warm, solver, spacing, settings)
        if settings.time_tol is not None:
            contacts, steps, more = _refine(contacts, steps, h0, z_low, z_up, solver, spacing,
                                            settings, midpoints)
            seconds = [a + b for a, b in zip(seconds, more)]
        moments = _time_average(steps)
        moments["n_steps"] = len(steps)
        if half_pass and settings.n_steps % 2 == 0:   # N_t / 2 instants: time-error estimate
            half = _half_pass(steps, contacts, sliding, solver, spacing, settings)
            moments.update({"half_" + k: v for k, v in _time_average(half).items()})
        moments["seconds_contact"], moments["seconds_cell"] = seconds
        if folder is not None:
            _save_point(Path(folder), key, h0, moments)
        out.append((i, moments))
    return out


def _instants(sliding, h0, warm, solver, spacing, settings):
    """Contacts and cell moments at the instants of ``sliding``; (contact, cell) seconds."""
    t0 = time.perf_counter()
    contacts = sliding_contacts(sliding.shapes, spacing, settings, h0, warm)
    squeezes = sliding_squeeze(contacts, sliding, spacing, settings)
    t1 = time.perf_counter()
    steps = [cell.moments for cell in
             sliding_cells([r.gap for r in contacts], squeezes, solver)]
    for m, r in zip(steps, contacts):
        m["p_con"], m["contact_fraction"] = float(r.pressure.mean()), r.contact_fraction
    return contacts, steps, [t1 - t0, time.perf_counter() - t1]


def _time_error(steps) -> float:
    """Relative change of A11 and b1 (eqs 13, 14) from every other instant to all."""
    def a11_b1(ms):
        m = _time_average(ms)
        return np.array([m["h3_grad"][0, 0] / m["h"] ** 3, 1 - m["h3_g1"][0] / m["h"]])
    full, half = a11_b1(steps), a11_b1(steps[::2])
    return float(np.max(np.abs(full - half) / np.abs(full)))


def _refine(contacts, steps, h0, z_low, z_up, solver, spacing, settings, midpoints):
    """Adaptive instants (``settings.time_tol``, exact scheme): while A11 or b1 change by
    more than the tolerance from every other instant to all, add the midpoints (the time
    average is then over twice the instants), up to one pixel per step.  In heavy contact
    the integrand jumps whenever a pixel enters contact, and a fixed N_t samples it
    unevenly; light contact stops at ``n_steps``.  ``midpoints`` keeps each level's pass and
    warm starts across the separations of a chunk."""
    seconds = [0.0, 0.0]
    while _time_error(steps) > settings.time_tol and 2 * len(steps) <= z_low.shape[1]:
        n = len(steps)
        if n not in midpoints:
            midpoints[n] = (sliding_pass(z_low, z_up, spacing, settings, n_steps=n,
                                         offset=0.5), [None] * n)
        mid, warm = midpoints[n]
        c, m, sec = _instants(mid, h0, warm, solver, spacing, settings)
        contacts = [x for pair in zip(contacts, c) for x in pair]
        steps = [x for pair in zip(steps, m) for x in pair]
        seconds = [a + b for a, b in zip(seconds, sec)]
    return contacts, steps, seconds


def _half_pass(steps, contacts, sliding, solver, spacing, settings):
    """Moments of the pass with ``N_t / 2`` instants: every other instant; the backward
    difference quotient is redone over the doubled step (its error is not in the sampling)."""
    if settings.time_derivative == "exact":
        return steps[::2]
    half = SlidingPass(sliding.shapes[::2], sliding.moving[::2], 2 * sliding.um_dt,
                       sliding.rigid_rate[::2])
    squeezes = sliding_squeeze(contacts[::2], half, spacing, settings)
    out = [cell.moments for cell in
           sliding_cells([r.gap for r in contacts[::2]], squeezes, solver)]
    for m, full in zip(out, steps[::2]):
        m["p_con"], m["contact_fraction"] = full["p_con"], full["contact_fraction"]
    return out


def _time_average(steps):
    """Mean of each moment over the instants (the trapezoidal rule of a periodic function)."""
    return {k: sum(m[k] for m in steps) / len(steps) for k in steps[0]}


def _chunks(indices, n):
    n = max(1, min(n, len(indices)))
    return [list(c) for c in np.array_split(np.asarray(indices, dtype=int), n) if len(c)]


# -- checkpoints ----------------------------------------------------------------------------
def _check_patches(pin, disk):
    for name, t in (("pin", pin), ("disk", disk)):
        if not isinstance(t, Topography):
            raise InputError(f"{name} must be a Topography, got {type(t).__name__}")
        if not np.all(np.isfinite(t.heights)):
            raise InputError(f"{name} patch has invalid (NaN) pixels: fill them first")
    if pin.shape != disk.shape:
        raise InputError(f"pin {pin.shape} and disk {disk.shape} patches differ in shape")
    if not np.allclose(pin.spacing, disk.spacing, rtol=1e-6):
        raise InputError(f"pin {pin.spacing} and disk {disk.spacing} pixel pitches differ [m]")
    if min(pin.shape) < 4:
        raise InputError(f"a roughness cell needs at least 4 x 4 pixels, got {pin.shape}")
    for name, t in (("pin", pin), ("disk", disk)):   # unit slips of 1e3 (warnings: CLI);
        if t.rms_height() > 0:                          # a smooth surface is a valid limit
            check_patch(t, f"{name} patch")
    return (np.ascontiguousarray(pin.heights, float), np.ascontiguousarray(disk.heights, float),
            tuple(float(s) for s in pin.spacing))


def _key(z_low, z_up, spacing, settings) -> str:
    return input_key(np.asarray(z_low), np.asarray(z_up), list(spacing), settings.__dict__)


def _point_path(folder: Path, key: str, h0: float) -> Path:
    return folder / f"{key}_h0_{h0:.9e}.json"


def _save_point(folder, key, h0, moments):
    data = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in moments.items()}
    path = _point_path(folder, key, h0)
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps({"h0": float(h0), "moments": data}))


#: the moments a checkpoint must hold (eqs 11-16)
_MOMENTS = ("h", "h3_grad", "h3_g1", "h_grad", "h_g1", "p_con", "contact_fraction")


def _read_point(path):
    data = json.loads(path.read_text())
    moments = {k: (np.array(v) if isinstance(v, list) else v)
               for k, v in data["moments"].items()}
    missing = [k for k in _MOMENTS if k not in moments]
    if missing or not np.all([np.all(np.isfinite(moments[k])) for k in _MOMENTS]):
        raise InputError(f"checkpoint lacks or has non-finite moments {missing or ''}")
    return moments


def _load_point(folder, key, h0):
    return load_or_none(_point_path(folder, key, h0), _read_point)


def _progress(total, enabled, patch_id=None, adaptive=False):
    """Bar over the h0 values (adaptive: over the candidates, of which a part is solved)."""
    from tqdm.auto import tqdm
    desc = f"homogenise {patch_id or 'h0'}" + (" (adaptive h0)" if adaptive else "")
    return tqdm(total=total, desc=desc, unit="h0",
                disable=not enabled or os.environ.get("FEM_TWIN_NO_PROGRESS") == "1")
