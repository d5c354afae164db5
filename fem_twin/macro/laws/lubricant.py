"""Lubricant models: Roelands piezoviscosity (eq 23) and Dowson-Higginson density (eq 24).

Both are functions of the relative pressure ``p = p_hd - p_cav`` [Pa].  The constants
default to Table 6 of the paper; ``viscosity`` (mu_0 at ambient pressure) depends on the
temperature (Table 3: 0.066 Pa s at 24 C, 0.024 Pa s at 50 C).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ... import tables as T
from ...checks import check, plausible
from ...errors import InputError


@dataclass(frozen=True)
class Lubricant:
    """An isothermal lubricant (SI units).

    Attributes
    ----------
    viscosity
        mu_0 at ambient pressure [Pa s]
    density
        rho_0 at ambient pressure [kg/m^3] (cancels from eq 17; kept for output)
    roelands_alpha, roelands_p0
        alpha_R [1/Pa] and p_0,R [Pa] of eq 23
    dh_c1, dh_c2
        C_1 [Pa] and C_2 [-] of eq 24
    piezoviscosity
        ``"roelands"`` (eq 23) or ``"barus"`` (``mu_0 exp(alpha p)`` with
        ``alpha = roelands_alpha``, the law of the Hamrock-Dowson fits and of many EHL papers)
    eyring_stress
        Eyring stress tau_0 [Pa] of the shear-thinning film: the Couette shear of eq 31
        becomes ``tau_0 asinh(tau_Newton / tau_0)`` (None: Newtonian, the paper's; an EHL
        contact needs it, its Newtonian shear at GPa viscosities is unphysical)
    """

    viscosity: float
    density: float = T.DENSITY
    roelands_alpha: float = T.ROELANDS_ALPHA
    roelands_p0: float = T.ROELANDS_P0
    dh_c1: float = T.DH_C1
    dh_c2: float = T.DH_C2
    piezoviscosity: str = "roelands"
    eyring_stress: float | None = None

    def __post_init__(self):
        if self.eyring_stress is not None:
            check("Lubricant.eyring_stress", self.eyring_stress, "number")
            if self.eyring_stress == 0:
                raise InputError("Lubricant.eyring_stress = 0: a Newtonian oil is None")
            plausible("Lubricant.eyring_stress", self.eyring_stress, "eyring_stress")
        if self.piezoviscosity not in ("roelands", "barus"):
            raise InputError("Lubricant.piezoviscosity must be 'roelands' or 'barus', got "
                             f"{self.piezoviscosity!r}")
        for name in ("viscosity", "density", "roelands_alpha", "roelands_p0", "dh_c1",
                     "dh_c2"):
            check(f"Lubricant.{name}", getattr(self, name), "number")
        for name in ("viscosity", "density", "roelands_p0", "dh_c1", "dh_c2"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"Lubricant.{name} must be positive and finite, got {v}")
        if self.viscosity > 10:
            raise InputError(f"Lubricant.viscosity {self.viscosity} Pa s is implausible: "
                             "give mu_0 in Pa s (0.066, not 66 mPa s)")
        if not (np.isfinite(self.roelands_alpha) and self.roelands_alpha >= 0):
            raise InputError("Lubricant.roelands_alpha must be >= 0 [1/Pa]")

    @property
    def roelands_z(self) -> float:
        """Pressure-viscosity index ``z_R = alpha_R p_0,R / (ln mu_0 + 9.67)``.

        The paper prints ``ln(mu_0 + 9.67)``; Roelands' index has ``ln(mu_0) + 9.67``, as
        in eq 23 itself (0.62 instead of 1.89 for 0.066 Pa s), which keeps the low-pressure
        slope of eq 23 equal to alpha_R.
        """
        return self.roelands_alpha * self.roelands_p0 / (np.log(self.viscosity) + 9.67)

    def viscosity_at(self, pressure):
        """mu_l of eq 23 (or Barus) at relative pressure ``p = p_hd - p_cav >= 0`` [Pa s]."""
        p = np.maximum(np.asarray(pressure, float), 0.0)
        mu0 = self.viscosity
        if self.piezoviscosity == "barus":
            return mu0 * np.exp(self.roelands_alpha * p)
        return mu0 * np.exp((np.log(mu0) + 9.67)
                            * (-1.0 + (1.0 + p / self.roelands_p0) ** self.roelands_z))

    def density_ratio(self, pressure):
        """rho_l / rho_0 of eq 24 at relative pressure ``p = p_hd - p_cav >= 0`` [-]."""
        p = np.maximum(np.asarray(pressure, float), 0.0)
        return (self.dh_c1 + self.dh_c2 * p) / (self.dh_c1 + p)

    def viscosity_log_slope(self, pressure):
        """``d ln(mu_l) / dp`` of eq 23 (or Barus) [1/Pa] (zero below p = 0, like the
        clipping of :meth:`viscosity_at`)."""
        p = np.asarray(pressure, float)
        if self.piezoviscosity == "barus":
            return np.where(p > 0, self.roelands_alpha, 0.0)
        x = 1.0 + np.maximum(p, 0.0) / self.roelands_p0
        slope = ((np.log(self.viscosity) + 9.67) * self.roelands_z
                 * x ** (self.roelands_z - 1) / self.roelands_p0)
        return np.where(p > 0, slope, 0.0)

    def density_log_slope(self, pressure):
        """``d ln(rho_l) / dp`` of eq 24 [1/Pa] (zero below p = 0)."""
        p = np.maximum(np.asarray(pressure, float), 0.0)
        c1, c2 = self.dh_c1, self.dh_c2
        slope = c1 * (c2 - 1) / ((c1 + p) * (c1 + c2 * p))
        return np.where(np.asarray(pressure, float) > 0, slope, 0.0)
