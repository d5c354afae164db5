"""Group ``deterministic-fine``: the knee of the ``deterministic`` group's pad at finer eps.

Its three knee speeds at eps = 1/8, 1/16 and 1/32 (1025^2 nodes, about 20 min a point on
2 cores; about 70 min in all): the gaps and the order each speed observes (``to_zero``),
so that the eps -> 0 value is measured, not assumed.  Times per point, the baseline the
first.  The summary line gives the worst gaps at 1/32; checked: they are within the
comparison's target, 1 % C_f,b and 0.02 in load share (docs/accuracy.md).
"""

from __future__ import annotations

import time

from common import Check
from deterministic import H0, PIXELS, SAMPLE, SPEEDS, _row

from fem_twin.studies import verification as V

DEFAULT = False
#: the comparison's target: the worst C_f gap [C_f,b] and load-share gap
TARGET = (0.01, 0.02)


#: the knee at two cells a side: 70 % to 22 % of the load on asperities at eps = 1/16
KNEE = SPEEDS[2:5]


def run(tiles=(8, 16, 32)):
    """The rows of the module docstring, the summary line at the finest eps and the check."""
    pad = V.sample_pad(SAMPLE, PIXELS)
    cfb = pad.settings.boundary_friction
    factors = V.pad_factors(pad, H0)
    rows, table = [], []
    for n in tiles:
        t0 = time.perf_counter()
        det = V.deterministic_sweep(pad, n, KNEE)
        t1 = time.perf_counter()
        table.append(V.compared(det, V.twin_sweep(pad, n, KNEE, factors), n))
        rows += [_row(p, cfb, (t1 - t0) / len(KNEE)) for p in table[-1]]
    eps = [1 / n for n in tiles]
    for k, speed in enumerate(KNEE):
        cf, order = V.to_zero(eps, [t[k].cf_gap(cfb) for t in table])
        share, share_order = V.to_zero(eps, [t[k].share - t[k].share_det for t in table])
        rows.append((f"eps -> 0 (speed {speed:.3g} m/s at eps 1/2)", 0.0,
                     f"C_f - C_f,det {100 * cf:+.2f} % C_f,b ({V.order_text(order)}), share "
                     f"- share,det {share:+.4f} ({V.order_text(share_order)})"))
    cf = max(abs(p.cf_gap(cfb)) for p in table[-1])
    share = max(abs(p.share - p.share_det) for p in table[-1])
    holds = cf <= TARGET[0] and share <= TARGET[1]
    return rows[0][1], rows, V.summary(table[-1], cfb, "mixed regime at eps 1/32"), Check(
        holds, f"at eps 1/{tiles[-1]} the knee within the target {100 * TARGET[0]:g} % C_f,b and "
               f"{TARGET[1]:g} in share (worst {100 * cf:.2f} %, {share:.4f})")
