"""The :class:`Topography` value: a height map on a regular grid, in SI units.

Conventions used throughout fem_twin
------------------------------------
* ``heights`` has shape ``(ny, nx)``: rows run along x2, columns along x1 (the sliding
  direction of the disk), so ``heights[i2, i1]`` is the height at
  ``(origin[0] + i1 * dx1, origin[1] + i2 * dx2)``.
* ``spacing = (dx1, dx2)`` is the pixel pitch [m]; ``origin`` the position of pixel
  ``[0, 0]`` [m].  Pixels are grid points (nodes), so a non-periodic map spans
  ``(nx - 1) * dx1``; a periodic patch has period ``nx * dx1``.
* Invalid (unmeasured) pixels hold NaN and are ``False`` in ``mask``; a fully valid map has
  ``mask is None``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..checks import as_pair, plausible
from ..errors import InputError

#: Largest peak-to-valley [m] accepted for a topography.  A pin-on-disk map spans a few
#: millimetres at most (pin height 1 mm); anything larger almost surely is in um or nm.
MAX_PEAK_TO_VALLEY = 0.05
#: the plausible extent of a map [m]: a pitch that makes it larger or smaller wants a unit
EXTENT = (1e-6, 1.0)


@dataclass(frozen=True, eq=False)
class Topography:
    """Height map ``heights`` [m] on a regular grid with pixel pitch ``spacing`` [m].

    Parameters
    ----------
    heights : array_like, shape (ny, nx)
        Heights in metres, x1 along the columns.  NaN marks invalid pixels.
    spacing : (dx1, dx2)
        Pixel pitch along x1 (columns) and x2 (rows) in metres; a scalar means square pixels.
    mask : array_like of bool, optional
        True where a pixel is valid.  Combined with ``isfinite(heights)``.
    origin : (x1, x2)
        Coordinates of pixel ``[0, 0]`` in metres.
    meta : dict
        Free-form provenance (file name, instrument, processing history).
    """

    heights: np.ndarray
    spacing: tuple[float, float]
    mask: np.ndarray | None = None
    origin: tuple[float, float] = (0.0, 0.0)
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        if np.iscomplexobj(self.heights):
            raise InputError("heights must be real numbers [m], got complex values (take the "
                             "real part or the modulus at I/O)")
        try:
            h = np.array(self.heights, dtype=float)
        except (TypeError, ValueError):
            raise InputError("heights must be a 2D array of numbers [m]") from None
        if h.ndim != 2:
            raise InputError(f"heights must be a 2D array (ny, nx), got shape {h.shape}")
        if min(h.shape) < 2:
            raise InputError(f"heights need at least 2 x 2 pixels, got shape {h.shape}")
        spacing = np.array(as_pair("spacing [m]", self.spacing))
        if not np.all(np.isfinite(spacing)) or np.any(spacing <= 0):
            raise InputError(f"spacing must be positive and finite [m], got ({spacing[0]:g}, "
                             f"{spacing[1]:g})")
        plausible("spacing [m]", spacing, "map_pitch")
        extent = np.array(h.shape[::-1]) * spacing
        if np.any(extent > EXTENT[1]) or np.any(extent < EXTENT[0]):
            raise InputError(
                f"spacing ({spacing[0]:g}, {spacing[1]:g}) m per pixel makes the "
                f"{h.shape[1]} x {h.shape[0]} px map {extent[0]:.3g} x {extent[1]:.3g} m; a "
                f"map spans {EXTENT[0]:g} to {EXTENT[1]:g} m: give the pitch in metres (16e-6 "
                "for 16 um)")
        valid = np.isfinite(h)
        if self.mask is not None:
            m = np.asarray(self.mask)
            if m.shape != h.shape:
                raise InputError(f"mask shape {m.shape} does not match heights shape {h.shape}")
            valid &= m.astype(bool)
        if not valid.any():
            raise InputError("topography has no valid pixel (all NaN or masked)")
        ptv = np.ptp(h[valid])
        if ptv > MAX_PEAK_TO_VALLEY:
            raise InputError(
                f"peak-to-valley {ptv:.3g} m is implausible for a tribometer surface: "
                "heights must be given in metres (convert um or nm at I/O)")
        h[~valid] = np.nan
        h.setflags(write=False)
        mask = None
        if not valid.all():
            mask = valid
            mask.setflags(write=False)
        origin = tuple(float(v) for v in np.broadcast_to(np.asarray(self.origin, float), (2,)))
        object.__setattr__(self, "heights", h)
        object.__setattr__(self, "spacing", (float(spacing[0]), float(spacing[1])))
        object.__setattr__(self, "mask", mask)
        object.__setattr__(self, "origin", origin)
        object.__setattr__(self, "meta", dict(self.meta))

    # -- geometry -----------------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, int]:
        """Grid shape ``(ny, nx)``."""
        return self.heights.shape

    @property
    def valid(self) -> np.ndarray:
        """Boolean array, True where the pixel is valid."""
        return np.ones(self.shape, bool) if self.mask is None else self.mask

    @property
    def x1(self) -> np.ndarray:
        """Pixel coordinates along x1 (columns) [m], shape (nx,)."""
        return self.origin[0] + self.spacing[0] * np.arange(self.shape[1])

    @property
    def x2(self) -> np.ndarray:
        """Pixel coordinates along x2 (rows) [m], shape (ny,)."""
        return self.origin[1] + self.spacing[1] * np.arange(self.shape[0])

    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """``(X1, X2)`` coordinate arrays shaped like ``heights`` [m]."""
        return np.meshgrid(self.x1, self.x2)

    @property
    def size(self) -> tuple[float, float]:
        """Physical size covered by the pixels, ``(nx * dx1, ny * dx2)`` [m]."""
        return (self.shape[1] * self.spacing[0], self.shape[0] * self.spacing[1])

    # -- statistics ---------------------------------------------------------------------
    def rms_height(self, mask: np.ndarray | None = None) -> float:
        """Sq: root mean square of the heights about their mean over valid pixels [m]."""
        sel = self.valid if mask is None else self.valid & mask
        z = self.heights[sel]
        return float(np.sqrt(np.mean((z - z.mean()) ** 2)))

    # -- derived values -----------------------------------------------------------------
    def with_heights(self, heights, **changes) -> "Topography":
        """A copy with new heights (same grid unless ``changes`` say otherwise)."""
        return replace(self, heights=heights, mask=changes.pop("mask", self.mask), **changes)

    def with_history(self, step: str) -> dict:
        """``meta`` with ``step`` appended to the processing history."""
        meta = dict(self.meta)
        meta["history"] = list(meta.get("history", [])) + [step]
        return meta

    def __repr__(self):
        ny, nx = self.shape
        inval = 0 if self.mask is None else int((~self.mask).sum())
        return (f"Topography({ny}x{nx} px, spacing=({self.spacing[0]:.4g}, "
                f"{self.spacing[1]:.4g}) m, Sq={self.rms_height():.4g} m, "
                f"invalid={inval})")
