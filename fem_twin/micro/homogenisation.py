"""Roughness-scale homogenisation of one pin/disk patch pair (paper 2.2.1, eqs 8-16).

For every rigid-body separation h0 the disk patch slides periodically along x1 over the pin
patch in ``steps`` time steps; at each step a periodic dry contact at imposed h0 gives the
asperity pressure and the deformed gap, then the three cell problems are solved and their
averages accumulated over space and time.

The physics of one pass (kinematics, the squeeze term, the frame identities) is in
:mod:`fem_twin.micro.sliding`; which separations run where, in :mod:`fem_twin.micro.schedule`;
the per-h0 checkpoints, in :mod:`fem_twin.micro.store`.
"""

from __future__ import annotations

from dataclasses import fields, replace

import numpy as np

from .. import __version__
from ..checks import plausible
from ..errors import InputError
from ..numerics.threads import one_thread
from ..topography import Topography
from ..topography.plausibility import check_patch
from .estimate import QUANTITIES, discrepancy, variants, watched
from .flow_factors import ARRAYS, FlowFactors
from .sampling import adaptive_separations
from .schedule import Separations, coarse_moments, progress_bar
from .sliding import CellSettings, factors_from_moments, film_spread, whole_pixel_steps
from .store import cell_key

#: the paper's separations: 100 values geometrically spaced in [0.1, 1] um
H0_MIN, H0_MAX, H0_COUNT = 1e-7, 1e-6, 100


def h0_candidates(h0_min: float = H0_MIN, h0_max: float = H0_MAX,
                  count: int = H0_COUNT) -> np.ndarray:
    """The separations h0 [m] a micro stage may solve: ``count`` values geometrically
    spaced from ``h0_min`` to ``h0_max`` (the paper's 100 in [0.1, 1] um by default)."""
    return np.geomspace(h0_min, h0_max, count)


DEFAULT_H0 = h0_candidates()


@one_thread
def homogenise(pin: Topography, disk: Topography, h0=None, *,
               settings: CellSettings | None = None, workers: int = 1, executor=None,
               checkpoint=None, progress: bool = False, patch_id=None,
               error_estimate: bool = True, h0_tol: float | None = None,
               friction: str = "pin", **shortcuts) -> FlowFactors:
    """Flow factors of a roughness patch pair versus h0 [m] (eqs 11-16).

    ``pin`` and ``disk``: periodic cells on one grid, zero mean plane, the disk flipped over
    the pin (:func:`fem_twin.topography.prepare.prepare_patch`); the gap is ``h0 + disk -
    pin + deformation``.  ``h0`` default: 100 values in [0.1, 1] um.  ``settings``: a
    :class:`~fem_twin.micro.CellSettings`, or its fields as ``**shortcuts``.  ``workers``
    processes, or any ``executor`` (Dask's), take the h0 values as ``4 workers``
    warm-started tasks; ``checkpoint``: a folder keeping each finished h0 (a
    rerun resumes); ``progress``: a bar, or a bar to share; ``patch_id``: for the metadata.
    ``error_estimate``: the time and grid errors (:mod:`fem_twin.micro.estimate`).
    ``h0_tol``: solve only the subset of ``h0`` the log-h0 interpolant needs to miss the
    others by less than this fraction (:func:`fem_twin.micro.sampling.adaptive_separations`;
    0 or None: every h0), watching eq 31's factors alone when ``friction`` is ``"paper"``.
    """
    settings = _settings(settings, shortcuts)
    h0_tol = h0_tol or None                                  # 0 means off, as in the case
    z_low, z_up, spacing = check_patches(pin, disk)
    plausible("reduced modulus e_reduced [Pa]", settings.e_reduced, "reduced_modulus")
    plausible("hardness [Pa]", settings.hardness, "hardness")
    h0 = _check_separations(DEFAULT_H0 if h0 is None else h0)
    if h0_tol is not None and not 0 < h0_tol < 1:
        raise InputError(f"h0_tol is a relative tolerance in (0, 1), got {h0_tol}")
    whole_pixel_steps(z_low.shape[1], settings.steps)
    key = cell_key(z_low, z_up, spacing, settings)
    args = dict(z_low=z_low, z_up=z_up, spacing=spacing, settings=settings,
                folder=None if checkpoint is None else str(checkpoint), key=key,
                half_pass=error_estimate)
    own_bar = not hasattr(progress, "update")
    bar = progress_bar(len(h0), progress, patch_id, h0_tol is not None) if own_bar else progress
    points = Separations(h0, args, workers, executor, bar)
    try:
        chosen, bound, moments, coarse = _solve(points, h0, h0_tol, friction, bar, (
            z_low, z_up, spacing, settings, checkpoint) if error_estimate else None)
    except BaseException:
        points.close(failed=True)
        raise
    else:
        points.close()
    finally:
        if own_bar:
            bar.close()
    meta = {**_meta(settings, pin, disk, spacing), "patch_id": patch_id,
            "checkpoint_keys": [key], "h0_tol": h0_tol, "h0_candidates": len(h0),
            "steps_used": [int(m.get("n_steps", settings.steps)) for m in moments],
            "seconds": points.seconds()}
    factors = factors_from_moments(h0[chosen], moments, meta)
    return _estimated(factors, moments, coarse, settings, bound) if error_estimate else factors


def _solve(points, h0, h0_tol, friction, bar, coarse_args):
    """``(chosen, bound, moments, coarse)``: the indices of the h0 solved (all, or the
    adaptive subset and its bound), their moments, and the coarsened cells' moments of
    the grid estimate (``coarse_args``; None: no estimate)."""
    if h0_tol is None:
        chosen, bound = list(range(len(h0))), None
    else:
        chosen, bound = adaptive_separations(h0, points.factors, h0_tol,
                                             quantities=watched(friction))
    moments = points.moments(chosen)
    bar.update(len(h0) - len(chosen))             # the candidates interpolated
    coarse = (None if coarse_args is None
              else coarse_moments(points, chosen, *coarse_args))
    return chosen, bound, moments, coarse


def _estimated(factors, moments, coarse, settings, bound):
    """``factors`` with their error estimate and its variants in the metadata (the h0 part
    the adaptive sample's ``bound`` when it has one)."""
    estimate = estimate_errors(factors, moments, coarse, settings)
    if bound is not None:
        estimate["h0"] = bound
    meta = factors.meta
    keys = meta["checkpoint_keys"] + estimate.pop("checkpoint_keys", [])
    moved = estimate.pop("variants")
    return replace(factors, meta={**meta, "error_estimate": estimate, "checkpoint_keys": keys,
                                  "variants": moved})


def _settings(settings: CellSettings | None, shortcuts: dict) -> CellSettings:
    """``settings`` (default ``CellSettings()``) with the keyword ``shortcuts`` replacing
    its fields; a typo is refused."""
    names = [f.name for f in fields(CellSettings)]
    unknown = set(shortcuts) - set(names)
    if unknown:
        raise InputError(f"homogenise: unknown setting(s) {sorted(unknown)}; the cell "
                         f"settings are {names}")
    return replace(settings or CellSettings(), **shortcuts)


def _meta(settings: CellSettings, pin, disk, spacing) -> dict:
    """What flow factors record of their cell and settings."""
    return {"shape": list(pin.shape), "spacing": list(spacing),
            "e_reduced": settings.e_reduced, "hardness": settings.hardness,
            "gap_floor": settings.gap_floor, "n_steps": settings.steps,
            "method": settings.method, "moving": settings.moving,
            "slide_to_roll": settings.slide_to_roll,
            "first_step": settings.first_step, "time_derivative": settings.time_derivative,
            "version": __version__, "time_tol": settings.time_tol,
            "sq": float(np.hypot(pin.heights.std(), disk.heights.std())),
            "pin": pin.meta.get("sample", pin.meta.get("source")),
            "disk": disk.meta.get("sample", disk.meta.get("source"))}


def _check_separations(h0) -> np.ndarray:
    try:
        h0 = np.asarray(h0, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"h0 must be a 1D array of separations [m], got {h0!r}"[:200]) from None
    if h0.ndim != 1 or h0.size == 0 or not np.all(np.isfinite(h0)) or np.any(h0 <= 0):
        raise InputError("h0 must be a non-empty 1D array of positive separations [m]")
    if np.unique(h0).size != h0.size:
        raise InputError("h0 values must be distinct")
    plausible("h0 [m]", h0, "separation")
    return np.sort(h0)


def estimate_errors(factors, moments, coarse, settings) -> dict:
    """Time and grid error estimates (see :mod:`fem_twin.micro.estimate`): every other
    instant of this run, and the coarsened cell (``coarse``, from :func:`coarse_moments`,
    compared with the pass of as many instants); ``"variants"``: the factors with each
    error added (:func:`fem_twin.micro.estimate.variants`)."""
    out, half, grid = {}, None, None
    if all("half_h" in m for m in moments):
        half = factors_from_moments(factors.h0, moments, {}, prefix="half_")
        out["time"] = discrepancy(factors, half)
        out["time_steps"] = [settings.steps, settings.steps // 2]
    if coarse is not None:
        coarse_moments, coarse_settings, key, shape = coarse
        other = factors_from_moments(factors.h0, coarse_moments, {})
        same = half if coarse_settings.steps != settings.steps else factors
        out["grid"] = discrepancy(same, other)
        out["grid_shape"], out["grid_steps"] = shape, coarse_settings.steps
        grid = replace(factors, meta={}, **{k: getattr(factors, k) + getattr(other, k)
                                            - getattr(same, k) for k in ARRAYS[1:]})
        out["checkpoint_keys"] = [key]
    films = [_film_variant(factors, moments, k) for k in (1, 2)]
    out["film"] = {q: max(discrepancy(factors, f)[q] for f in films) for q in QUANTITIES}
    out["variants"] = variants(factors, half, grid, films)
    return out


def _film_variant(factors, moments, k) -> FlowFactors:
    """``factors`` with the friction factors of film cut ``k`` (:data:`.sliding.FILM_CUTS`)."""
    def get(key):
        return np.array([m[key][k] for m in moments])

    out = {"friction_factor": get("s_c") * factors.h_m,
           "thin_friction": get("s_thin") * factors.h_m, "thin_area": get("a_thin")}
    if all("film_area" in m for m in moments):
        out.update(film_spread(get("film_area"), get("log_shear"), factors.h_m))
    return replace(factors, meta={}, **out)


def check_patches(pin, disk):
    """The checked ``(z_low, z_up, spacing)`` of a cell's pin and disk patches
    (:class:`~fem_twin.topography.Topography`: finite, of one shape and pitch [m], at least
    4 x 4 pixels); :class:`~fem_twin.errors.InputError` otherwise."""
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
