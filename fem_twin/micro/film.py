"""The cell's mean inverse film over a cut-off, ``<1/h>`` over the films thicker than ``c``
(the Couette part of the friction factor s_C, :func:`fem_twin.micro.sliding.film_moments`),
integrated exactly on the linear interpolant of the nodal gap.

Each pixel of the periodic cell is split into two triangles on which ``h`` is linear; for
any integrable ``g``, ``int_T g(h) dA = 2 |T| G[h_a, h_b, h_c]``, the second divided
difference of ``G`` with ``G'' = g`` (Hermite-Genocchi).  With ``g = 1/h`` above ``c`` and 0
below, ``G(h) = h ln(h/c) - (h - c)`` above ``c`` and 0 below.  A film that thins to the
cut-off inside a pixel then contributes the part of the pixel above it, so ``s_C`` is
continuous in h0 through contact onset, where the nodal ``1/h`` with a hard cut-off puts a
pixel's weight on a node just above ``c`` or on none.
"""

from __future__ import annotations

import numpy as np

#: triangles whose nodal films differ by less than this fraction of their mean take the
#: midpoint rule (error below the fraction squared; the divided differences lose digits)
NEAR_EQUAL = 1e-4


def _antiderivative(h, cut):
    """``G`` of the module docstring [m], zero below ``cut``."""
    above = h > cut
    safe = np.where(above, h, cut)
    return np.where(above, safe * np.log(safe / cut) - (safe - cut), 0.0)


def _triangle_means(a, b, c, cut):
    """``G[a, b, c]`` [1/m] of each triangle's nodal films (arrays of one shape): half the
    triangle's mean of ``1/h`` above ``cut``, zero where no node is above it (a plastic
    spot's raw gap is negative: the relative closeness takes ``|hi + lo|``)."""
    lo, mid, hi = np.sort(np.stack([a, b, c]), axis=0)
    spread = hi - lo
    close = spread <= NEAR_EQUAL * np.abs(hi + lo) / 2
    mean = (a + b + c) / 3
    midpoint = np.where(mean > cut, 1 / np.where(mean > 0, mean, 1.0), 0.0) / 2
    G_lo, G_mid, G_hi = (_antiderivative(v, cut) for v in (lo, mid, hi))
    with np.errstate(divide="ignore", invalid="ignore"):
        first_hi = (G_hi - G_mid) / (hi - mid)
        first_lo = (G_mid - G_lo) / (mid - lo)
        # two equal values: the first divided difference is G' there
        slope = np.where(mid > cut, np.log(np.where(mid > cut, mid, cut) / cut), 0.0)
        first_hi = np.where(hi - mid > 0, first_hi, slope)
        first_lo = np.where(mid - lo > 0, first_lo, slope)
        exact = (first_hi - first_lo) / np.where(close, 1.0, spread)
    return np.where(hi <= cut, 0.0, np.where(close, midpoint, exact))


def mean_inverse_film(gap, cut: float) -> float:
    """``<1/h>`` over the films thicker than ``cut`` [1/m] of the periodic cell's nodal
    ``gap`` [m] (ny, nx), exact on its linear interpolant over two triangles a pixel."""
    h00 = np.asarray(gap, float)
    h10 = np.roll(h00, -1, axis=1)
    h01 = np.roll(h00, -1, axis=0)
    h11 = np.roll(h10, -1, axis=0)
    total = _triangle_means(h00, h10, h11, cut) + _triangle_means(h00, h11, h01, cut)
    return float(np.mean(total))


def area_above(gap, cut: float) -> float:
    """The share of the periodic cell [-] where the linear interpolant of the nodal ``gap``
    [m] (two triangles a pixel, as :func:`mean_inverse_film`) lies above ``cut`` [m]:
    per triangle of sorted nodal values lo <= mid <= hi, 1 below lo, ``1 - (c - lo)^2 /
    ((mid - lo)(hi - lo))`` up to mid, ``(hi - c)^2 / ((hi - mid)(hi - lo))`` up to hi."""
    h00 = np.asarray(gap, float)
    h10 = np.roll(h00, -1, axis=1)
    h01 = np.roll(h00, -1, axis=0)
    h11 = np.roll(h10, -1, axis=0)
    return float(np.mean(_triangle_areas(h00, h10, h11, cut)
                         + _triangle_areas(h00, h11, h01, cut)) / 2)


def _triangle_areas(a, b, c, cut):
    """Each triangle's share above ``cut`` (:func:`area_above`)."""
    lo, mid, hi = np.sort(np.stack([a, b, c]), axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        lower = 1 - (cut - lo) ** 2 / ((mid - lo) * (hi - lo))
        upper = (hi - cut) ** 2 / ((hi - mid) * (hi - lo))
    return np.where(cut <= lo, 1.0, np.where(cut >= hi, 0.0,
                                             np.where(cut <= mid, lower, upper)))


def shear_spread(h, density, film, shear_weight) -> dict:
    """The moments of the local shear's spread over the films thicker than each of
    ``film`` [m]: ``film_area`` [-], and ``log_shear``, the area mean of ``ln s`` there (zero
    elsewhere) of ``s = 1/h + shear_weight density`` [1/m], from the films ``h`` [m] and the
    sliding flow's ``h^3 |grad chi_1|^2`` (``density``, one array per film) [1/m] at points
    of equal weight."""
    above = [h > cut for cut in film]
    local = [np.log(1 / h + shear_weight * d) for d in density]
    return {"film_area": np.array([a.mean() for a in above]),
            "log_shear": np.array([np.where(a, v, 0.0).mean() for a, v in zip(above, local)])}
