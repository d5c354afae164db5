"""
The mixed regime against a deterministic solution
=================================================

The twin against a solution that does not homogenise: a crowned square pad carrying a
roughness cell tiled ``n`` times per side (the bundled patch pair 1, the disk smooth), solved
with the roughness resolved on the film's grid, the asperity contact and the film together
(:func:`fem_twin.macro.reference.deterministic.solve_deterministic`), and by the twin with the flow
factors of that cell (:mod:`fem_twin.studies.verification`).

    python examples/13_deterministic_mixed.py [OUT] [--quick]

The pad grows with ``n`` at 1 MPa and its speed falls as ``1/n``, so every ``eps = 1/n``
poses the same problem: the load share is the same, the film's friction coefficient falls
as ``1/n``.  Left: C_f against the speed of the pad of 2 cells, deterministic (markers) and
twin (lines) at each eps.  Right: the share of the load on asperities; the twin's is one
curve, the deterministic ones approach it as the cells get smaller against the crown.
docs/accuracy.md ("The mixed regime against a deterministic solution") has the table.
Ends in ``OUT/deterministic_mixed.png``; about 30 s on 2 cores with ``--quick`` (16 px
cells, eps down to 1/8), 2 min without (32 px).
"""

import argparse
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin.studies import verification as V

SAMPLE = Path(sys.argv[0]).resolve().parents[1] / "meshes" / "sample"


def main(out="out/deterministic_mixed", quick=False):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    pad = V.sample_pad(SAMPLE, 16 if quick else 32)
    factors = V.pad_factors(pad, np.geomspace(3e-8, 3e-6, 60))
    speeds = np.geomspace(0.1, 5.0, 5 if quick else 8)
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for k, tiles in enumerate((2, 4, 8)):
        pairs = V.compared(V.deterministic_sweep(pad, tiles, speeds),
                           V.twin_sweep(pad, tiles, speeds, factors), tiles)
        colour = f"C{k}"
        left.plot(speeds, [p.cf for p in pairs], "-", color=colour, label=f"twin, eps 1/{tiles}")
        left.plot(speeds, [p.cf_det for p in pairs], "o", color=colour, mfc="none",
                  label=f"deterministic, eps 1/{tiles}")
        right.plot(speeds, [p.share_det for p in pairs], "o", color=colour, mfc="none",
                   label=f"deterministic, eps 1/{tiles}")
        worst = max(abs(p.cf_gap(pad.settings.boundary_friction)) for p in pairs)
        print(f"eps 1/{tiles}: worst |C_f - C_f,det| {100 * worst:.2f} % C_f,b, worst |share -"
              f" share,det| {max(abs(p.share - p.share_det) for p in pairs):.3f}")
    right.plot(speeds, [p.share for p in pairs], "k-", label="twin (every eps)")
    for ax in (left, right):
        ax.set(xscale="log", xlabel="speed of the pad of 2 cells [m/s] (n cells: x 2/n)")
    left.set(yscale="log", ylabel="C_f", title="(a) friction coefficient")
    right.set(ylabel="load share on asperities", title="(b) load share")
    left.legend(fontsize="x-small")
    right.legend(fontsize="x-small")
    path = out / "deterministic_mixed.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default="out/deterministic_mixed")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    main(args.out, args.quick)
