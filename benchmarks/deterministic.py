"""The ``deterministic`` group: the twin against a deterministic solution in the mixed regime.

The crowned pad of :mod:`fem_twin.studies.verification` (sample patch pair 1, 256 px cut, resampled
to 32 px; 1 MPa mean pressure, 1 um crown, the bundled case's oil at 24 C, E' and hardness
of Table 4) with 2, 4, 8 and 16 cells a side, 8 speeds from full film to 90 % of the load on
asperities.  Per point: the load share, the separation, the film friction and C_f of both,
and the differences extrapolated to eps -> 0.  Then what carries the differences, on the
pad of 8 cells: the film pressure's deformation of the asperities switched off in the
deterministic solver; the film cut-off at 5 and 20 nm, an isoviscous oil and a shear law
with tau_0 = 50 MPa (the homogenised tau_0 a_c against tau_0 on the resolved spots), on
both sides; on the pad of 4 cells, cells of 64 px on both sides.  The times are
per point; the baseline is the twin's on the finest pad.  The summary line gives the worst
gaps on the finest pad; checked: the worst C_f gap falls with eps (scale separation).
The knee at eps = 1/32 is the group ``deterministic-fine``.
"""

from __future__ import annotations

import os
import time
from dataclasses import replace

import numpy as np
from common import Check

from fem_twin.macro import BoundaryLaw, Lubricant
from fem_twin.studies import verification as V

DEFAULT = False
HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLE = os.path.join(HERE, "..", "meshes", "sample")
#: the speeds at two cells a side [m/s] (the finer pads' scale as 2 / tiles)
SPEEDS = np.geomspace(0.1, 5.0, 8)
#: the separations of the twin's flow factors [m]
H0 = np.geomspace(3e-8, 3e-6, 60)
PIXELS = 32
#: a shear law with tau_0 > 0 on both sides: tau_0 on the twin's dry contact fraction
#: against tau_0 on the resolved spots (Garvey et al.'s order of magnitude)
SHEAR = BoundaryLaw(law="shear", shear_strength=50e6, pressure_coefficient=0.1)


def _row(p: V.Pair, cfb: float, seconds: float):
    note = (f"U {p.speed:.3g} m/s: share {p.share_det:.3f} / {p.share:.3f}, h_d "
            f"{p.separation_det * 1e9:.1f} / {p.separation * 1e9:.1f} nm, film "
            f"{p.film_det * 1e3:.4g} / {p.film * 1e3:.4g} mN, C_f {p.cf_det:.4f} / "
            f"{p.cf:.4f} ({100 * p.cf_gap(cfb):+.2f} % C_f,b)")
    return (f"eps 1/{p.tiles}, deterministic / twin", seconds, note)


def _gap_rows(label, pad, tiles, cfb, base=None):
    """A row of the worst twin - deterministic gap on the pad of ``tiles`` (the twin's
    factors from the pad's own cell), and how far the deterministic C_f moved from
    ``base`` (deterministic points of the reference pad)."""
    det = V.deterministic_sweep(pad, tiles, SPEEDS)
    pairs = V.compared(det, V.twin_sweep(pad, tiles, SPEEDS, V.pad_factors(pad, H0)), tiles)
    note = (f"worst |C_f - C_f,det| {100 * max(abs(p.cf_gap(cfb)) for p in pairs):.2f} % "
            f"C_f,b, |share - share,det| {max(abs(p.share - p.share_det) for p in pairs):.3f}")
    if base is not None:
        moved = max(abs(d.friction_coefficient - b.friction_coefficient)
                    for d, b in zip(det, base))
        note += f"; C_f,det moves by {100 * moved / cfb:.2f} % C_f,b"
    return (f"eps 1/{tiles}: {label}", 0.0, note)


def _diagnostics(pad, tiles, cfb, base):
    """What moves the points on the pad of ``tiles`` (``base``: its deterministic sweep):
    the film's deformation off in the deterministic solver, the cut-off at 5 and 20 nm, an
    isoviscous oil and the shear law :data:`SHEAR` on both sides, and, on the pad of 4
    cells, cells of twice the pixels (both sides)."""
    still = V.deterministic_sweep(pad, tiles, SPEEDS,
                                  V.with_settings(pad, film_deforms=False).settings)
    moved = max(abs(a.friction_coefficient - b.friction_coefficient) for a, b in zip(base, still))
    shares = max(abs(a.load_share - b.load_share) for a, b in zip(base, still))
    rows = [(f"eps 1/{tiles}: film pressure does not deform", 0.0,
             f"C_f,det moves by at most {100 * moved / cfb:.3f} % C_f,b, share {shares:.4f}")]
    rows += [_gap_rows(f"film cut-off {cut * 1e9:.0f} nm", V.with_settings(
        pad, boundary_film=cut), tiles, cfb, base) for cut in (5e-9, 20e-9)]
    oil = Lubricant(pad.lubricant.viscosity, roelands_alpha=0.0, dh_c2=1.0)
    rows.append(_gap_rows("isoviscous oil", replace(pad, lubricant=oil), tiles, cfb, base))
    rows.append(_gap_rows("shear law, tau_0 on the spots", V.with_settings(pad, boundary=SHEAR),
                          tiles, cfb))
    rows.append(_gap_rows(f"cells of {2 * PIXELS} px", V.sample_pad(SAMPLE, 2 * PIXELS),
                          4, cfb))
    return rows


def run(tiles=V.TILES):
    """The comparison table (module docstring), its summary line and the check."""
    pad = V.sample_pad(SAMPLE, PIXELS)
    cfb = pad.settings.boundary_friction
    factors = V.pad_factors(pad, H0)
    rows, table, dets = [], [], {}
    for n in tiles:
        t0 = time.perf_counter()
        det = dets[n] = V.deterministic_sweep(pad, n, SPEEDS)
        t1 = time.perf_counter()
        twin = V.twin_sweep(pad, n, SPEEDS, factors)
        t_twin = time.perf_counter() - t1
        table.append(V.compared(det, twin, n))
        rows += [_row(p, cfb, (t1 - t0) / len(SPEEDS)) for p in table[-1]]
    eps = [1 / n for n in tiles]
    for k, speed in enumerate(SPEEDS):
        share, order = V.to_zero(eps, [t[k].share - t[k].share_det for t in table])
        cf, _ = V.to_zero(eps, [t[k].cf_gap(cfb) for t in table])
        note = (f"share - share,det {share:+.4f} ({V.order_text(order)}), C_f - C_f,det "
                f"{100 * cf:+.2f} % C_f,b")
        rows.append((f"eps -> 0 (speed {speed:.3g} m/s at eps 1/2)", 0.0, note))
    rows += _diagnostics(pad, 8, cfb, dets.get(8) or V.deterministic_sweep(pad, 8, SPEEDS))
    worst = [max(abs(p.cf_gap(cfb)) for p in pairs) for pairs in table]
    falls = all(b < a for a, b in zip(worst, worst[1:]))
    gaps = ", ".join(f"{100 * w:.2f}" for w in worst)
    return t_twin / len(SPEEDS), rows, V.summary(table[-1], cfb), Check(
        falls, f"the worst |C_f - C_f,det| falls with eps: {gaps} % C_f,b at eps "
               + ", ".join(f"1/{n}" for n in tiles))
