"""Greenwood and Tripp's asperity contact of two rough surfaces (Proc. Inst. Mech. Eng. 185
(1970) 625), with the summits from the spectral moments (McCool, Wear 107 (1986) 37).

Summit pairs of density ``eta`` and radius ``beta`` touch in Hertz contact; integrated over
their heights and lateral offsets, the mean contact pressure and the real contact area
fraction at mean-plane separation ``h`` are

    p_con = (8 sqrt(2) pi / 15) (eta beta s)^2 sqrt(s / beta) E' F_5/2(H),
    A_r / A = pi^2 (eta beta s)^2 F_2(H),      H = (h - z_s) / s,

with ``E'`` of eq 22 (twice the Hertz modulus), ``s`` the summits' height spread and
``z_s`` their mean height.  ``F_n(H) = int_H^inf (x - H)^n phi(x) dx`` for the standard
normal density phi (or an exponential one, Greenwood and Williamson's closed form).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import special

from ..checks import arguments, check, plausible
from ..errors import InputError

#: the summit heights' densities of :func:`tail_moment`
DENSITIES = ("gaussian", "exponential")
#: below ``H = -DEEP`` :func:`tail_moment` takes its expansion in ``1/H^2`` (its next term
#: is below 1e-7 relative there)
DEEP = 10.0
#: McCool's constant of the summit height variance, ``1 - 0.8968 / alpha``
SUMMIT_VARIANCE = 0.8968


def tail_moment(H, n: float, density: str = "gaussian") -> np.ndarray:
    """``F_n(H)`` [-]: the n-th moment of the heights above ``H`` (in units of their
    spread), for the standard normal density (parabolic cylinder function
    ``Gamma(n+1) exp(-H^2/4) D_{-n-1}(H) / sqrt(2 pi)``) or the exponential ``exp(-x)``
    (``Gamma(n+1) exp(-H)`` above 0)."""
    check("tail_moment: H", H, "numbers")
    check("tail_moment: n", n, "number")
    H = np.asarray(H, float)
    if density not in DENSITIES:
        raise InputError(f"density must be one of {DENSITIES}, got {density!r}")
    if not n >= 0:
        raise InputError(f"tail_moment: n = {n} must be >= 0")
    if density == "exponential":
        below = np.maximum(-H, 0.0)                    # heights start at 0
        return special.gamma(n + 1) * np.exp(-H) * special.gammaincc(n + 1, below)
    d, _ = special.pbdv(-n - 1, H)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        out = special.gamma(n + 1) * np.exp(-H ** 2 / 4) * d / np.sqrt(2 * np.pi)
        a = -H                                         # deep in contact: E[(a + x)^n], a >> 1
        deep = a ** n * (1 + n * (n - 1) / (2 * a ** 2)
                         + n * (n - 1) * (n - 2) * (n - 3) / (8 * a ** 4))
    out = np.where(H < -DEEP, deep, out)               # D_{-n-1} overflows there
    return np.where(H > 38, 0.0, out)                  # exp(-H^2/2) underflows there


@dataclass(frozen=True)
class Summits:
    """Summit statistics of a Gaussian surface (SI units): ``density`` eta [1/m^2],
    ``radius`` beta [m], height ``spread`` [m] and ``mean`` height above the mean plane
    [m]."""

    density: float
    radius: float
    spread: float
    mean: float

    def __post_init__(self):
        for name in ("density", "radius", "spread", "mean"):
            check(f"Summits.{name}", getattr(self, name), "number")
        for name, unit in (("density", "summits per m^2, 1e10 is 1e4 per mm^2"),
                           ("radius", "m, a summit's radius of curvature (20 um is 20e-6)"),
                           ("spread", "m, the summit heights' rms (0.1 um is 1e-7)")):
            if not getattr(self, name) > 0:
                raise InputError(f"Summits.{name} = {getattr(self, name)!r}: must be positive "
                                 f"({unit})")

    @classmethod
    def from_moments(cls, m0: float, m2: float, m4: float) -> "Summits":
        """McCool (1986) from the profile moments ``m0`` [m^2], ``m2`` [-], ``m4``
        [1/m^2] of an isotropic surface: ``eta = m4 / (6 pi sqrt(3) m2)``,
        ``beta = (3/8) sqrt(pi / m4)``, ``alpha = m0 m4 / m2^2``,
        spread ``sqrt(1 - 0.8968/alpha) sqrt(m0)``, mean ``4 sqrt(m0 / (pi alpha))``."""
        for name, m in (("m0", m0), ("m2", m2), ("m4", m4)):
            check(f"Summits.from_moments: {name}", m, "number")
        if not (m0 > 0 and m2 > 0 and m4 > 0):
            raise InputError("spectral moments must be positive: a surface flat along one "
                             "direction (pure ridges) has no summits for Greenwood-Tripp")
        alpha = m0 * m4 / m2 ** 2
        return cls(density=float(m4 / (6 * np.pi * np.sqrt(3) * m2)),
                   radius=float(3 / 8 * np.sqrt(np.pi / m4)),
                   spread=float(np.sqrt(max(1 - SUMMIT_VARIANCE / alpha, 0.0) * m0)),
                   mean=float(4 * np.sqrt(m0 / (np.pi * alpha))))

    def separation(self, h) -> np.ndarray:
        """``H = (h - z_s) / s`` [-] at mean-plane separations ``h`` [m]."""
        return (np.asarray(h, float) - self.mean) / self.spread

    @property
    def roughness_parameter(self) -> float:
        """``eta beta s`` [-], the product the contact scales with (0.03-0.05 typically)."""
        return self.density * self.radius * self.spread


@arguments(h="numbers", summits=Summits, e_reduced="number")
def contact_pressure(h, summits: Summits, e_reduced: float,
                     density: str = "gaussian") -> np.ndarray:
    """Greenwood-Tripp mean asperity pressure [Pa] at mean-plane separations ``h`` [m]
    (``e_reduced``: E' of eq 22 [Pa])."""
    plausible("contact_pressure: e_reduced [Pa]", e_reduced, "reduced_modulus")
    s = summits
    k = 8 * np.sqrt(2) * np.pi / 15 * s.roughness_parameter ** 2 * np.sqrt(s.spread
                                                                              / s.radius)
    return k * e_reduced * tail_moment(s.separation(h), 2.5, density)


@arguments(h="numbers", summits=Summits)
def contact_fraction(h, summits: Summits, density: str = "gaussian") -> np.ndarray:
    """Greenwood-Tripp real contact area over the nominal one [-] at ``h`` [m], at most 1."""
    a = np.pi ** 2 * summits.roughness_parameter ** 2 * tail_moment(
        summits.separation(h), 2.0, density)
    return np.minimum(a, 1.0)
