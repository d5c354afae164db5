"""Group ``contact``: periodic rough contact (Hurst 0.8, Sq 150 nm, 85 um patch) at 256^2,
512^2 and 1024^2 against a textbook numpy Polonsky-Keer (``contact_reference.py``), cold,
warm-started and at a fixed separation with the hardness cap; then the micro stage's own use,
a warm patch sweep.  Times per CG iteration in units of one rfft2+irfft2 pair of the grid
(the baseline).  Checked: fem_twin's pressure equals the textbook one within 1e-6 of the
peak at every size."""

from __future__ import annotations

import numpy as np
from common import Check, best_of, sample_patch_pair
from contact_reference import polonsky_keer

from fem_twin import contact
from fem_twin.topography.synthetic import self_affine

DEFAULT = True
#: fem_twin's pressure against the textbook PK's, relative to the peak
AGREE = 1e-6


def run(sizes=(256, 512, 1024)):
    e_red = contact.reduced_modulus(210e9, 0.3, 210e9, 0.3)
    rows, base, worst = [], None, 0.0
    for n in sizes:
        dx = 85e-6 / n
        shape = -self_affine((n, n), dx, 0.8, 150e-9, rng=1).heights
        z = np.random.default_rng(0).random((n, n))
        t_fft, _ = best_of(lambda: np.fft.irfft2(np.fft.rfft2(z), s=z.shape), 5)
        load = 100e6 * 85e-6 ** 2
        t_ref, (p_ref, it_ref) = best_of(lambda: polonsky_keer(shape, dx, e_red, 100e6), 1)
        t_el, el = best_of(lambda: contact.solve(shape, dx, e_red, load=load, periodic=True), 1)
        near = contact.solve(shape, dx, e_red, load=0.9 * load, periodic=True)
        t_w, warm = best_of(lambda: contact.solve(shape, dx, e_red, load=load, periodic=True,
                                                  initial_pressure=near.pressure), 1)
        h0 = el.separation
        t_s, sep = best_of(lambda: contact.solve(shape, dx, e_red, separation=h0, periodic=True,
                                                 hardness=6.99e9), 1)
        t_sw, sepw = best_of(lambda: contact.solve(shape, dx, e_red, separation=h0, periodic=True,
                                                   hardness=6.99e9,
                                                   initial_pressure=el.pressure), 1)
        base = base or t_fft
        per = lambda t, it: f"{it} it, {t / it / t_fft:.2f} x (rfft2+irfft2) per it"  # noqa: E731
        worst = max(worst, float(np.abs(el.pressure - p_ref).max() / p_ref.max()))
        rows += [
            (f"{n}^2 baseline rfft2+irfft2", t_fft, ""),
            (f"{n}^2 textbook numpy PK, 100 MPa (ref)", t_ref, per(t_ref, it_ref)),
            (f"{n}^2 fem_twin PK, 100 MPa, cold", t_el, per(t_el, el.iterations)),
            (f"{n}^2 fem_twin PK, warm from 90 MPa", t_w, per(t_w, warm.iterations)),
            (f"{n}^2 fixed h0 + H, cold", t_s, per(t_s, sep.iterations)),
            (f"{n}^2 fixed h0 + H, warm", t_sw, per(t_sw, sepw.iterations)),
        ]
    rows.append(_warm_patch_sweep(e_red))
    sides = ", ".join(f"{n}^2" for n in sizes)
    return base, rows, Check(worst < AGREE, f"fem_twin's pressure within {AGREE:g} of the peak "
                                            f"of the textbook PK's at {sides} (worst "
                                            f"{worst:.1e})")


def _warm_patch_sweep(e_red):
    """The micro stage's contact use: sample patch 3 at 256^2, 8 sliding instants, h0 from
    0.4 to 0.1 um, each warm-started from the same instant at the previous h0 (hardness
    cap on); time per CG iteration in units of one rfft2+irfft2 pair at 256^2."""
    from fem_twin.micro.sliding import CellSettings, sliding_pass
    pin, disk = sample_patch_pair()
    shapes = sliding_pass(pin.heights, disk.heights, pin.spacing, CellSettings(steps=8)).shapes
    z = np.random.default_rng(0).random(pin.shape)
    t_fft, _ = best_of(lambda: np.fft.irfft2(np.fft.rfft2(z), s=z.shape), 5)

    def sweep():
        warm, its = [None] * len(shapes), 0
        for h0 in (0.4e-6, 0.3e-6, 0.2e-6, 0.14e-6, 0.1e-6):
            for k, s in enumerate(shapes):
                r = contact.solve(s, pin.spacing, e_red, separation=h0, hardness=6.99e9,
                                  periodic=True, initial_pressure=warm[k])
                warm[k], its = (r.pressure if r.load > 0 else None), its + r.iterations
        return its
    t, its = best_of(sweep, 1)
    return ("256^2 patch sweep, 8 instants x 5 h0, warm", t,
            f"{its} it, {t / its / t_fft:.2f} x (rfft2+irfft2) per it")
