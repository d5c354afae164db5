"""Levelling to a (masked) mean plane, zeroing and radial masks (paper 2.2.1)."""

from __future__ import annotations

import numpy as np

from ..checks import arguments
from ..errors import InputError
from .core import Topography


@arguments(topo=Topography)
def mean_plane(topo: Topography, mask: np.ndarray | None = None) -> np.ndarray:
    """Least-squares plane ``(a, b1, b2)`` with ``z ~ a + b1 x1 + b2 x2`` over valid pixels.

    ``mask`` (True where a pixel takes part in the fit) restricts the fit, e.g. to the pin
    face.  Coordinates are those of :meth:`Topography.coordinates` [m].
    """
    sel = _selection(topo, mask)
    x1, x2 = topo.coordinates()
    # centre the coordinates for a well-conditioned normal system
    c1, c2 = x1[sel].mean(), x2[sel].mean()
    design = np.column_stack([np.ones(sel.sum()), x1[sel] - c1, x2[sel] - c2])
    if np.linalg.matrix_rank(design) < 3:
        raise InputError("mean plane is undefined: the fitted pixels lie on a line")
    a, b1, b2 = np.linalg.lstsq(design, topo.heights[sel], rcond=None)[0]
    return np.array([a - b1 * c1 - b2 * c2, b1, b2])


@arguments(topo=Topography)
def level(topo: Topography, mask: np.ndarray | None = None) -> Topography:
    """Subtract the mean plane fitted where ``mask`` is True (all valid pixels by default).

    After levelling, the fitted pixels have zero mean and no tilt: the zero-height mark sits
    at the mean plane.  Invalid pixels stay invalid.
    """
    a, b1, b2 = mean_plane(topo, mask)
    x1, x2 = topo.coordinates()
    what = "all" if mask is None else f"{int(np.count_nonzero(mask))} px"
    return topo.with_heights(topo.heights - (a + b1 * x1 + b2 * x2),
                             meta=topo.with_history(f"level(mean plane over {what})"))


@arguments(topo=Topography)
def zero_mean(topo: Topography, mask: np.ndarray | None = None) -> Topography:
    """Shift heights so that their mean over ``mask`` (valid pixels by default) is zero."""
    sel = _selection(topo, mask)
    return topo.with_heights(topo.heights - topo.heights[sel].mean(),
                             meta=topo.with_history("zero_mean"))


@arguments(topo=Topography, radius="number", centre="pair")
def radial_mask(topo: Topography, radius: float, centre=(0.0, 0.0)) -> np.ndarray:
    """True for pixels within ``radius`` [m] of ``centre`` (x1, x2) [m]."""
    if radius <= 0:
        raise InputError(f"radial_mask: radius = {radius:g} m: a positive radius in metres "
                         "(3 mm is 3e-3)")
    x1, x2 = topo.coordinates()
    return (x1 - centre[0]) ** 2 + (x2 - centre[1]) ** 2 <= radius ** 2


def _selection(topo: Topography, mask) -> np.ndarray:
    sel = topo.valid
    if mask is not None:
        mask = np.asarray(mask, bool)
        if mask.shape != topo.shape:
            raise InputError(f"mask shape {mask.shape} does not match topography {topo.shape}")
        sel = sel & mask
    if sel.sum() < 3:
        raise InputError("fewer than 3 valid pixels selected by the mask")
    return sel
