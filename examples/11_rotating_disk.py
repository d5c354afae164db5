"""
The rotating disk
=================

The disk turns under the pin: across an 8 mm face at a 30 mm track radius its speed varies
by +-13 % and its direction by +-7.6 degrees.

    python examples/11_rotating_disk.py [OUT] [--quick]

Left: the bundled sample pin's face at a mixed-lubrication speed: the disk's velocity less
the uniform model's (arrows, ``fem_twin.macro.disk_velocity`` - e1: the turn about the
disk's axis below the face) over the change of the film pressure from the uniform model to
the rotating one: the outer half (top) runs faster and carries more.
Right: the Stribeck curve of both models and their difference in % of C_f,b, which peaks
where the film gives way to contact.  docs/model.md ("The rotating disk") has the model and
docs/accuracy.md the measurements on the bundled and paper cases.  Ends in
``OUT/rotating_disk.png``; about 20 s on 2 cores (``--quick``: a coarser grid, fewer speeds).
"""

import argparse
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin import read_topography
from fem_twin.macro import Lubricant, MacroSettings, disk_velocity, solve_mixed
from fem_twin.micro import homogenise
from fem_twin.topography import pin_face, resample_cell
from fem_twin.topography.prepare import MacroOptions, prepare_disk, prepare_patch, prepare_pin

HERE = Path(sys.argv[0]).resolve().parent
SAMPLE = HERE.parent / "meshes" / "sample"
TRACK, LOAD, CFB = 30e-3, 150.0, 0.1924500897


def geometry(n):
    """The sample pin 1 on its disk on an n^2 macro grid: gap [m], spacing [m], face."""
    opts = MacroOptions(resolution=(n, n))
    pin = prepare_pin(read_topography(SAMPLE / "pin_1.npz"), opts)
    disk = prepare_disk(read_topography(SAMPLE / "disk_1.npz"), opts)
    return disk.heights - pin.heights, pin.spacing, pin_face(pin, opts.holder_height)


def sweep(gap, dx, face, factors, speeds, radius):
    """The converged points over ``speeds`` (fast to slow, warm-started)."""
    points, previous = [], None
    for U in speeds:
        previous = solve_mixed(gap, dx, factors, load=LOAD, speed=U, face=face,
                               lubricant=Lubricant(0.066), initial=previous,
                               settings=MacroSettings(track_radius=radius))
        points.append(previous)
    return points


def main(out="out/rotating_disk", quick=False):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    low = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_1_pin.npz")), (32, 32))
    up = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_1_disk.npz"), upper=True),
                       (32, 32))
    factors = homogenise(low, up, np.geomspace(2e-8, 1e-6, 14), steps=4)
    gap, dx, face = geometry(48 if quick else 96)
    speeds = np.geomspace(1.0, 0.005, 8 if quick else 16)
    uniform = sweep(gap, dx, face, factors, speeds, None)
    rotating = sweep(gap, dx, face, factors, speeds, TRACK)
    cf = {k: np.array([p.friction_coefficient for p in v])
          for k, v in (("uniform", uniform), ("rotating", rotating))}
    k = int(np.argmax(np.abs(cf["rotating"] - cf["uniform"])))

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.4), constrained_layout=True)
    ny, nx = gap.shape
    x1, x2 = (np.arange(nx) - nx / 2) * dx[0] * 1e3, (np.arange(ny) - ny / 2) * dx[1] * 1e3
    change = np.where(face, rotating[k].pressure - uniform[k].pressure, np.nan) / 1e6
    lim = np.nanmax(np.abs(change))
    image = left.pcolormesh(x1, x2, change, cmap="RdBu_r", vmin=-lim, vmax=lim)
    fig.colorbar(image, ax=left, label="p rotating - p uniform [MPa]")
    v, s = disk_velocity(face, dx, TRACK), slice(None, None, max(nx // 12, 1))
    left.quiver(x1[s], x2[s], v[s, s, 0] - 1, v[s, s, 1], scale=1.5, width=0.004)
    left.set(xlabel="x1 [mm] (sliding)", ylabel="x2 [mm] (outward)", aspect="equal",
             title=f"U = {speeds[k]:.3g} m/s at the track radius {TRACK * 1e3:g} mm")
    right.semilogx(speeds, cf["uniform"], "o-", label="uniform sliding (the paper)")
    right.semilogx(speeds, cf["rotating"], "s--", label="rotating disk (default)")
    right.set(xlabel="sliding speed U at the track radius [m/s]", ylabel="C_f")
    twin = right.twinx()
    twin.semilogx(speeds, (cf["rotating"] - cf["uniform"]) / CFB * 100, "k:",
                  label="difference")
    twin.set_ylabel("rotating - uniform [% C_f,b]")
    right.legend(loc="center left")
    path = out / "rotating_disk.png"
    fig.savefig(path, dpi=110)
    print(f"largest difference {np.abs(cf['rotating'] - cf['uniform']).max() / CFB * 100:.3f} "
          f"% C_f,b at {speeds[k]:.3g} m/s; wrote {path}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default="out/rotating_disk")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    main(args.out, args.quick)
