"""Rate of change of a dry contact state whose shape moves (the tangent of the contact problem).

At imposed separation the deformed gap ``g = h0 + shape + K p`` is zero on the elastic
contact set ``C = {p_min < p < H}``; the pressure stays at ``p_min`` where the gap is open and
at ``H`` where it is plastic.  When the shape changes at the rate ``shape'`` the pressure
changes at the rate ``p'`` that keeps these conditions (almost every instant, the sets are
fixed)::

    (K p')|_C = -shape'|_C,    p' = 0 off C,

a symmetric positive definite system on ``C`` (conjugate gradients, one FFT pair per
iteration).  The deformation rate is ``K p'``.  The sliding cell problems of eq 8 need the
time derivative of the gap: for a rough surface translating rigidly at ``V`` the shape rate
is ``-V dz/dx1``, known exactly at every instant, and this module adds the rate of the
contact deformation, so the squeeze term carries no time-step error.
"""

from __future__ import annotations

import numpy as np

from ..checks import arguments
from ..errors import InputError
from .elastic import elastic_operator
from .solver import ContactNotConverged, ContactResult


@arguments(result=ContactResult, shape_rate="field", spacing="pair", e_reduced="number")
def contact_rate(result: ContactResult, shape_rate, spacing, e_reduced: float, *,
                 hardness: float = np.inf, p_min: float = 0.0, periodic: bool = True,
                 tol: float = 1e-10, max_iter: int = 2000):
    """Pressure and deformation rates of a separation-controlled contact state.

    Parameters
    ----------
    result : the converged contact (its ``pressure`` fixes the sets).
    shape_rate : rate of change of the undeformed gap geometry, ``(ny, nx)`` [m per unit of
        the rate variable, e.g. m/s, or m per metre of sliding].
    spacing, e_reduced, hardness, p_min, periodic : as for :func:`fem_twin.contact.solve`.
    tol : relative residual of the CG on the contact set.

    Returns ``(pressure_rate [Pa per unit], deformation_rate [m per unit])``.  Raises
    :class:`ContactNotConverged` with the residual history if CG does not converge.
    """
    p = np.asarray(result.pressure, float)
    rate = np.asarray(shape_rate, float)
    if rate.shape != p.shape or not np.all(np.isfinite(rate)):
        raise InputError(f"shape_rate must be a finite {p.shape} array, got {rate.shape}")
    op = elastic_operator(p.shape, spacing, e_reduced, periodic)
    on = (p > p_min) & (p < hardness)
    x = np.zeros_like(p)
    if not on.any():
        return x, x.copy()
    b = -rate[on]
    r = b.copy()
    d = np.zeros_like(p)
    d[on] = r
    rr, norm_b, history = r @ r, np.linalg.norm(b), []
    for _ in range(max_iter):
        if np.sqrt(rr) <= tol * norm_b:
            return x, op(x)
        kd = op(d)[on]
        alpha = rr / (d[on] @ kd)
        x[on] += alpha * d[on]
        r -= alpha * kd
        rr_new = r @ r
        history.append(np.sqrt(rr_new) / norm_b)
        d[on] = r + (rr_new / rr) * d[on]
        rr = rr_new
    raise ContactNotConverged(f"contact rate did not converge in {max_iter} iterations "
                              f"(tol {tol})", history)
