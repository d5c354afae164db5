"""The ``unsteady`` group: the twin against the time-resolved deterministic pad with both
bodies rough and the disk's roughness sliding over the pin's (docs/accuracy.md, "Both
bodies rough, the disk's roughness moving").

The crowned pad of :mod:`fem_twin.studies.verification` (1 MPa, 1 um crown, E' and hardness
of Table 4, C_f,b of eq 32, the 10 nm cut-off and 1 nm floor on both sides) with both
cells of a patch pair at 32 px: the bundled pairs 1 and 3, and two square crops of
``../shared/topographies/x3p-2.x3p`` (skipped without it).  Both sides take the
isoviscous, incompressible oil at 0.066 Pa s and asperities that feel their contact
pressure alone (the cells' own assumptions), so the comparison is the homogenisation's:
scale separation, the unsteady cells, sealed pockets, micro-cavitation.  Pair 1 at
eps = 1/2, 1/4, 1/8 over 8 speeds from full film to 91 % of the load on asperities and at
1/16 at the knee's middle speed, extrapolated to eps -> 0 with the order it shows; pair 3
and the crops at 1/4 and 1/8 at that speed.  Then, on pair 1 at 1/4 and the three knee
speeds, one assumption at a time: the film pressure deforming the asperities, the twin's
cells leaking, the cut-off and the floor on the deterministic side, and the steady cells
(the composite on the pin at rest).  The sweeps run on two processes; times are per point;
the baseline is the twin's point.  The summary line gives the worst gaps at the finest pads
and the order observed; checked: the unsteady cells' worst C_f gap on pair 1 at eps = 1/4
and the knee below the steady cells'.
"""

from __future__ import annotations

import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace

import numpy as np
from common import Check

from fem_twin.macro import Lubricant
from fem_twin.studies import verification as V

DEFAULT = False
HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLE = os.path.join(HERE, "..", "meshes", "sample")
X3P = os.path.join(HERE, "..", "..", "shared", "topographies", "x3p-2.x3p")
#: the speeds at two cells a side [m/s] (the finer pads' scale as 2 / tiles)
SPEEDS = np.geomspace(0.1, 5.62, 8)
#: the knee: 73 % to 30 % of the load on asperities at eps = 1/2
KNEE = SPEEDS[2:5]
#: the knee's middle speed (55 %), where the finest pad and the other pairs run
MIDDLE = SPEEDS[3:4]
#: the separations of the twin's flow factors [m]
H0 = np.geomspace(3e-8, 3e-6, 60)
PIXELS = 32
#: both sides' oil: isoviscous and incompressible, as the cells' is
OIL = Lubricant(0.066, roelands_alpha=0.0, dh_c2=1.0)


def _reference(pad):
    """The pad with the cells' assumptions on the deterministic side too."""
    return V.with_settings(replace(pad, lubricant=OIL), film_deforms=False)


def pads() -> dict:
    """The pads of the comparison: bundled pairs 1 and 3, and the x3p crops if present."""
    out = {f"pair {k}": _reference(V.sample_pad(SAMPLE, PIXELS, pair=k, moving=True))
           for k in (1, 3)}
    if os.path.isfile(X3P):
        out["x3p-2 crops"] = _reference(_crop_pad())
    return out


def _crop_pad():
    """Two non-overlapping square crops of x3p-2.x3p (256 x 104 px, 33 um a side: its
    pixels are 2.45x taller than wide) as the pin's and the disk's cells."""
    from fem_twin.io.files import read_topography
    from fem_twin.topography.prepare import prepare_patch
    raw = read_topography(X3P)
    rows = int(round(256 * raw.spacing[0] / raw.spacing[1]))
    pin = prepare_patch(raw, (rows, 256), (0, 0))
    disk = prepare_patch(raw, (rows, 256), (300, 300), upper=True)
    return V.patch_pad(pin, disk, PIXELS, OIL, moving=True)


def _factors(task):
    """The twin's flow factors of ``(pad, cell settings)`` (a task for the pool)."""
    pad, cell = task
    return V.pad_factors(pad, H0, **cell)


def _sweep(task):
    """One sweep of the group (a picklable unit for the pool): ``(deterministic pad, twin
    pad, factors, tiles, speeds)`` -> ``(deterministic points, twin points, seconds per
    deterministic point, seconds per twin point)``."""
    det_pad, twin_pad, factors, tiles, speeds = task
    t0 = time.perf_counter()
    det = V.time_resolved_sweep(det_pad, tiles, speeds)
    t1 = time.perf_counter()
    twin = V.twin_sweep(twin_pad, tiles, speeds, factors)
    return det, twin, (t1 - t0) / len(speeds), (time.perf_counter() - t1) / len(speeds)


def _variant(name: str, pad, side: str):
    """``(deterministic pad, twin pad, cell)`` with one assumption changed, the twin's
    cell as ``(label, pad, cell settings)`` of its flow factors."""
    if side == "film deforms":
        return V.with_settings(pad, film_deforms=True), pad, (name, pad, {})
    if side == "leaking cells":
        return pad, pad, (f"{name}, leaking", pad, {"pockets": "leaking"})
    if side.startswith("cut-off") or side.startswith("floor"):
        key = "boundary_film" if side.startswith("cut-off") else "gap_floor"
        det = V.with_settings(pad, **{key: float(side.split()[-2]) * 1e-9})
        return det, pad, (name, pad, {})
    if side == "steady cells":
        steady = replace(pad, disk=None)
        return pad, steady, (f"{name}, steady", steady, {})
    return pad, pad, (name, pad, {})


#: what is changed one at a time on pair 1 at eps = 1/4 and the knee speeds
VARIANTS = ("film deforms", "leaking cells", "cut-off 5 nm",
            "cut-off 20 nm", "floor 0.5 nm", "floor 2 nm", "steady cells")


def _tasks(pads_: dict) -> list:
    """``[(row name, tiles, speeds, deterministic pad, twin pad, cell)]``: the sweeps."""
    runs = [("pair 1", n, SPEEDS, "") for n in (2, 4, 8)] + [("pair 1", 16, MIDDLE, "")]
    runs += [(name, n, MIDDLE, "") for name in pads_ if name != "pair 1" for n in (4, 8)]
    runs += [("pair 1", 4, KNEE, side) for side in VARIANTS]
    return [(f"{name}, {side}" if side else name, n, speeds,
             *_variant(name, pads_[name], side)) for name, n, speeds, side in runs]


def run():
    """The comparison table (module docstring), its summary line and the check."""
    tasks = _tasks(pads())
    cells = {label: (pad, cell) for *_, (label, pad, cell) in tasks}
    with ProcessPoolExecutor(2) as pool:
        factors = dict(zip(cells, pool.map(_factors, cells.values())))
        work = [(det, twin, factors[cell[0]], n, speeds)
                for _, n, speeds, det, twin, cell in tasks]
        order = sorted(range(len(work)), key=lambda i: -work[i][3] ** 2 * len(work[i][4]))
        futures = {i: pool.submit(_sweep, work[i]) for i in order}
        done = [futures[i].result() for i in range(len(work))]
    cfb = tasks[0][3].settings.boundary_friction
    rows, table = [], {}
    for (name, tiles, *_), (det, twin, seconds, _) in zip(tasks, done):
        table[name, tiles] = V.compared(det, twin, tiles)
        rows += [_row(name, p, cfb, seconds) for p in table[name, tiles]]
    rows += _limits(table, cfb)
    finest = [table["pair 1", 8][k] for k in range(len(SPEEDS))
              if not np.isclose(SPEEDS[k], MIDDLE).any()] + table["pair 1", 16]
    _, order = _extrapolated(table, cfb)
    unsteady, steady = (max(abs(p.cf_gap(cfb)) for p in pairs) for pairs in
                        (table["pair 1", 4][2:5], table["pair 1, steady cells", 4]))
    return done[1][3], rows, V.summary(finest, cfb, "both rough, unsteady", order), Check(
        unsteady < steady, f"pair 1 at eps 1/4, the knee: the unsteady cells' worst |C_f - "
                           f"C_f,det| {100 * unsteady:.2f} % C_f,b below the steady cells' "
                           f"{100 * steady:.2f} %")


def _row(name, p: V.Pair, cfb: float, seconds: float):
    note = (f"U {p.speed:.3g} m/s: share {p.share_det:.3f} / {p.share:.3f}, h_d "
            f"{p.separation_det * 1e9:.1f} / {p.separation * 1e9:.1f} nm, film "
            f"{p.film_det * 1e3:.4g} / {p.film * 1e3:.4g} mN, C_f {p.cf_det:.4f} / "
            f"{p.cf:.4f} ({100 * p.cf_gap(cfb):+.2f} % C_f,b)")
    return (f"{name}, eps 1/{p.tiles}: deterministic / twin", seconds, note)


def _extrapolated(table, cfb: float):
    """The C_f and share gaps of pair 1 at the knee's middle speed at eps -> 0 and the
    orders the finest three pads show (None: none observed)."""
    eps = [1 / n for n in (4, 8, 16)]
    at = [table["pair 1", n][3 if n < 16 else 0] for n in (4, 8, 16)]
    cf, cf_order = V.to_zero(eps, [p.cf_gap(cfb) for p in at])
    share, share_order = V.to_zero(eps, [p.share - p.share_det for p in at])
    return (cf, share, share_order), cf_order


def _limits(table, cfb: float) -> list:
    """A row per knee speed at eps -> 0, then a row per assumption against the reference
    (pair 1, eps = 1/4, the knee speeds)."""
    (cf, share, share_order), cf_order = _extrapolated(table, cfb)
    rows = [(f"pair 1, eps -> 0 (U {MIDDLE[0]:.3g} m/s at eps 1/2)", 0.0,
             f"C_f - C_f,det {100 * cf:+.2f} % C_f,b ({V.order_text(cf_order)}), "
             f"share - share,det {share:+.4f} ({V.order_text(share_order)})")]
    base = table["pair 1", 4][2:5]
    for side in VARIANTS:
        pairs = table[f"pair 1, {side}", 4]
        det = max(abs(p.cf_det - b.cf_det) for p, b in zip(pairs, base)) / cfb
        gap = max(abs(p.cf_gap(cfb)) for p in pairs)
        share = max(abs(p.share - p.share_det) for p in pairs)
        rows.append((f"pair 1, eps 1/4: {side}", 0.0,
                     f"C_f,det moves by {100 * det:.2f} % C_f,b; worst |C_f - C_f,det| "
                     f"{100 * gap:.2f} % C_f,b, |share - share,det| {share:.3f}"))
    return rows
