"""Group ``topography``: the macro pin's reconstruction at 500^2 (sample pin 1) against one
rfft2+irfft2 of the same grid: defect filling, the Gaussian filter, refinement and the whole
``prepare_pin`` chain.  Checked: the filled map has no missing pixel left."""

from __future__ import annotations

import os

import numpy as np
from common import SAMPLE, Check, best_of

from fem_twin import read_topography
from fem_twin import topography as tp
from fem_twin.topography.prepare import prepare_pin

DEFAULT = True


def run():
    raw = read_topography(os.path.join(SAMPLE, "pin_1.npz"))
    z = np.nan_to_num(raw.heights)
    base, _ = best_of(lambda: np.fft.irfft2(np.fft.rfft2(z), s=z.shape), 5)
    rows = [("baseline: rfft2+irfft2 500^2", base, "")]
    t_fill, filled = best_of(lambda: tp.fill_defects(raw))
    holes = int((~raw.valid).sum())
    rows.append(("fill_defects (Laplace) 500^2", t_fill, f"{holes} holes"))
    t_filt, _ = best_of(lambda: tp.gaussian_filter(filled, 9))
    rows.append(("gaussian_filter 9 px 500^2", t_filt, ""))
    t_ref, _ = best_of(lambda: tp.refine(filled, 4))
    rows.append(("refine 500 -> 1997", t_ref, ""))
    t_pin, _ = best_of(lambda: prepare_pin(raw))
    rows.append(("prepare_pin (whole chain, 256^2 out)", t_pin, ""))
    left = int((~np.isfinite(filled.heights)).sum())
    return base, rows, Check(left == 0, f"fill_defects filled sample pin 1's {holes} missing "
                                        f"pixels ({left} non-finite heights left)")
