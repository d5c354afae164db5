"""
Topography pipeline: the virtual macro pins
===========================================

Reconstruct the virtual macroscopic pins of the sample twin and plot their centre lines
(like the paper's Figure 3), using the Python API step by step.

    python examples/01_topography_pipeline.py [OUT.png] [--quick]

``--quick`` resamples to 64 x 64 instead of 256 x 256 (the gallery's smoke test).
"""

import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import fem_twin
from fem_twin import topography as tp
from fem_twin.topography.prepare import pin_face_guess

SAMPLE = Path(sys.argv[0]).resolve().parents[1] / "meshes" / "sample"
args = [a for a in sys.argv[1:] if a != "--quick"]
n = 64 if "--quick" in sys.argv else 256
out = Path(args[0] if args else "pin_centre_lines.png")

fig, ax = plt.subplots(figsize=(7, 4))
for k in (1, 2, 3):
    raw = fem_twin.read_topography(SAMPLE / f"pin_{k}.npz")
    topo = tp.fill_defects(raw)                                  # Laplace fill
    topo = tp.level(topo, pin_face_guess(topo))                  # mean plane of the face
    topo = tp.clip_heights(topo, -20e-6, 20e-6)                  # +-20 um
    topo = tp.gaussian_filter(topo, fwhm_px=9)                   # 9 px FWHM
    topo = tp.resample(topo, (n, n))                             # 256 x 256
    face = topo.heights > -20e-6
    topo = tp.centre_on(topo, tp.pin_centre(topo, face))         # origin at the pin centre
    topo = tp.level(topo, tp.radial_mask(topo, 3e-3) & face)     # mean plane within 3 mm
    pin = tp.mount_pin(topo)                                     # holder at -1 mm
    row = pin.heights[pin.shape[0] // 2]
    ax.plot(pin.x1 * 1e3, np.where(row > -1e-3, row * 1e6, np.nan), label=f"pin {k}")
    print(f"pin {k}: {pin!r}")
ax.set_xlabel("x1 [mm]")
ax.set_ylabel("x3,low [um]")
ax.legend()
fig.tight_layout()
fig.savefig(out, dpi=120)
print(f"wrote {out}")
