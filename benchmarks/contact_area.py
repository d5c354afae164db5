"""Group ``contact-area``: the real (dry) contact area of the bundled patch pairs against the
cell grid, the part of ``real_contact_area_m2`` that the shear law's tau_0 multiplies.

    python benchmarks/run.py contact-area        # about 2 minutes on 2 cores

Each of the six bundled pairs as the case prepares them (256 px, the disk flipped over the
pin), resampled periodically to 64, 96, 128 and 256 px, in periodic dry contact (Table 4's
E' and hardness) at the mean cell pressures 1, 10, 100 and 300 MPa: the contact fraction
a_c, the mean real pressure p_r = p / a_c and, from 64, 128 and 256 px, the limit and the
order the differences show (:func:`fem_twin.studies.verification.to_zero`; none where they
do not shrink).  The timed baseline is one 256 px contact solve.  The last line: the
range of the change from 128 to 256 px and of the observed orders at 100 and 300 MPa
(at 1 and 10 MPa a cell has a handful of spots, and the count jumps by pixels); checked:
at 100 and 300 MPa every pair's differences shrink with the grid (an order is observed).
"""

from __future__ import annotations

import time

from common import SAMPLE, Check

from fem_twin import read_topography
from fem_twin.contact import solve
from fem_twin.contact.levelling import TABLE4
from fem_twin.studies.verification import to_zero
from fem_twin.topography import resample_cell
from fem_twin.topography.prepare import prepare_patch

DEFAULT = False
GRIDS = (64, 96, 128, 256)
PRESSURES = (1e6, 10e6, 100e6, 300e6)
PAIRS = (1, 2, 3, 4, 5, 6)


def pair(k: int):
    """Bundled patch pair ``k`` as the case prepares it (256 px, +x1 sliding)."""
    low = prepare_patch(read_topography(f"{SAMPLE}/patch_{k}_pin.npz"), (256, 256), (0, 0),
                        sliding_direction="+x1")
    up = prepare_patch(read_topography(f"{SAMPLE}/patch_{k}_disk.npz"), (256, 256), (0, 0),
                       upper=True, sliding_direction="+x1")
    return low, up


def contact_fraction(low, up, n: int, pressure: float) -> float:
    """The dry contact fraction [-] of the pair on ``n`` px at the mean ``pressure`` [Pa]."""
    lo, hi = resample_cell(low, (n, n)), resample_cell(up, (n, n))
    area = lo.shape[0] * lo.spacing[1] * lo.shape[1] * lo.spacing[0]
    return solve(hi.heights - lo.heights, lo.spacing, TABLE4["e_reduced"],
                 load=pressure * area, hardness=TABLE4["hardness"],
                 periodic=True).contact_fraction


def run(pairs=PAIRS):
    low, up = pair(1)
    t0 = time.perf_counter()
    contact_fraction(low, up, 256, 100e6)
    base = time.perf_counter() - t0
    rows, changes, orders = [], [], []
    for k in pairs:
        low, up = pair(k)
        for p in PRESSURES:
            a = {n: contact_fraction(low, up, n, p) for n in GRIDS}
            limit, order = to_zero([1 / 64, 1 / 128, 1 / 256], [a[64], a[128], a[256]])
            if p >= 100e6:                   # enough spots that the count is not a handful
                changes.append(a[256] / a[128] - 1)
                orders += [] if order is None else [order]
            rows.append((f"  pair {k}, {p / 1e6:g} MPa: a_c % at " + ", ".join(
                f"{a[n]:.3%}" for n in GRIDS), 0.0,
                f"p_r {p / a[256] / 1e9:.2f} GPa at 256 px; " + (
                    "no order" if order is None else f"order {order:.2f}, limit {limit:.3%}")))
    line = (f"contact area: from 128 to 256 px the dry area at 100-300 MPa changes by "
            f"{min(changes):+.1%} to {max(changes):+.1%}, observed orders "
            f"{min(orders):.2f}-{max(orders):.2f}")
    return base, [("baseline: one 256 px periodic contact at 100 MPa", base, "")] + rows, line, \
        Check(len(orders) == len(changes), f"an order observed at {len(orders)} of "
                                           f"{len(changes)} pairs and pressures from 100 MPa")
