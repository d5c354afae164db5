"""Study: b1 and d1 in heavy contact, over the time steps and the cell grid, in the pin's and
the mean-speed frame (issue 27 item 6).

    python benchmarks/micro_contact.py [PATCHES] [--quick]

Sample patches 1 and 2 of the bundled case, prepared as the pipeline prepares them (256 px,
the disk flipped over the pin) and resampled periodically to the cell grid.  At each patch
three separations where 40, 20 and 10 % of the pixels touch (found by periodic contact at
128^2), b1 and d1 of eqs 14 and 16:

- over the time steps N_t = 16, 32, 64, 128 on the 128^2 cell (128: every pixel
  translation), the exact squeeze term;
- over the cell grid 64^2, 128^2, 256^2 at 32 steps.

Prints one markdown table per patch and frame.  About 15 minutes on 2 cores (``--quick``:
patch 1, 64^2 and 16-32 steps).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from fem_twin import read_topography  # noqa: E402
from fem_twin.contact import solve  # noqa: E402
from fem_twin.contact.levelling import TABLE4  # noqa: E402
from fem_twin.micro import homogenise  # noqa: E402
from fem_twin.topography import resample_cell  # noqa: E402
from fem_twin.topography.prepare import prepare_patch  # noqa: E402

SAMPLE = Path(__file__).resolve().parents[1] / "meshes" / "sample"
TARGETS = (0.1, 0.2, 0.4)                   # contact fractions of the three separations


def patch_pair(k: int):
    """Sample patch pair ``k`` as the bundled case prepares it (256 px, +x1 sliding)."""
    low = prepare_patch(read_topography(SAMPLE / f"patch_{k}_pin.npz"), (256, 256), (0, 0),
                        sliding_direction="+x1")
    up = prepare_patch(read_topography(SAMPLE / f"patch_{k}_disk.npz"), (256, 256), (0, 0),
                       upper=True, sliding_direction="+x1")
    return low, up


def separations(low, up, targets=TARGETS) -> list[float]:
    """h0 [m] where the given fractions of the pixels touch at the first instant (128^2)."""
    low, up = resample_cell(low, (128, 128)), resample_cell(up, (128, 128))
    h0 = np.geomspace(2e-9, 3e-7, 40)
    fraction = [solve(up.heights - low.heights, low.spacing, TABLE4["e_reduced"],
                      separation=h, hardness=TABLE4["hardness"], periodic=True).contact_fraction
                for h in h0]
    order = np.argsort(fraction)
    return [float(np.exp(np.interp(t, np.array(fraction)[order], np.log(h0)[order])))
            for t in targets]


def factors(low, up, n, steps, h0, moving):
    low, up = resample_cell(low, (n, n)), resample_cell(up, (n, n))
    f = homogenise(low, up, h0, steps=steps, moving=moving, error_estimate=False, workers=2)
    return f.b[:, 0], f.d[:, 0], f.contact_fraction


def study(k: int, quick: bool) -> None:
    low, up = patch_pair(k)
    h0 = sorted(separations(low, up))                 # homogenise sorts them too
    steps = (16, 32) if quick else (16, 32, 64, 128)
    grids = (32, 64) if quick else (64, 128, 256)
    n_time = 64 if quick else 128
    for moving in ("upper", "both"):
        frame = "pin's frame" if moving == "upper" else "mean-speed frame"
        print(f"\n### patch {k}, {frame}: b1 / d1 at h0 = "
              + ", ".join(f"{h * 1e9:.1f} nm" for h in h0))
        print("| cell | steps | " + " | ".join(f"h0 {h * 1e9:.1f} nm" for h in h0) + " |")
        print("|---|---|" + "---|" * len(h0))
        rows = [(n_time, s) for s in steps] + [(n, 32) for n in grids if n != n_time]
        for n, s in rows:
            b, d, c = factors(low, up, n, s, h0, moving)
            cells = " | ".join(f"{bi:.4f} / {di:.4f} ({ci:.0%})" for bi, di, ci in zip(b, d, c))
            print(f"| {n}^2 | {s} | {cells} |", flush=True)


if __name__ == "__main__":
    quick = "--quick" in sys.argv
    args = [a for a in sys.argv[1:] if a != "--quick"]
    for k in ([int(a) for a in args] or ([1] if quick else [1, 2])):
        study(k, quick)
