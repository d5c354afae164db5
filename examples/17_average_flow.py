"""
The statistical model beside the twin
=====================================

What a lubrication engineer would run instead of fem_twin: Patir and Cheng's average flow
and shear factors with Greenwood and Tripp's asperity contact (:mod:`fem_twin.peers`),
set by the cell's rms roughness, Peklenik number and spectral moments. Here both read the
same roughness cell (bundled sample pair 1 at 32 px on the pin at rest), and both run on
the crowned pad of :mod:`fem_twin.studies.verification`, which the deterministic solver
resolves at eps = 1/2 (docs/peers.md).

    python examples/17_average_flow.py [OUT] [--quick]

Left: the pressure flow factor A11 and the Couette factor b1 of the twin's cells and of
the statistical model against h0, and the contact pressure on a log scale. Right: C_f
against speed from the deterministic pad, the twin and the statistical model. Prints the
worst C_f gap of each to the deterministic solution in % of C_f,b and ends in
``OUT/average_flow.png``. About 25 s on 2 cores (``--quick``: 4 speeds, 20 h0, 15 s).
"""

import argparse
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin.studies import verification as V

SAMPLE = Path(sys.argv[0]).resolve().parent.parent / "meshes" / "sample"
FULL = dict(speeds=np.geomspace(0.1, 5.0, 8), h0=np.geomspace(3e-8, 3e-6, 60))
QUICK = dict(speeds=np.geomspace(0.1, 5.0, 4), h0=np.geomspace(3e-8, 3e-6, 20))


def main(out="out/average_flow", quick=False):
    size = QUICK if quick else FULL
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    pad = V.sample_pad(SAMPLE, 32)
    cfb = pad.settings.boundary_friction
    factors = {"twin (cells)": V.pad_factors(pad, size["h0"]),
               "average flow": V.pad_average_flow(pad)}
    det = V.deterministic_sweep(pad, 2, size["speeds"])
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    contact = left.twinx()
    h0 = size["h0"]
    right.plot(size["speeds"], [d.friction_coefficient for d in det], "ko-",
               label="deterministic")
    for (name, ff), colour in zip(factors.items(), ("C0", "C1")):
        loc = ff.at(h0)
        left.plot(h0 * 1e6, loc.A[:, 0, 0], "-", color=colour, label=f"A11, {name}")
        left.plot(h0 * 1e6, loc.b[:, 0], "--", color=colour, label=f"b1, {name}")
        contact.semilogy(h0 * 1e6, np.maximum(loc.p_con, 1.0), ":", color=colour)
        pairs = V.compared(det, V.twin_sweep(pad, 2, size["speeds"], ff), 2)
        right.plot(size["speeds"], [p.cf for p in pairs], "s--", color=colour, label=name)
        worst = max(abs(p.cf_gap(cfb)) for p in pairs)
        share = max(abs(p.share - p.share_det) for p in pairs)
        print(f"eps 1/2, {name}: worst |C_f - C_f,det| {100 * worst:.2f} % C_f,b, "
              f"|share - share,det| {share:.3f}")
    left.set(xscale="log", xlabel="h0 [um]", ylabel="A11 (solid), b1 (dashed)")
    contact.set_ylabel("p_con [Pa] (dotted)")
    left.legend(fontsize="x-small", loc="center right")
    right.set(xscale="log", xlabel="U [m/s]", ylabel="C_f", title="crowned pad, eps = 1/2")
    right.legend(fontsize="small")
    fig.tight_layout()
    path = out / "average_flow.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default="out/average_flow")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    main(args.out, args.quick)
