"""
Both bodies rough, the disk's roughness moving
==============================================

The configuration every run uses, against a solution resolved in time: the crowned pad of
:mod:`fem_twin.studies.verification` carries the pin's cell of the bundled patch pair 1
tiled ``n`` times a side, and the disk's cell slides over it one pixel a step
(:func:`fem_twin.macro.reference.time_resolved.solve_time_resolved`: the transient, mass-conserving
Reynolds equation with JFO, the asperity contact with the hardness cap, the separation
balanced on the load of each roughness period).  The twin takes the pair's unsteady cells
(eq 8 with its time term).  Both sides take the isoviscous oil and asperities that feel
their contact pressure alone, the cells' own assumptions, so the comparison is the
homogenisation's.

    python examples/16_moving_roughness.py [OUT] [--quick]

Left: C_f against the speed of the pad of 2 cells, time-resolved (markers) and twin
(lines) at each eps.  Right: the share of the load on asperities.  docs/accuracy.md
("Both bodies rough, the disk's roughness moving") has the table at 32 px and eps down to
1/16.  Ends in ``OUT/moving_roughness.png``; about a minute on 2 cores with ``--quick``
(16 px cells, 5 speeds), 20 min without (32 px, 8 speeds).
"""

import argparse
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin.macro import Lubricant
from fem_twin.studies import verification as V

SAMPLE = Path(sys.argv[0]).resolve().parents[1] / "meshes" / "sample"


def main(out="out/moving_roughness", quick=False):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    oil = Lubricant(0.066, roelands_alpha=0.0, dh_c2=1.0)
    pad = V.sample_pad(SAMPLE, 16 if quick else 32, moving=True, lubricant=oil)
    pad = V.with_settings(pad, film_deforms=False)
    factors = V.pad_factors(pad, np.geomspace(3e-8, 3e-6, 60))
    speeds = np.geomspace(0.1, 5.62, 5 if quick else 8)
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for k, tiles in enumerate((2, 4, 8)):
        pairs = V.compared(V.time_resolved_sweep(pad, tiles, speeds),
                           V.twin_sweep(pad, tiles, speeds, factors), tiles)
        colour = f"C{k}"
        left.plot(speeds, [p.cf for p in pairs], "-", color=colour, label=f"twin, eps 1/{tiles}")
        left.plot(speeds, [p.cf_det for p in pairs], "o", color=colour, mfc="none",
                  label=f"time-resolved, eps 1/{tiles}")
        right.plot(speeds, [p.share_det for p in pairs], "o", color=colour, mfc="none",
                   label=f"time-resolved, eps 1/{tiles}")
        worst = max(abs(p.cf_gap(pad.settings.boundary_friction)) for p in pairs)
        print(f"eps 1/{tiles}: worst |C_f - C_f,det| {100 * worst:.2f} % C_f,b, worst |share -"
              f" share,det| {max(abs(p.share - p.share_det) for p in pairs):.3f}")
    right.plot(speeds, [p.share for p in pairs], "k-", label="twin (every eps)")
    for ax in (left, right):
        ax.set(xscale="log", xlabel="speed of the pad of 2 cells [m/s] (n cells: x 2/n)")
    left.set(yscale="log", ylabel="C_f", title="(a) friction coefficient, both bodies rough")
    right.set(ylabel="load share on asperities", title="(b) load share")
    left.legend(fontsize="x-small")
    right.legend(fontsize="x-small")
    path = out / "moving_roughness.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default="out/moving_roughness")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    main(args.out, args.quick)
