"""The paper's geometry reconstruction chains (2.2.1) for pins, disks and roughness patches."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import tables as T
from ..checks import check_choices, check_ranges, setting
from ..errors import InputError
from .core import Topography
from .filling import fill_defects
from .filtering import clip_heights, gaussian_filter
from .geometry import align_sliding, centre_on, extract_patch, flip_disk, mount_pin, pin_centre
from .levelling import level, radial_mask
from .resampling import resample


@dataclass(frozen=True)
class MacroOptions:
    """``[preprocessing]``: the macroscopic reconstruction (paper 2.2.1; SI units, defaults
    from the paper)."""

    fwhm_px: float = setting(9.0, "Gaussian filter FWHM in pixels of the measured map (0: "
                             "unfiltered; the paper's calibrated value is 9)", "fwhm_px")
    clip: float = setting(20e-6, "heights clipped to +-clip", "height")
    resolution: tuple[int, int] | None = setting(
        (256, 256), "rows and columns of the virtual geometry (the macro grid), at least 16 "
        "each in a case file (its error estimate solves the grid coarsened by two)", "pixels")
    resample_method: str = setting("linear", "resampling interpolation",
                                   choices=("linear", "cubic"))
    truncation: float = setting(-20e-6, "below this height a pin pixel belongs to the "
                                "holder", "depth")
    holder_height: float = setting(T.HOLDER_HEIGHT, "the holder surface (pin height 1 mm)", "depth")
    level_radius: float = setting(3e-3, "radius about the pin centre of the final "
                                  "mean-plane fit", "length")
    sliding_direction: str = setting("+x1", "measured axis along the disk velocity",
                                     choices=("+x1", "-x1", "+x2", "-x2"))

    def __post_init__(self):
        check_choices(self)
        check_ranges(self)


def pin_face_guess(topo: Topography) -> np.ndarray:
    """Pixels of the pin face in a raw map: above the midpoint of the 5th and 90th percentiles.

    The face (tens of um above the chamfer and holder) dominates the upper part of the
    height histogram; the threshold is insensitive to measurement tilt of a few um.
    """
    z = topo.heights[topo.valid]
    lo, hi = np.percentile(z, [5, 90])
    face = topo.valid & (np.nan_to_num(topo.heights, nan=-np.inf) > 0.5 * (lo + hi))
    if face.sum() < 3:
        raise InputError(f"no pin face in the map: its heights span {np.ptp(z):.3g} m without "
                         "a face standing above the chamfer and holder (is it a pin map?)")
    return face


def prepare_pin(raw: Topography, opts: MacroOptions = MacroOptions()) -> Topography:
    """Measured pin -> virtual lower surface ``x3_low`` centred on the pin, holder at -1 mm.

    Steps (paper 2.2.1): Laplace defect fill; mean plane over the face only (holder and
    chamfer excluded), zero at that plane; clip to +-``clip``; Gaussian filter; resample;
    origin at the pin centre; mean plane within ``level_radius`` of the centre; mount in
    the holder.  Torque-balance levelling against the disk is a separate step (contact).
    """
    topo = align_sliding(fill_defects(raw), opts.sliding_direction)
    topo = level(topo, pin_face_guess(topo))
    topo = level(topo, topo.heights > opts.truncation)
    topo = gaussian_filter(clip_heights(topo, -opts.clip, opts.clip), opts.fwhm_px)
    if opts.resolution is not None:
        topo = resample(topo, opts.resolution, opts.resample_method)
    topo = centre_on(topo, pin_centre(topo, topo.heights > opts.truncation))
    face = topo.heights > opts.truncation
    topo = level(topo, radial_mask(topo, opts.level_radius) & face)
    return mount_pin(topo, opts.truncation, opts.holder_height)


def prepare_disk(raw: Topography, opts: MacroOptions = MacroOptions()) -> Topography:
    """Measured disk -> virtual upper surface ``x3_up`` (flipped over the pin, centred).

    Steps: Laplace defect fill; mean plane; clip; Gaussian filter; resample; origin at the
    centre of the map (aligned with the pin centre); flip about x1.
    """
    topo = align_sliding(fill_defects(raw), opts.sliding_direction)
    topo = gaussian_filter(clip_heights(level(topo), -opts.clip, opts.clip), opts.fwhm_px)
    if opts.resolution is not None:
        topo = resample(topo, opts.resolution, opts.resample_method)
    ny, nx = topo.shape
    topo = centre_on(topo, (topo.x1[0] + 0.5 * (nx - 1) * topo.spacing[0],
                            topo.x2[0] + 0.5 * (ny - 1) * topo.spacing[1]))
    return flip_disk(topo)


def flat_disk(pin: Topography) -> Topography:
    """A perfectly flat upper surface at zero height on the pin's grid (paper 3.2)."""
    return pin.with_heights(np.zeros(pin.shape), mask=None,
                            meta={"sample": "flat disk", "history": ["flat_disk"]})


def prepare_patch(raw: Topography, shape=(256, 256), start=(0, 0), *, upper: bool = False,
                  sliding_direction: str = "+x1") -> Topography:
    """Measured roughness patch -> periodic cell surface (no filter, no interpolation).

    Laplace fill, ``shape`` pixels cut at ``start``, mean plane of the patch with zero at
    that plane (a plane removed from the whole map first would be absorbed by this fit),
    origin at the patch corner; the disk patch (``upper=True``) is flipped above the pin.
    """
    topo = extract_patch(align_sliding(fill_defects(raw), sliding_direction), shape, start)
    topo = centre_on(level(topo), topo.origin)
    return flip_disk(topo) if upper else topo
