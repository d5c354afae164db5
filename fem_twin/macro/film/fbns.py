"""Fischer-Burmeister-Newton-Schur (FBNS) solution of the JFO complementarity problem.

The paper's EHL-FBNS scheme for ``K p + B (1 - theta) = 0`` with ``p theta = 0``,
``p, theta >= 0``: the complementarity is the Fischer-Burmeister equation

    phi_FB(p, t) = p + t - sqrt(p^2 + t^2) = 0,     t = s theta,

with ``s`` a pressure scale (100x the uncavitated pressures),

and Newton's method on the 2N equations is reduced by a Schur complement to one N x N
system per step: at each node the better-conditioned of the two FB derivatives is used to
eliminate ``dt`` (pressurised-like nodes) or ``dp`` (cavitated-like nodes).  A backtracking
line search on ``|F|^2`` globalises it.  Returns the same ``phi`` (``p`` or ``-t``) as the
p-theta switch solver, so the two are interchangeable.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ...checks import arguments
from ...errors import ReynoldsNotConverged


@arguments(K=sp.spmatrix, B=sp.spmatrix, scale="number")
def solve_complementarity_fb(K, B, dirichlet, p_boundary, scale, *, phi0=None, tol=1e-10,
                             max_iter=200, inexact=False):
    """FBNS on the interior nodes; same arguments and results as
    :func:`fem_twin.macro.film.switch.solve_complementarity`."""
    n = K.shape[0]
    interior = np.flatnonzero(~np.asarray(dirichlet).ravel())
    KI = K[interior][:, interior].tocsc()
    BI = B[interior][:, interior].tocsc()
    # boundary contributions (p = p_boundary, theta = 0 on Dirichlet nodes)
    p_full = np.full(n, float(p_boundary))
    p_full[interior] = 0.0
    const = K[interior] @ p_full + B[interior] @ np.ones(n) - BI @ np.ones(interior.size)
    # const + KI p + BI (1 - theta) = F1 on the interior
    p = np.full(interior.size, max(float(p_boundary), 0.0))
    theta = np.zeros(interior.size)
    if phi0 is not None:
        phi = np.asarray(phi0, float).ravel()[interior]
        p, theta = np.maximum(phi, 0.0), np.maximum(-phi, 0.0) / scale
    size = abs(K[interior]) @ np.maximum(np.abs(p_full), abs(p_boundary)) \
        + abs(B[interior]) @ np.ones(n) + 1e-300
    ones = np.ones(interior.size)

    def residual(p, theta, s):
        f1 = const + KI @ p + BI @ (ones - theta)
        f2 = p + s * theta - np.hypot(p, s * theta)
        return f1, f2

    def norm(f1, f2, s):
        return float(np.sum((f1 / size) ** 2) + np.sum((f2 / s) ** 2))

    # pressure scale of t = s theta: 100x the pressures of the uncavitated problem (one LU);
    # the zero set of phi_FB does not depend on s, Newton's convergence does (tested: a scale
    # near the pressures took 2-4x more steps than one 100x above them)
    p_lin = spla.splu(KI).solve(-(const + BI @ ones))
    s = 100 * max(float(np.abs(p_lin).max()), abs(float(p_boundary)), 1e-300)
    if phi0 is None:
        p = np.maximum(p_lin, 0.0)
    history = []
    for it in range(1, max_iter + 1):
        f1, f2 = residual(p, theta, s)
        res = max(float(np.max(np.abs(f1) / (size + abs(KI) @ p))), float(np.max(np.abs(f2))) / s)
        history.append(res)
        if res < tol:
            return _phi(p, theta, s, scale, n, interior, p_boundary), it, history
        d_p, d_theta = _newton_direction(KI, BI, p, theta, s, f1, f2, history)
        merit, lam = norm(f1, f2, s), 1.0
        while True:
            p_new, theta_new = p + lam * d_p, theta + lam * d_theta
            if norm(*residual(p_new, theta_new, s), s) <= (1 - 1e-4 * lam) * merit or lam < 1e-6:
                break
            lam /= 2
        p, theta = p_new, theta_new
    if inexact:                     # a truncated inner solve (see solve_complementarity)
        return _phi(p, theta, s, scale, n, interior, p_boundary), max_iter + 1, history
    raise ReynoldsNotConverged(f"FBNS: no convergence in {max_iter} Newton steps (tol {tol})",
                               history)


def _phi(p, theta, s, scale, n, interior, p_boundary):
    """The switch variable of :func:`fem_twin.macro.film.switch.solve_complementarity`."""
    phi = np.full(n, float(p_boundary))
    phi[interior] = np.where(p >= s * theta, p, -theta * scale)
    return phi


def _newton_direction(KI, BI, p, theta, s, f1, f2, history):
    """The semismooth Newton direction ``(d_p, d_theta)`` of ``(F1, phi_FB(p, s theta))``:
    per node the larger of the two Fischer-Burmeister slopes is eliminated, leaving one
    sparse system in ``p`` or ``theta`` (SuperLU)."""
    t = s * theta
    r = np.hypot(p, t)
    safe = np.where(r > 0, r, 1.0)
    dp = np.where(r > 0, 1 - p / safe, 1 - 1 / np.sqrt(2))
    dt = np.where(r > 0, 1 - t / safe, 1 - 1 / np.sqrt(2))
    P = dt >= dp                                       # eliminate dt here, dp elsewhere
    a = np.where(P, 1.0, -dt / np.where(P, 1.0, dp))
    b = np.where(P, dp / np.where(P, dt, 1.0), -1.0)
    M = (KI @ sp.diags(a) + BI @ sp.diags(b / s)).tocsc()
    rhs = -f1 - BI @ np.where(P, f2 / np.where(P, dt, 1.0), 0.0) / s \
        + KI @ np.where(P, 0.0, f2 / np.where(P, 1.0, dp))
    try:
        y = spla.splu(M).solve(rhs)
    except RuntimeError as err:
        raise ReynoldsNotConverged(f"singular FBNS Schur complement: {err}", history) from err
    d_p = np.where(P, y, (-f2 - dt * y) / np.where(P, 1.0, dp))
    d_theta = np.where(P, (-f2 - dp * y) / np.where(P, dt, 1.0), y) / s
    return d_p, d_theta
