"""Height clipping and Gaussian smoothing parametrised by FWHM (paper 2.2.1)."""

from __future__ import annotations

import numpy as np
import scipy.ndimage as ndi

from ..checks import arguments, plausible
from ..errors import InputError
from .core import Topography

#: FWHM of a Gaussian in units of its standard deviation, 2 sqrt(2 ln 2).
FWHM_PER_SIGMA = 2.0 * np.sqrt(2.0 * np.log(2.0))


@arguments(topo=Topography, lower="number", upper="number")
def clip_heights(topo: Topography, lower: float = -20e-6, upper: float = 20e-6) -> Topography:
    """Limit heights to ``[lower, upper]`` [m] (paper: height range limited to 20 um)."""
    if not lower < upper:
        raise InputError(f"clip range must satisfy lower < upper, got [{lower}, {upper}]")
    return topo.with_heights(np.clip(topo.heights, lower, upper),
                             meta=topo.with_history(f"clip[{lower:.3g}, {upper:.3g}] m"))


@arguments(topo=Topography, fwhm_px="number")
def gaussian_filter(topo: Topography, fwhm_px: float) -> Topography:
    """Smooth with a Gaussian whose full width at half maximum is ``fwhm_px`` pixels.

    ``sigma = fwhm_px / (2 sqrt(2 ln 2))`` along both axes (in pixels), kernel truncated at
    6 sigma, edges mirrored.  Invalid pixels are excluded by normalised convolution and stay
    invalid.  ``fwhm_px = 0`` returns the topography unchanged (the paper's "unfiltered");
    a width is else at least 1 pixel, at most 200 (``[preprocessing] fwhm_px``'s range: a
    width in metres, 9e-6, is refused).
    """
    plausible("gaussian_filter: fwhm_px [pixels]", fwhm_px, "fwhm_px")
    if 0 < fwhm_px < 1:
        raise InputError(f"gaussian_filter: fwhm_px = {fwhm_px:g}: the filter width is in "
                         "pixels (0: no filter, else at least 1; the paper's is 9)")
    if fwhm_px == 0:
        return topo
    sigma = fwhm_px / FWHM_PER_SIGMA
    opts = dict(sigma=sigma, mode="reflect", truncate=6.0)
    if topo.mask is None:
        smooth = ndi.gaussian_filter(topo.heights, **opts)
    else:
        w = topo.mask.astype(float)
        num = ndi.gaussian_filter(np.where(topo.mask, topo.heights, 0.0), **opts)
        den = ndi.gaussian_filter(w, **opts)
        smooth = np.where(topo.mask, num / np.where(den > 0, den, 1.0), np.nan)
    return topo.with_heights(smooth, meta=topo.with_history(f"gaussian_filter(fwhm={fwhm_px} px)"))
