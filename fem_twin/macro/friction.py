"""Friction on the pin: homogenised shear stress (eq 31), boundary shear (eq 32), eqs 33-34."""

from __future__ import annotations

import numpy as np

from .. import tables as T

#: Boundary friction coefficient C_f,b of eq 32 (Bowden and Tabor, pure shearing).
BOUNDARY_FRICTION = T.BOUNDARY_FRICTION


def hydrodynamic_shear(pressure, mean_gap, cavity_fraction, viscosity, C, d, spacing,
                       speed, entrainment=None, eyring_stress=None) -> np.ndarray:
    """tau_hd,31 of eq 31 on the lower surface [Pa], sliding speed ``speed`` along +x1.

    ``tau = -(h_m/2) (C grad p)_1 + (mu / h_m) (-6 u_m d_1 + u_r) (1 - theta)`` with
    ``u_r = U`` and ``u_m = U/2`` (a stationary pin) or ``entrainment`` (a ball on a disk),
    with ``d`` at that slide-to-roll ratio (:func:`fem_twin.micro.at_slide_to_roll`, as
    :func:`~fem_twin.macro.solve_mixed` passes it): the Couette part is then
    ``(mu u_r / h_m) (1 - 3 d_1)`` in the pin-at-rest ``d``, zero in pure rolling;
    ``grad p`` by second-order central differences on the grid.  ``eyring_stress`` tau_0
    [Pa]: the Couette (shear-driven) part becomes ``tau_0 asinh(tau / tau_0)`` (Eyring).
    """
    dp2, dp1 = np.gradient(np.asarray(pressure, float), spacing[1], spacing[0])
    u_m = speed / 2 if entrainment is None else entrainment
    poiseuille = -mean_gap / 2 * (C[..., 0, 0] * dp1 + C[..., 0, 1] * dp2)
    couette = viscosity / mean_gap * (-6 * u_m * d[..., 0] + speed) * (1 - cavity_fraction)
    if eyring_stress is not None:
        couette = eyring_stress * np.arcsinh(couette / eyring_stress)
    return poiseuille + couette


def boundary_shear(contact_pressure, coefficient: float = BOUNDARY_FRICTION) -> np.ndarray:
    """tau_con = C_f,b p_con of eq 32 [Pa], where the surfaces slide (u_r > 0): a pure
    rolling contact has none (the operating point applies it only then; the creep of
    partial slip at small slide-to-roll ratios is not modelled, so any sliding gives the
    whole of it)."""
    return coefficient * np.asarray(contact_pressure, float)
