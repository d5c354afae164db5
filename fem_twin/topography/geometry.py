"""Placing surfaces in the twin: patches, disk flipping, pin mounting (paper 2.2.1)."""

from __future__ import annotations

import numpy as np

from .. import tables as T
from ..checks import arguments
from ..errors import InputError
from .core import Topography

#: Rotations (number of 90-degree turns counter-clockwise) that bring a measured axis onto
#: the sliding direction x1.
_TURNS = {"+x1": 0, "+x2": 1, "-x1": 2, "-x2": 3}


@arguments(topo=Topography, shape="shape", start="pair")
def extract_patch(topo: Topography, shape=(256, 256), start=(0, 0)) -> Topography:
    """Cut a ``shape = (ny, nx)`` sub-grid starting at pixel ``start = (row, col)``.

    No interpolation: the patch holds the original pixels and pitch (paper: 256 x 256).
    """
    (ny, nx), (r0, c0) = shape, start
    if r0 < 0 or c0 < 0 or r0 + ny > topo.shape[0] or c0 + nx > topo.shape[1]:
        raise InputError(f"patch {shape} at {start} does not fit a {topo.shape} topography")
    sl = (slice(r0, r0 + ny), slice(c0, c0 + nx))
    mask = None if topo.mask is None else topo.mask[sl]
    origin = (topo.origin[0] + c0 * topo.spacing[0], topo.origin[1] + r0 * topo.spacing[1])
    return topo.with_heights(topo.heights[sl], mask=mask, origin=origin,
                             meta=topo.with_history(f"patch({ny}x{nx} at {r0},{c0})"))


@arguments(topo=Topography)
def align_sliding(topo: Topography, direction: str = "+x1") -> Topography:
    """Rotate the map so that the measured axis ``direction`` becomes x1 (sliding velocity).

    ``direction`` is one of ``+x1, -x1, +x2, -x2`` in the measured frame.  Rotation keeps the
    surface (heights) as it is, only the in-plane axes turn.
    """
    if direction not in _TURNS:
        raise InputError(f"direction must be one of {sorted(_TURNS)}, got {direction!r}")
    k = _TURNS[direction]
    if k == 0:
        return topo
    heights = _rotate(topo.heights, k)
    mask = None if topo.mask is None else _rotate(topo.mask, k)
    spacing = topo.spacing if k % 2 == 0 else topo.spacing[::-1]
    return topo.with_heights(heights, mask=mask, spacing=spacing, origin=(0.0, 0.0),
                             meta=topo.with_history(f"align_sliding({direction})"))


def _rotate(a: np.ndarray, k: int) -> np.ndarray:
    """Pixel array seen in a frame whose x1 is the old axis (+x1, +x2, -x1, -x2)[k]."""
    if k == 1:      # new x1 = old x2, new x2 = -old x1
        return a.T[::-1, :]
    if k == 2:      # new x1 = -old x1, new x2 = -old x2
        return a[::-1, ::-1]
    return a.T[:, ::-1]   # k == 3: new x1 = -old x2, new x2 = old x1


@arguments(disk=Topography)
def flip_disk(disk: Topography) -> Topography:
    """Turn the measured disk face-down over the pin by rotating it 180 deg about x1.

    The measured heights z(x1, x2) (peaks positive, pointing out of the disk) become the
    upper surface ``x3_up(x1, x2) = -z(x1, -x2)``: heights change sign and the x2 axis
    reverses, x1 (sliding direction) is kept.  The gap above a pin at ``x3_low`` is
    ``h_d + x3_up - x3_low``.
    """
    heights = -disk.heights[::-1, :]
    mask = None if disk.mask is None else disk.mask[::-1, :]
    ny = disk.shape[0]
    origin = (disk.origin[0], -(disk.origin[1] + (ny - 1) * disk.spacing[1]))
    return disk.with_heights(heights, mask=mask, origin=origin,
                             meta=disk.with_history("flip_disk(about x1)"))


@arguments(topo=Topography, face="field")
def pin_centre(topo: Topography, face: np.ndarray) -> tuple[float, float]:
    """Centroid (x1, x2) [m] of the pin face pixels ``face`` (boolean array)."""
    x1, x2 = topo.coordinates()
    if not face.any():
        raise InputError("pin face is empty: no pixel above the truncation height")
    return float(x1[face].mean()), float(x2[face].mean())


@arguments(topo=Topography, centre="pair")
def centre_on(topo: Topography, centre) -> Topography:
    """Shift coordinates so that ``centre`` (x1, x2) [m] becomes the origin."""
    origin = (topo.origin[0] - centre[0], topo.origin[1] - centre[1])
    return topo.with_heights(topo.heights, origin=origin,
                             meta=topo.with_history(f"centre_on({centre[0]:.4g}, {centre[1]:.4g})"))


@arguments(topo=Topography, truncation="number", holder_height="number")
def mount_pin(topo: Topography, truncation: float = -20e-6, holder_height: float = T.HOLDER_HEIGHT,
              radius: float | None = None) -> Topography:
    """Put the pin face in its holder: everything off the face is the holder at -1 mm.

    The face is where heights are above ``truncation`` [m] (and, if ``radius`` [m] is given,
    within that radius of the origin, i.e. of the pin centre); the pin stands
    ``-holder_height`` (1 mm) above the holder, whose surface is perfectly flat (paper 2.2.1).
    Invalid pixels off the face become holder too; on the face they must be filled first.
    """
    face = topo.valid & (np.nan_to_num(topo.heights, nan=-np.inf) > truncation)
    if radius is not None:
        x1, x2 = topo.coordinates()
        face &= x1 ** 2 + x2 ** 2 <= radius ** 2
    if not face.any():
        raise InputError(f"no pin face: no valid pixel above the truncation {truncation} m")
    return topo.with_heights(np.where(face, topo.heights, holder_height), mask=None,
                             meta=topo.with_history(
                                 f"mount_pin(truncation={truncation:.3g} m, "
                                 f"holder={holder_height:.3g} m)"))


@arguments(topo=Topography, holder_height="number")
def pin_face(topo: Topography, holder_height: float = T.HOLDER_HEIGHT) -> np.ndarray:
    """Boolean mask of the pin face of a mounted pin: pixels above half the holder's depth
    ``holder_height`` [m] (a rim pixel that resampling left between face and holder counts
    with the side it is nearer).  The one rule of the face, for every stage."""
    return topo.heights > holder_height / 2
