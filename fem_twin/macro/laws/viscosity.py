"""Viscosity against temperature: the Walther equation of ASTM D341.

``log10 log10(nu + 0.7) = A - B log10(T)`` with the kinematic viscosity ``nu`` in mm^2/s
(cSt) and the absolute temperature ``T`` in K.  Two measured viscosities fix ``A`` and
``B`` (the paper's Table 3: 0.066 Pa s at 24 C, 0.024 Pa s at 50 C); more are fitted by
least squares in the transformed variables.  The dynamic viscosity is ``mu = rho nu`` with
the case's density, taken as constant over the range (a few per cent for mineral oils over
25 K, far below the uncertainty of a fitted contact temperature).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...checks import check, plausible
from ...errors import InputError

#: 0 C in K
KELVIN = 273.15


@dataclass(frozen=True)
class WaltherLaw:
    """ASTM D341 viscosity-temperature law; ``a``, ``b`` its constants, ``density`` [kg/m^3]."""

    a: float
    b: float
    density: float

    def __post_init__(self):
        for name in ("a", "b"):
            check(f"WaltherLaw.{name}", getattr(self, name), "number")
        if not self.b > 0:
            raise InputError(f"WaltherLaw.b = {self.b!r}: positive (an oil thins as it warms; "
                             "WaltherLaw.through fits it to measured viscosities)")
        plausible("WaltherLaw.density [kg/m^3]", self.density, "density")

    @classmethod
    def through(cls, temperatures, viscosities, density: float) -> "WaltherLaw":
        """The law through measured dynamic viscosities [Pa s] at temperatures [C] (two or
        more distinct ones)."""
        plausible("temperatures [C]", temperatures, "temperature_C")
        plausible("viscosities [Pa s]", viscosities, "viscosity")
        plausible("density [kg/m^3]", density, "density")
        t, mu = np.asarray(temperatures, float), np.asarray(viscosities, float)
        if t.shape != mu.shape or np.unique(t).size < 2:
            raise InputError("the viscosity-temperature law needs viscosities at two or more "
                             f"distinct temperatures, got {t.tolist()} C")
        x = np.log10(t + KELVIN)
        y = np.log10(np.log10(mu / density * 1e6 + 0.7))
        slope, intercept = np.polyfit(x, y, 1)
        if slope >= 0:
            raise InputError(f"viscosities {mu.tolist()} Pa s do not fall with temperature "
                             f"{t.tolist()} C")
        return cls(float(intercept), float(-slope), float(density))

    def viscosity(self, temperature):
        """Dynamic viscosity [Pa s] at ``temperature`` [C] (finite numbers)."""
        check("WaltherLaw.viscosity: temperature [C]", temperature, "numbers")
        if np.any(np.asarray(temperature, float) <= -KELVIN):
            raise InputError(f"WaltherLaw.viscosity: temperature [C] above absolute zero "
                             f"(-273.15 C; 24 C is 24.0), got {temperature!r}")
        plausible("WaltherLaw.viscosity: temperature [C]", temperature, "film_temperature_C")
        x = np.log10(np.asarray(temperature, float) + KELVIN)
        nu = 10 ** 10 ** (self.a - self.b * x) - 0.7
        return nu * 1e-6 * self.density

    def temperature(self, viscosity):
        """Temperature [C] at which the oil has the dynamic ``viscosity`` [Pa s]."""
        plausible("WaltherLaw.temperature: viscosity [Pa s]", viscosity, "viscosity")
        y = np.log10(np.log10(np.asarray(viscosity, float) / self.density * 1e6 + 0.7))
        return 10 ** ((self.a - y) / self.b) - KELVIN
