"""Statistics of a periodic roughness cell: rms height, autocorrelation lengths, the Peklenik
number and the profiles' spectral moments (Patir and Cheng 1978; McCool 1986).

What a statistical mixed-lubrication model needs from a measured patch
(:mod:`fem_twin.peers`): the rms height ``sigma``, the lengths ``lambda_0.5`` at which the
normalised autocorrelation falls to 0.5 along x1 (the sliding) and x2, their ratio
``gamma`` (Peklenik's number: > 1 for ridges along the sliding), and the spectral moments
``m0, m2, m4`` of its profiles (the variances of the height, slope and curvature).  The
cell is periodic, as the cell problems take it (:func:`fem_twin.topography.resample_cell`),
so the autocorrelation is circular and the derivatives spectral.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import arguments, as_pair, check
from ..errors import InputError
from .core import Topography

#: the autocorrelation level of Patir and Cheng's correlation length
CORRELATION_LEVEL = 0.5


@dataclass(frozen=True)
class RoughnessStatistics:
    """Statistics of one periodic height map (SI units).

    sigma : rms height about the mean plane [m] (``sqrt(m0)``)
    lengths : ``(lambda_x1, lambda_x2)``, where the autocorrelation falls to 0.5 [m]
    m2, m4 : ``(along x1, along x2)``: the profiles' mean square slope [-] and curvature
    [1/m^2] (spectral moments; m0 = sigma^2)
    bounded : ``(x1, x2)``: True where the autocorrelation stays above 0.5 over half the
    cell, whose half is then the length (a lower bound of the true one)
    """

    sigma: float
    lengths: tuple[float, float]
    m2: tuple[float, float]
    m4: tuple[float, float]
    bounded: tuple[bool, bool] = (False, False)

    def __post_init__(self):
        check("RoughnessStatistics.sigma", self.sigma, "number")
        if self.sigma < 0:
            raise InputError(f"RoughnessStatistics.sigma = {self.sigma!r}: an rms height [m], "
                             "not negative (0.1 um is 1e-7)")
        for name, unit in (("lengths", "m, positive (10 um is 1e-5)"), ("m2", "[-], >= 0"),
                           ("m4", "1/m^2, >= 0")):
            pair = as_pair(f"RoughnessStatistics.{name}", getattr(self, name))
            if not all(np.isfinite(pair)) or min(pair) < 0 or (name == "lengths"
                                                               and min(pair) == 0):
                raise InputError(f"RoughnessStatistics.{name} = {getattr(self, name)!r}: "
                                 f"two finite numbers ({unit})")

    @property
    def gamma(self) -> float:
        """Peklenik's number ``lambda_x1 / lambda_x2`` [-] (Patir and Cheng's gamma)."""
        return self.lengths[0] / self.lengths[1]

    @property
    def gamma_bound(self) -> str:
        """What :attr:`gamma` is: ``"exact"``, an ``"upper"`` or a ``"lower"`` bound (one
        length bounded by the cell), or ``"none"`` (both)."""
        return {(False, False): "exact", (False, True): "upper", (True, False): "lower",
                (True, True): "none"}[tuple(self.bounded)]

    @property
    def moments(self) -> tuple[float, float, float]:
        """``(m0, m2, m4)`` of the equivalent isotropic surface [m^2, -, 1/m^2]: the geometric
        means of the two directions' moments (McCool 1986, for mild anisotropy)."""
        return (self.sigma ** 2, float(np.sqrt(np.prod(self.m2))),
                float(np.sqrt(np.prod(self.m4))))


@arguments(topo=Topography)
def roughness_statistics(topo: Topography) -> RoughnessStatistics:
    """:class:`RoughnessStatistics` of a periodic, fully valid cell ``topo`` (where the
    autocorrelation does not fall to 0.5 within half the cell along a direction, the half
    cell is its length and ``bounded`` says so)."""
    if topo.mask is not None:
        raise InputError("roughness statistics need a fully valid cell: fill its defects "
                         "first (fem_twin.topography.fill_defects)")
    z = topo.heights - topo.heights.mean()
    power = np.abs(np.fft.fft2(z)) ** 2 / z.size ** 2          # sum = m0 (Parseval)
    if not np.sum(power) > 0:
        raise InputError("roughness_statistics: a flat cell (sigma = 0) has no roughness to "
                         "describe: no autocorrelation, no summits (a smooth body adds none "
                         "to a pair's statistics)")
    acf = np.real(np.fft.ifft2(power))
    acf = acf / acf[0, 0]
    k1 = 2 * np.pi * np.fft.fftfreq(z.shape[1], topo.spacing[0])[None, :]
    k2 = 2 * np.pi * np.fft.fftfreq(z.shape[0], topo.spacing[1])[:, None]
    m2 = tuple(float(np.sum(power * k ** 2)) for k in (k1, k2))
    m4 = tuple(float(np.sum(power * k ** 4)) for k in (k1, k2))
    (l1, b1), (l2, b2) = (_half_length(acf[0, :], topo.spacing[0]),
                          _half_length(acf[:, 0], topo.spacing[1]))
    return RoughnessStatistics(sigma=float(np.sqrt(np.sum(power))), lengths=(l1, l2),
                               m2=m2, m4=m4, bounded=(b1, b2))


def _half_length(acf, dx: float) -> tuple[float, bool]:
    """``(lag [m], bounded)``: where the circular autocorrelation ``acf`` (lag 0 first)
    first falls to :data:`CORRELATION_LEVEL`, linear between pixels, or half the cell and
    True where it does not."""
    half = acf[: acf.size // 2 + 1]
    below = np.flatnonzero(half <= CORRELATION_LEVEL)
    if not below.size:
        return float((half.size - 1) * dx), True
    i = below[0]
    frac = (half[i - 1] - CORRELATION_LEVEL) / (half[i - 1] - half[i])
    return float((i - 1 + frac) * dx), False
