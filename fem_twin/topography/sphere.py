"""A measured ball cap: its sphere, its form error, and its gap against a flat disk.

A ball's top measured by an optical profiler is a spherical cap plus the ball's form error
and roughness.  :func:`fit_sphere` finds the sphere by least squares on the heights: first
the paraboloid ``z = c0 + c1 x1 + c2 x2 + c3 (x1^2 + x2^2)`` (linear; the cap of a ball is
shallow, ``R = -1 / (2 c3)``), then the exact cap ``z = z_c + sqrt(R^2 - r^2)`` from there
(:func:`scipy.optimize.least_squares`).  Its apex levels the cap as the torque balance
levels a pin: a tilt of a sphere only moves its apex.  :func:`cap_gap` reads the measured
cap (sphere, form error and roughness) around the apex as the rigid gap of the ball over a
flat disk, on the macro grid of the point contact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import RegularGridInterpolator
from scipy.optimize import least_squares

from ..errors import InputError
from .core import Topography


@dataclass(frozen=True, eq=False)
class SphereFit:
    """The sphere of a measured cap (SI units).

    radius : R [m];  apex : (x1, x2) of the apex [m];  apex_height : the sphere's height
    there [m];  form_error : the measured heights minus the sphere, a :class:`Topography`
    on the cap's grid (NaN where the cap is invalid) [m].
    """

    radius: float
    apex: tuple
    apex_height: float
    form_error: Topography

    @property
    def form_error_rms(self) -> float:
        """Root mean square of the form error [m]."""
        return self.form_error.rms_height()

    def sphere(self, x1, x2) -> np.ndarray:
        """Heights of the fitted sphere's cap at ``(x1, x2)`` [m]."""
        return _cap(self.radius, self.apex, self.apex_height, x1, x2)


#: the largest ball radius [m] a fitted cap may have: beyond it the map is a flat plate
MAX_RADIUS = 1.0


def _cap(radius, apex, apex_height, x1, x2):
    """Heights [m] of a sphere's cap of ``radius`` with its top ``apex_height`` at ``apex``."""
    r2 = (np.asarray(x1) - apex[0]) ** 2 + (np.asarray(x2) - apex[1]) ** 2
    return apex_height - radius + np.sqrt(np.maximum(radius ** 2 - r2, 0))


def fit_sphere(cap: Topography) -> SphereFit:
    """Least-squares sphere of a measured ball cap (convex upwards, its apex inside the
    map); raises :class:`~fem_twin.errors.InputError` for a map that is no cap."""
    x1, x2 = cap.coordinates()
    ok = np.isfinite(cap.heights)
    x, y, z = x1[ok], x2[ok], cap.heights[ok]
    if z.size < 10:
        raise InputError("a ball cap needs at least 10 valid pixels")
    s = max(np.ptp(x), np.ptp(y))                        # scale: the map's size
    G = np.column_stack([np.ones_like(x), x / s, y / s, (x ** 2 + y ** 2) / s ** 2])
    c = np.linalg.lstsq(G, z, rcond=None)[0]
    if not c[3] < 0:
        raise InputError("the map is not convex upwards: no ball cap (measure the ball's "
                         "top, heights increasing towards the apex)")
    radius = -s ** 2 / (2 * c[3])
    apex = (-c[1] * s / (2 * c[3]), -c[2] * s / (2 * c[3]))
    top = c[0] - (c[1] ** 2 + c[2] ** 2) / (4 * c[3])

    def residual(p):                                     # parameters in units of s
        return _cap(p[0] * s, (p[1] * s, p[2] * s), p[3] * s, x, y) - z

    p = least_squares(residual, [radius / s, apex[0] / s, apex[1] / s, top / s],
                      x_scale="jac").x * s
    radius, apex, top = float(p[0]), (float(p[1]), float(p[2])), float(p[3])
    if radius > MAX_RADIUS:
        raise InputError(f"the fitted sphere's radius is {radius:.3g} m: the map is nearly "
                         f"flat, no ball cap (a ball's radius is at most {MAX_RADIUS:g} m); "
                         "measure the ball's top")
    if not (x1.min() <= apex[0] <= x1.max() and x2.min() <= apex[1] <= x2.max()):
        raise InputError(f"the fitted apex {apex} [m] lies outside the map: measure the "
                         "ball's top")
    return SphereFit(radius, apex, top,
                     cap.with_heights(cap.heights - _cap(radius, apex, top, x1, x2)))


def cap_gap(cap: Topography, fit: SphereFit, x1, x2) -> np.ndarray:
    """The rigid gap [m] of the measured cap over a flat disk at the macro grid's node
    coordinates ``x1``, ``x2`` [m] (1D, relative to the apex): the sphere's apex height
    minus the measured heights there (bilinear), so a perfect sphere gives its cap's gap
    ``R - sqrt(R^2 - r^2)``."""
    c1, c2 = cap.x1, cap.x2
    X1, X2 = np.meshgrid(np.asarray(x1) + fit.apex[0], np.asarray(x2) + fit.apex[1])
    if (X1.min() < c1[0] or X1.max() > c1[-1] or X2.min() < c2[0] or X2.max() > c2[-1]):
        raise InputError(f"the macro grid ({np.ptp(x1) * 1e3:.3g} x {np.ptp(x2) * 1e3:.3g} mm "
                         f"around the apex) reaches beyond the measured cap "
                         f"({np.ptp(c1) * 1e3:.3g} x {np.ptp(c2) * 1e3:.3g} mm): measure a "
                         "larger cap or use a coarser [macro] grid extent")
    if not np.all(np.isfinite(cap.heights)):
        raise InputError("the ball cap has invalid pixels: fill them first "
                         "(fem_twin.topography.fill_defects)")
    read = RegularGridInterpolator((c2, c1), cap.heights)
    heights = read(np.column_stack([X2.ravel(), X1.ravel()])).reshape(X1.shape)
    return fit.apex_height - heights
