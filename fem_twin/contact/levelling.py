"""Pin levelling by torque balance (paper eqs 1-7, Table 4) and set averaging of pins.

The pin self-aligns against the disk under ``F_N,imp = 50 N``: its face is tilted until the
dry contact pressure exerts no torque about x1 and x2.  The paper's PID controller (eqs
5-6) is available; the default is a quasi-Newton (Broyden) iteration on the same residuals,
which reaches the same tilt in a few contact solves.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.ndimage as ndi

from .. import tables as T
from ..checks import arguments
from ..errors import InputError
from ..topography.core import Topography
from ..topography.geometry import pin_face
from ..topography.levelling import level, radial_mask
from .solver import ContactNotConverged, ContactResult, solve

#: Table 4 of the paper.
TABLE4 = {"load": T.LEVELLING_LOAD, "e_reduced": T.E_REDUCED, "hardness": T.HARDNESS,
          "gains": T.LEVELLING_GAINS}


@dataclass(frozen=True, eq=False)
class LevellingResult:
    """A levelled pin and how it got there.

    pin : the tilted (levelled) lower surface, holder unchanged at its height
    tilt : (alpha_x1, alpha_x2) [rad] applied to the unlevelled pin by eq 7
    residuals : final torque residuals (r_x1, r_x2) of eqs 3-4
    contact : the dry contact state of the levelled pin
    history : rows (alpha_x1, alpha_x2, r_x1, r_x2) per outer iteration
    """

    pin: Topography
    tilt: tuple[float, float]
    residuals: tuple[float, float]
    contact: ContactResult
    history: np.ndarray


@arguments(pressure="field", x1="field", x2="field")
def torque_residuals(pressure: np.ndarray, x1: np.ndarray, x2: np.ndarray) -> np.ndarray:
    """Dimensionless torque residuals (r_x1, r_x2) of eqs 1-4 (pixel area cancels)."""
    t1, t2 = -x2 * pressure, x1 * pressure
    n1, n2 = np.abs(t1).sum(), np.abs(t2).sum()
    if n1 == 0 or n2 == 0:
        raise InputError("no contact pressure: torques undefined")
    return np.array([t1.sum() / n1, t2.sum() / n2])


@arguments(pin=Topography, tilt="pair")
def tilt_pin(pin: Topography, tilt, holder_height: float = T.HOLDER_HEIGHT) -> Topography:
    """Eq 7 on the pin face: ``x3_low = x3_low0 + x2 tan(a_x1) - x1 tan(a_x2)``.

    The holder (pixels at ``holder_height``) stays where it is.
    """
    x1, x2 = pin.coordinates()
    face = pin_face(pin, holder_height)
    tilted = pin.heights + x2 * np.tan(tilt[0]) - x1 * np.tan(tilt[1])
    return pin.with_heights(np.where(face, tilted, holder_height))


def _pid(evaluate, tilt, gains, tol, max_iter):
    """The paper's incremental PID on the torque residuals (eqs 5-6, angles in degrees):
    the last tilt [rad] and ``evaluate``'s ``(tilted, contact, residuals)`` there."""
    kp, ki, kd = gains
    state = evaluate(tilt)
    r = state[2]
    integral, r_prev = np.zeros(2), r.copy()
    for _ in range(max_iter):
        if np.max(np.abs(r)) < tol:
            break
        integral += r
        tilt = np.deg2rad((kp * r + ki * integral + kd * (r - r_prev)) * 360.0)
        r_prev = r
        state = evaluate(tilt)
        r = state[2]
    return tilt, state


def _broyden(evaluate, tilt, tol, max_iter, pin, holder_height, history):
    """Broyden's method on the torque residuals from the finite-difference Jacobian:
    the last tilt [rad] and ``evaluate``'s ``(tilted, contact, residuals)`` there."""
    state = evaluate(tilt)
    r = state[2]
    jac = _initial_jacobian(evaluate, tilt, r, pin, holder_height)
    for _ in range(max_iter):
        if np.max(np.abs(r)) < tol:
            break
        try:
            step = -np.linalg.solve(jac, r)
        except np.linalg.LinAlgError:
            raise ContactNotConverged(
                "pin levelling: a tilt does not change the contact torques (singular "
                "Jacobian); is the pin face cropped by the edge of the map, or the map "
                "not square about the pin?", _residuals(history)) from None
        state = evaluate(tilt + step)
        jac += np.outer(state[2] - r - jac @ step, step) / (step @ step)   # Broyden update
        tilt, r = tilt + step, state[2]
    return tilt, state


@arguments(pin=Topography, disk=Topography, load="number")
def level_pin(pin: Topography, disk: Topography | None = None, *, load: float = TABLE4["load"],
              e_reduced: float = TABLE4["e_reduced"], hardness: float = TABLE4["hardness"],
              method: str = "broyden", tol: float = 1e-6, max_iter: int = 200,
              gains=TABLE4["gains"], holder_height: float = T.HOLDER_HEIGHT) -> LevellingResult:
    """Tilt ``pin`` (mounted, origin at its centre) until the contact torques vanish.

    ``disk`` is the flipped upper surface on the same grid (flat if None).  ``method`` is
    ``"broyden"`` (default) or ``"pid"`` (eqs 5-6 with ``gains = (K_P, K_I, K_D)``, angles
    in degrees as in the paper).  Converged when both residuals are below ``tol``
    (paper: 1e-6); otherwise :class:`ContactNotConverged` with the history is raised.
    """
    upper = np.zeros(pin.shape) if disk is None else np.asarray(disk.heights)
    if upper.shape != pin.shape:
        raise InputError(f"disk grid {upper.shape} does not match pin grid {pin.shape}")
    if method not in ("broyden", "pid"):
        raise InputError(f"method must be 'broyden' or 'pid', got {method!r}")
    x1, x2 = pin.coordinates()
    state = {"p": None}
    history = []

    def evaluate(tilt):
        tilted = tilt_pin(pin, tilt, holder_height)
        res = solve(upper - tilted.heights, pin.spacing, e_reduced, load=load,
                    hardness=hardness, initial_pressure=state["p"])
        state["p"] = res.pressure
        r = torque_residuals(res.pressure, x1, x2)
        history.append([tilt[0], tilt[1], r[0], r[1]])
        return tilted, res, r

    tilt = np.zeros(2) if method == "pid" else mean_plane_tilt(pin, upper, holder_height)
    if method == "pid":
        tilt, (tilted, res, r) = _pid(evaluate, tilt, gains, tol, max_iter)
    else:
        tilt, (tilted, res, r) = _broyden(evaluate, tilt, tol, max_iter, pin, holder_height,
                                          history)
    if np.max(np.abs(r)) >= tol:
        raise ContactNotConverged(f"pin levelling ({method}) did not reach torque residuals "
                                  f"below {tol}", _residuals(history))
    return LevellingResult(tilted, (float(tilt[0]), float(tilt[1])), (float(r[0]), float(r[1])),
                           res, np.array(history))


def _residuals(history) -> list:
    """The largest torque residual of each step of a levelling ``history``."""
    return [float(np.max(np.abs(h[2:]))) for h in history]


def mean_plane_tilt(pin: Topography, upper: np.ndarray, holder_height: float = T.HOLDER_HEIGHT):
    """Tilt (eq 7) that removes the mean-plane slope of the gap over the pin face [rad].

    The paper's initial levelling guess; exact for a flat face and any centro-symmetric
    crown, and a start inside the region where the torques depend smoothly on the tilt.
    """
    face = pin_face(pin, holder_height)
    x1, x2 = pin.coordinates()
    gap = upper - pin.heights
    design = np.column_stack([np.ones(face.sum()), x1[face], x2[face]])
    _, b1, b2 = np.linalg.lstsq(design, gap[face], rcond=None)[0]
    return np.array([np.arctan(b2), np.arctan(-b1)])


def _initial_jacobian(evaluate, tilt, r, pin, holder_height):
    """Finite-difference d r / d tilt with a step of 1e-3 of the face's slope scale."""
    face = pin_face(pin, holder_height)
    x1, x2 = pin.coordinates()
    radius = np.sqrt(np.max(x1[face] ** 2 + x2[face] ** 2))
    h = 1e-3 * max(np.ptp(pin.heights[face]), 1e-7) / radius
    jac = np.empty((2, 2))
    for k in range(2):
        d = np.zeros(2)
        d[k] = h
        jac[:, k] = (evaluate(tilt + d)[2] - r) / h
    return jac


@arguments(pins=[Topography])
def average_pins(pins, *, radius: float = 3e-3, truncation: float = -20e-6,
                 holder_height: float = T.HOLDER_HEIGHT) -> Topography:
    """Set average of levelled pins (paper 2.2.1, Figure 3).

    Each pin is re-zeroed at its mean plane within ``radius`` of its centre, interpolated
    (linearly) onto the grid of the first pin, and the heights are averaged; below
    ``truncation`` the holder height is enforced again.  Level the result once more with
    :func:`level_pin`.
    """
    pins = list(pins)
    if not pins:
        raise InputError("no pins to average")
    ref = pins[0]
    X1, X2 = ref.coordinates()
    total = np.zeros(ref.shape)
    for pin in pins:
        face = pin_face(pin, holder_height)
        z = level(pin, radial_mask(pin, radius) & face).heights
        z = np.where(face, z, holder_height)
        rows = (X2 - pin.origin[1]) / pin.spacing[1]
        cols = (X1 - pin.origin[0]) / pin.spacing[0]
        total += ndi.map_coordinates(z, [rows, cols], order=1, mode="constant",
                                     cval=holder_height)
    mean = total / len(pins)
    mean = np.where(mean < truncation, holder_height, mean)
    return ref.with_heights(mean, mask=None, meta={"sample": f"average of {len(pins)} pins",
                                                   "history": ["average_pins"]})
