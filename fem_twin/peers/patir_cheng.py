"""Patir and Cheng's average flow and shear stress factors: their published curve fits.

Pressure flow (Patir and Cheng, J. Lubr. Technol. 100 (1978) 12, Table 1 and eq 25):
``phi_x = 1 - C exp(-r H)`` for gamma <= 1, ``1 + C H^-r`` for gamma > 1, and
``phi_y(H, gamma) = phi_x(H, 1/gamma)``.  Shear flow, shear stress (J. Lubr. Technol. 101
(1979) 220, Tables 1-3): ``Phi_s = A1 H^a1 exp(-a2 H + a3 H^2)`` (H <= 5),
``A2 exp(-H / 4)`` above; ``Phi_fs = A3 H^a4 exp(-a5 H + a6 H^2)`` (0 above H = 7);
``phi_fp = 1 - D exp(-s H)``; ``phi_f`` their closed form for the polynomial height
density ``(35 / 32 c) (1 - d^2/c^2)^3``, c = 3 sigma.  ``H = h / sigma`` is the mean-plane
separation over the composite rms roughness, gamma Peklenik's number.  Each fit holds over
its table's range of H; outside it (and for gamma outside [1/9, 9]) a function raises
:class:`~fem_twin.errors.InputError` unless asked to hold the fit's end value.  Between
the tabulated gammas the factors are interpolated linearly in ``ln gamma``.
"""

from __future__ import annotations

import numpy as np

from ..checks import arguments, check
from ..errors import InputError

#: the tabulated Peklenik numbers
GAMMAS = np.array([1 / 9, 1 / 6, 1 / 3, 1.0, 3.0, 6.0, 9.0])
#: phi_x: (C, r, smallest H) per gamma (1978, Table 1)
PRESSURE = np.array([[1.48, 0.42, 1.0], [1.38, 0.42, 1.0], [1.18, 0.42, 0.75],
                     [0.90, 0.56, 0.5], [0.225, 1.5, 0.5], [0.520, 1.5, 0.5],
                     [0.870, 1.5, 0.5]])
#: Phi_s: (A1, a1, a2, a3, A2) per gamma (1979, Table 1), H >= SHEAR_MIN_H
SHEAR_FLOW = np.array([[2.046, 1.12, 0.78, 0.03, 1.856], [1.962, 1.08, 0.77, 0.03, 1.754],
                       [1.858, 1.01, 0.76, 0.03, 1.561], [1.899, 0.98, 0.92, 0.05, 1.126],
                       [1.560, 0.85, 1.13, 0.08, 0.556], [1.290, 0.62, 1.09, 0.08, 0.388],
                       [1.011, 0.54, 1.07, 0.08, 0.249]])
#: Phi_fs: (A3, a4, a5, a6) per gamma (1979, Table 3), for SHEAR_MIN_H <= H <= 7
SHEAR_STRESS = np.array([[14.1, 2.45, 2.30, 0.10], [13.4, 2.42, 2.30, 0.10],
                         [12.3, 2.32, 2.30, 0.10], [11.1, 2.31, 2.38, 0.11],
                         [9.8, 2.25, 2.80, 0.18], [10.1, 2.25, 2.90, 0.18],
                         [8.7, 2.15, 2.97, 0.18]])
#: phi_fp: (D, s) per gamma (1979, Table 2), H >= SHEAR_MIN_H
PRESSURE_STRESS = np.array([[1.51, 0.52], [1.51, 0.54], [1.47, 0.58], [1.40, 0.66],
                            [0.98, 0.79], [0.97, 0.91], [0.73, 0.91]])
#: the smallest H of the 1979 fits (their simulations' range)
SHEAR_MIN_H = 0.5
#: Phi_s's switch to its exponential tail, and Phi_fs's end (zero above)
SHEAR_FLOW_TAIL, SHEAR_STRESS_END = 5.0, 7.0
#: phi_f's local film cut-off over 3 sigma (Patir and Cheng's epsilon*: 1/300)
FILM_CUTOFF = 1.0 / 300.0


def _bracket(gamma: float):
    """The two tabulated gammas around ``gamma`` and the weight of the upper one (ln)."""
    check("Peklenik number gamma", gamma, "number")
    if not GAMMAS[0] * (1 - 1e-12) <= gamma <= GAMMAS[-1] * (1 + 1e-12):
        raise InputError(f"Peklenik number gamma = {gamma:.4g} lies outside Patir and "
                         f"Cheng's tables [1/9, 9]: their fits do not extrapolate")
    j = int(np.clip(np.searchsorted(GAMMAS, gamma), 1, GAMMAS.size - 1))
    w = np.log(gamma / GAMMAS[j - 1]) / np.log(GAMMAS[j] / GAMMAS[j - 1])
    return j - 1, j, float(np.clip(w, 0.0, 1.0))


def _in_range(H, lo: float, what: str, hold: bool) -> np.ndarray:
    """``H`` (array) checked against the fit's smallest ``lo``, or held there."""
    check(f"{what}: H = h / sigma", H, "numbers")
    H = np.asarray(H, float)
    if hold:
        return np.maximum(H, lo)
    if np.any(H < lo * (1 - 1e-12)):
        raise InputError(f"{what}: H = h / sigma = {H.min():.3g} lies below the fit's range "
                         f"(H >= {lo:g}); pass hold=True to hold its end value")
    return H


def _interpolated(one, H, gamma: float, lo_of, what: str, hold: bool) -> np.ndarray:
    """``one(row, H)`` at ``gamma``, linear in ln gamma between the tabulated rows."""
    i, j, w = _bracket(gamma)
    rows = [k for k, weight in ((i, 1 - w), (j, w)) if weight > 0]
    H = _in_range(H, max(lo_of(k) for k in rows), what, hold)
    return sum(weight * one(k, H) for k, weight in ((i, 1 - w), (j, w)) if weight > 0)


@arguments(gamma="number")
def pressure_flow_range(gamma: float) -> float:
    """The smallest H [-] of ``phi_x``'s fit at ``gamma`` (of both rows around it)."""
    i, j, w = _bracket(gamma)
    return float(max(PRESSURE[k, 2] for k, weight in ((i, 1 - w), (j, w)) if weight > 0))


@arguments(gamma="number", hold=bool)
def pressure_flow(H, gamma: float, *, hold: bool = False) -> np.ndarray:
    """``phi_x(H, gamma)`` [-], the pressure flow factor along the sliding (1978, eq 25)."""
    def one(i, h):
        c, r, _ = PRESSURE[i]
        return 1 - c * np.exp(-r * h) if GAMMAS[i] <= 1 else 1 + c * h ** -r
    return _interpolated(one, H, gamma, lambda i: PRESSURE[i, 2], "phi_x", hold)


@arguments(gamma="number", hold=bool)
def pressure_flow_across(H, gamma: float, *, hold: bool = False) -> np.ndarray:
    """``phi_y(H, gamma) = phi_x(H, 1/gamma)`` [-], across the sliding (1978)."""
    _bracket(gamma)
    return pressure_flow(H, 1.0 / gamma, hold=hold)


@arguments(gamma="number", hold=bool)
def shear_flow(H, gamma: float, *, hold: bool = False) -> np.ndarray:
    """``Phi_s(H, gamma)`` [-] of one rough surface (1979, Table 1); the pair's
    ``phi_s = V1 Phi_s(gamma_1) - V2 Phi_s(gamma_2)`` (:func:`fem_twin.peers.average_flow`)."""
    def one(i, h):
        a1, e1, e2, e3, a2 = SHEAR_FLOW[i]
        near = np.minimum(h, SHEAR_FLOW_TAIL)
        return np.where(h <= SHEAR_FLOW_TAIL,
                        a1 * near ** e1 * np.exp(-e2 * near + e3 * near ** 2),
                        a2 * np.exp(-0.25 * h))
    return _interpolated(one, H, gamma, lambda i: SHEAR_MIN_H, "Phi_s", hold)


@arguments(gamma="number", hold=bool)
def shear_stress(H, gamma: float, *, hold: bool = False) -> np.ndarray:
    """``Phi_fs(H, gamma)`` [-] of one rough surface (1979, Table 3), zero above H = 7."""
    def one(i, h):
        a3, e4, e5, e6 = SHEAR_STRESS[i]
        near = np.minimum(h, SHEAR_STRESS_END)
        return np.where(h <= SHEAR_STRESS_END,
                        a3 * near ** e4 * np.exp(-e5 * near + e6 * near ** 2), 0.0)
    return _interpolated(one, H, gamma, lambda i: SHEAR_MIN_H, "Phi_fs", hold)


@arguments(gamma="number", hold=bool)
def pressure_stress(H, gamma: float, *, hold: bool = False) -> np.ndarray:
    """``phi_fp(H, gamma)`` [-], the Poiseuille part of the mean wall shear (1979)."""
    def one(i, h):
        d, s = PRESSURE_STRESS[i]
        return 1 - d * np.exp(-s * h)
    return _interpolated(one, H, gamma, lambda i: SHEAR_MIN_H, "phi_fp", hold)


def couette_stress(H) -> np.ndarray:
    """``phi_f(H) = h <1 / h_T>`` [-] (1979): the mean Couette shear over ``mu U / h``, for
    the polynomial height density with local films cut at ``FILM_CUTOFF 3 sigma``; above
    H = 30 its series ``1 + 1/H^2 + (27/11)/H^4``, where the closed form cancels."""
    H = _in_range(H, 1e-12, "phi_f", False)
    z = H / 3.0
    poly = (1 - z ** 2) ** 3
    small = np.log((z + 1) / FILM_CUTOFF) * poly + (
        -55 + z * (132 + z * (345 + z * (-160 + z * (-405 + z * (60 + 147 * z)))))) / 60
    with np.errstate(divide="ignore", invalid="ignore"):
        large = poly * np.log((z + 1) / (z - 1)) + z / 15 * (66 + z ** 2 * (30 * z ** 2 - 80))
    series = 1 + 1 / H ** 2 + 27 / 11 / H ** 4
    return np.where(z <= 1, 35 / 32 * z * small,
                    np.where(z < 10, 35 / 32 * z * large, series))
