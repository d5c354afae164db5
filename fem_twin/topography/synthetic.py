"""Synthetic surfaces: self-affine random roughness by Fourier filtering."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .core import Topography


def self_affine(shape, spacing, hurst: float, rms: float, *, rolloff_wavelength=None,
                short_cutoff=None, rng=None) -> Topography:
    """Gaussian, periodic, self-affine random surface with RMS height ``rms`` [m].

    The power spectrum is ``C(q) ~ q^(-2 (1 + hurst))`` between the roll-off wavenumber
    ``2 pi / rolloff_wavelength`` (flat below; default: the longest wavelength of the grid)
    and ``2 pi / short_cutoff`` (zero above; default: two pixels).  Random phases from
    ``rng`` (a ``numpy.random.Generator`` or a seed).  The result has zero mean and exactly
    the requested ``rms`` (Sq).
    """
    if not 0 < hurst <= 1:
        raise InputError(f"hurst must be in (0, 1], got {hurst}")
    if not rms > 0:
        raise InputError(f"rms must be positive [m], got {rms}")
    rng = np.random.default_rng(rng)
    ny, nx = shape
    dx1, dx2 = np.broadcast_to(np.asarray(spacing, float), (2,))
    q1 = 2 * np.pi * np.fft.rfftfreq(nx, dx1)
    q2 = 2 * np.pi * np.fft.fftfreq(ny, dx2)
    q = np.hypot(q1[None, :], q2[:, None])
    q_r = 2 * np.pi / (rolloff_wavelength or max(nx * dx1, ny * dx2))
    q_s = 2 * np.pi / (short_cutoff or 2 * max(dx1, dx2))
    amplitude = np.maximum(q, q_r) ** (-(1 + hurst))
    amplitude[(q > q_s) | (q == 0)] = 0.0
    noise = rng.standard_normal((ny, nx))
    z = np.fft.irfft2(np.fft.rfft2(noise) * amplitude, s=(ny, nx))
    z -= z.mean()
    z *= rms / np.sqrt(np.mean(z ** 2))
    return Topography(z, (dx1, dx2), meta={"synthetic": "self_affine", "hurst": hurst})
