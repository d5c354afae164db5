"""Physical plausibility of measured maps: unit slips of 1e3 caught before any work.

A roughness patch given in um instead of m is 1e3 too high (every separation is then in
heavy contact), one in nm 1e3 too low (a perfectly smooth cell); a pitch in mm taken as m
makes a patch larger than the pin.  These checks look at what cannot be right for a
pin-on-disk tribometer: the RMS height Sq, the RMS slope Sdq (heights against pitch) and the
extent against the pin diameter.  :func:`check_patch` and :func:`check_pin` raise
:class:`ImplausibleTopography` for the impossible and return warnings for the unusual.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .core import Topography

#: roughness patch: Sq [m] refused outside, warned outside the inner range
PATCH_SQ = (1e-10, 1e-5)
PATCH_SQ_USUAL = (2e-9, 2e-6)
#: RMS slope: refused above, warned above
PATCH_SDQ, PATCH_SDQ_USUAL = 10.0, 1.0
#: pixel pitch of a roughness patch [m]
PATCH_PITCH = (1e-9, 1e-4)


class ImplausibleTopography(InputError):
    """A map whose heights or pitch cannot be those of a tribometer surface (units?)."""


def rms_slope(topo: Topography) -> float:
    """Sdq: RMS of the height gradient (periodic central differences) [-]."""
    z = topo.heights
    g1 = (np.roll(z, -1, axis=1) - np.roll(z, 1, axis=1)) / (2 * topo.spacing[0])
    g2 = (np.roll(z, -1, axis=0) - np.roll(z, 1, axis=0)) / (2 * topo.spacing[1])
    return float(np.sqrt(np.mean(g1 ** 2 + g2 ** 2)))


def check_patch(topo: Topography, name: str, pin_diameter: float | None = None) -> list[str]:
    """Refuse a roughness patch that cannot be right; return warnings for unusual ones."""
    sq, sdq = topo.rms_height(), rms_slope(topo)
    pitch, size = min(topo.spacing), max(topo.size)
    where = f"{name}: "
    if not PATCH_PITCH[0] <= pitch <= PATCH_PITCH[1]:
        raise ImplausibleTopography(f"{where}pixel pitch {pitch:.3g} m is implausible for a "
                                    "roughness patch (pitches are in metres: 0.3 um is 3e-7)")
    if not PATCH_SQ[0] <= sq <= PATCH_SQ[1]:
        raise ImplausibleTopography(f"{where}Sq = {sq:.3g} m is implausible for a roughness "
                                    "patch (heights in metres: 100 nm is 1e-7; a factor 1e3 "
                                    "off?)")
    if sdq > PATCH_SDQ:
        raise ImplausibleTopography(f"{where}RMS slope {sdq:.3g} is implausible (heights or "
                                    "pitch off by a factor 1e3?)")
    if pin_diameter is not None and size > pin_diameter:
        raise ImplausibleTopography(f"{where}patch of {size:.3g} m is larger than the pin "
                                    f"({pin_diameter:.3g} m): pitch in mm given as m?")
    warnings = []
    if not PATCH_SQ_USUAL[0] <= sq <= PATCH_SQ_USUAL[1]:
        warnings.append(f"{where}Sq = {sq:.3g} m is unusual for a run-in tribometer surface")
    if sdq > PATCH_SDQ_USUAL:
        warnings.append(f"{where}RMS slope {sdq:.3g} > 1: steeper than measured roughness "
                        "usually is (check heights and pitch)")
    return warnings


def check_pin(topo: Topography, name: str, pin_diameter: float) -> None:
    """Refuse a macro pin map whose extent cannot hold a pin of ``pin_diameter`` [m]."""
    size = max(topo.size)
    if not 0.5 * pin_diameter <= size <= 10 * pin_diameter:
        raise ImplausibleTopography(f"{name}: map of {size:.3g} m against a pin of "
                                    f"{pin_diameter:.3g} m ([tribometer] pin_diameter): pitch "
                                    "in the wrong unit?")
