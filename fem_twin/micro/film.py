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

from dataclasses import dataclass

import numpy as np

#: triangles whose nodal films differ by less than this fraction of their mean take the
#: midpoint rule (error below the fraction squared; the divided differences lose digits)
NEAR_EQUAL = 1e-4


def _antiderivative(h, cut):
    """``G`` of the module docstring [m], zero below ``cut``."""
    above = h > cut
    safe = np.where(above, h, cut)
    return np.where(above, safe * np.log(safe / cut) - (safe - cut), 0.0)


@dataclass(frozen=True, eq=False)
class Triangles:
    """The periodic cell's nodal gap split into two triangles a pixel (``(2, ny, nx)``
    arrays, one per diagonal family): each triangle's nodal films sorted, ``lo <= mid <=
    hi`` [m], and their ``mean`` [m]; built once per gap and read for every cut."""

    lo: np.ndarray
    mid: np.ndarray
    hi: np.ndarray
    mean: np.ndarray

    @classmethod
    def of(cls, gap) -> Triangles:
        """The triangles of the nodal ``gap`` [m] (ny, nx)."""
        h00 = np.asarray(gap, float)
        h10 = np.roll(h00, -1, axis=1)
        h01 = np.roll(h00, -1, axis=0)
        h11 = np.roll(h10, -1, axis=0)
        a, b, c = np.stack([h00, h00]), np.stack([h10, h11]), np.stack([h11, h01])
        low, high = np.minimum(a, b), np.maximum(a, b)      # a sort of three, exactly
        return cls(np.minimum(low, c), np.maximum(low, np.minimum(high, c)),
                   np.maximum(high, c), (a + b + c) / 3)

    def mean_inverse(self, cut: float) -> float:
        """``<1/h>`` over the films thicker than ``cut`` [1/m] (:func:`mean_inverse_film`):
        per triangle ``G[lo, mid, hi]``, half its mean of ``1/h`` above ``cut``, zero where
        no node is above it (a plastic spot's raw gap is negative: the relative closeness
        takes ``|hi + lo|``)."""
        lo, mid, hi, mean = self.lo, self.mid, self.hi, self.mean
        spread = hi - lo
        close = spread <= NEAR_EQUAL * np.abs(hi + lo) / 2
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
        means = np.where(hi <= cut, 0.0, np.where(close, midpoint, exact))
        return float(np.mean(means[0] + means[1]))

    def area_above(self, cut: float) -> float:
        """The share of the cell [-] where the interpolant lies above ``cut`` [m]
        (:func:`area_above`)."""
        lo, mid, hi = self.lo, self.mid, self.hi
        with np.errstate(divide="ignore", invalid="ignore"):
            lower = 1 - (cut - lo) ** 2 / ((mid - lo) * (hi - lo))
            upper = (hi - cut) ** 2 / ((hi - mid) * (hi - lo))
        shares = np.where(cut <= lo, 1.0, np.where(cut >= hi, 0.0,
                                                   np.where(cut <= mid, lower, upper)))
        return float(np.mean(shares[0] + shares[1]) / 2)


def mean_inverse_film(gap, cut: float) -> float:
    """``<1/h>`` over the films thicker than ``cut`` [1/m] of the periodic cell's nodal
    ``gap`` [m] (ny, nx), exact on its linear interpolant over two triangles a pixel."""
    return Triangles.of(gap).mean_inverse(cut)


def area_above(gap, cut: float) -> float:
    """The share of the periodic cell [-] where the linear interpolant of the nodal ``gap``
    [m] (two triangles a pixel, as :func:`mean_inverse_film`) lies above ``cut`` [m]:
    per triangle of sorted nodal values lo <= mid <= hi, 1 below lo, ``1 - (c - lo)^2 /
    ((mid - lo)(hi - lo))`` up to mid, ``(hi - c)^2 / ((hi - mid)(hi - lo))`` up to hi."""
    return Triangles.of(gap).area_above(cut)


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
