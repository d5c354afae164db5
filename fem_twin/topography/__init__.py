"""Topography stage: height maps and their pre-processing (paper 2.2.1).

Each function takes a :class:`Topography` and returns a new one; nothing is changed in place.
"""

from .core import Topography
from .filling import fill_defects
from .filtering import FWHM_PER_SIGMA, clip_heights, gaussian_filter
from .geometry import (
                       align_sliding,
                       centre_on,
                       extract_patch,
                       flip_disk,
                       mount_pin,
                       pin_centre,
                       pin_face,
)
from .levelling import level, mean_plane, radial_mask, zero_mean
from .resampling import refine, resample, resample_cell

__all__ = [
    "Topography", "fill_defects", "clip_heights", "gaussian_filter", "FWHM_PER_SIGMA",
    "align_sliding", "centre_on", "extract_patch", "flip_disk", "mount_pin", "pin_centre",
    "pin_face", "level", "mean_plane", "radial_mask", "zero_mean", "refine", "resample",
    "resample_cell",
]
