"""Resampling of a topography to a new resolution (paper 2.2.1 and section 3.2)."""

from __future__ import annotations

import numpy as np
import scipy.ndimage as ndi

from ..checks import arguments, memory_shortfall
from ..errors import InputError
from .core import Topography

_ORDER = {"nearest": 0, "linear": 1, "cubic": 3}


@arguments(topo=Topography, shape="shape")
def resample(topo: Topography, shape: tuple[int, int], method: str = "linear") -> Topography:
    """Interpolate onto a ``shape = (ny, nx)`` grid spanning the same first and last pixels.

    The new pitch is ``(n - 1) / (m - 1)`` times the old one, so a refinement with
    ``m - 1 = k (n - 1)`` (e.g. 500 -> 999 or 1997 pixels) contains every original point
    unchanged and adds ``k - 1`` points in between.  ``method`` is ``"linear"`` (default,
    like MATLAB's interp2), ``"cubic"`` (interpolating spline) or ``"nearest"``.
    """
    if method not in _ORDER:
        raise InputError(f"method must be one of {sorted(_ORDER)}, got {method!r}")
    ny, nx = _target(topo, shape, "resample")
    oy, ox = topo.shape
    # exact rational positions: i (n-1) / (m-1) is an integer whenever the refinement is exact
    pos2 = np.arange(ny) * (oy - 1) / (ny - 1)
    pos1 = np.arange(nx) * (ox - 1) / (nx - 1)
    p2, p1 = np.meshgrid(pos2, pos1, indexing="ij")
    order = _ORDER[method]
    new = ndi.map_coordinates(topo.heights, [p2, p1], order=order, mode="nearest",
                              prefilter=order > 1)
    spacing = (topo.spacing[0] * (ox - 1) / (nx - 1), topo.spacing[1] * (oy - 1) / (ny - 1))
    return topo.with_heights(new, spacing=spacing,
                             meta=topo.with_history(f"resample({ny}x{nx}, {method})"))


@arguments(topo=Topography, factor="number")
def refine(topo: Topography, factor: int, method: str = "linear") -> Topography:
    """Insert ``factor - 1`` points between neighbours: ``n -> factor (n - 1) + 1`` pixels."""
    if int(factor) != factor or factor < 1:
        raise InputError(f"refinement factor must be a positive integer, got {factor}")
    ny, nx = topo.shape
    shape = (int(factor) * (ny - 1) + 1, int(factor) * (nx - 1) + 1)
    _fits(shape, f"refine: factor = {factor}")
    return resample(topo, shape, method)


@arguments(topo=Topography, shape="shape")
def resample_cell(topo: Topography, shape: tuple[int, int]) -> Topography:
    """Periodic roughness cell onto ``shape = (ny, nx)`` pixels over the same period.

    The new pitch is ``n / m`` times the old one and the interpolation is linear and wraps
    around (the last pixel's neighbour is the first), so the result is the same periodic
    bilinear surface sampled anew: coarsening by an integer factor keeps every ``k``-th
    pixel, refinement by ``k`` keeps every pixel and adds ``k - 1`` between neighbours.
    (:func:`resample` spans the first and last pixels instead, which changes the period.)
    """
    ny, nx = _target(topo, shape, "resample_cell")
    oy, ox = topo.shape
    p2, p1 = np.meshgrid(np.arange(ny) * oy / ny, np.arange(nx) * ox / nx, indexing="ij")
    new = ndi.map_coordinates(topo.heights, [p2, p1], order=1, mode="grid-wrap")
    spacing = (topo.spacing[0] * ox / nx, topo.spacing[1] * oy / ny)
    return topo.with_heights(new, spacing=spacing,
                             meta=topo.with_history(f"resample_cell({ny}x{nx})"))


def _target(topo: Topography, shape, name: str) -> tuple[int, int]:
    """The checked target ``(ny, nx)`` of a resampling of a fully valid ``topo``."""
    if topo.mask is not None:
        raise InputError(f"{name} needs a fully valid topography: call fill_defects first")
    ny, nx = (int(v) for v in shape)
    if ny < 2 or nx < 2:
        raise InputError(f"target shape must be at least 2 x 2, got {shape}")
    _fits((ny, nx), f"{name}: shape")
    return ny, nx


def _fits(shape, name: str) -> None:
    """Refuse a resampled map of ``shape`` pixels this machine's memory cannot hold
    (:func:`~fem_twin.checks.memory_shortfall`), naming ``name``, before allocating it."""
    short = memory_shortfall(shape[0] * shape[1], "map")
    if short:
        raise InputError(f"{name}: a {shape[0]} x {shape[1]} pixel map; {short}")
