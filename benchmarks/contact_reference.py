"""Textbook Polonsky-Keer (1999), plain numpy: the same-run baseline of the contact benchmark.

Elastic, periodic, load-controlled; kernel and FFTs recomputed with numpy.fft on every call,
cold start from uniform pressure.  Kept deliberately simple.
"""

import numpy as np


def polonsky_keer(shape, spacing, e_reduced, mean_pressure, tol=1e-10, max_iter=5000):
    ny, nx = shape.shape
    q1 = 2 * np.pi * np.fft.rfftfreq(nx, spacing)
    q2 = 2 * np.pi * np.fft.fftfreq(ny, spacing)
    q = np.hypot(q1[None, :], q2[:, None])
    q[0, 0] = np.inf
    k_hat = 4.0 / (e_reduced * q)

    def conv(a):
        return np.fft.irfft2(np.fft.rfft2(a) * k_hat, s=a.shape)

    total = mean_pressure * shape.size
    p = np.full(shape.shape, mean_pressure)
    t = np.zeros_like(p)
    g_old, delta = 1.0, 0.0
    for it in range(1, max_iter + 1):
        g = conv(p) + shape
        c = p > 0
        g -= g[c].mean()
        gg = np.sum(g[c] ** 2)
        t = np.where(c, g + delta * gg / g_old * t, 0)
        g_old = gg
        r = conv(t)
        r -= r[c].mean()
        tau = np.sum(g[c] * t[c]) / np.sum(r[c] * t[c])
        p_old = p.copy()
        p = np.maximum(p - tau * t, 0)
        ol = (p == 0) & (g < 0)
        delta = 0.0 if ol.any() else 1.0
        p[ol] -= tau * g[ol]
        p *= total / p.sum()
        if np.abs(p - p_old).sum() / total < tol:
            return p, it
    raise RuntimeError("reference PK did not converge")
