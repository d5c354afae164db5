"""
Traction curve of a measured ball
=================================

An MTM-style traction curve: C_f against the slide-to-roll ratio at one entrainment speed.
The ball's macro gap is a measured cap, and the roughness is a real instrument file's.

    python examples/09_measured_ball_traction.py [OUT] [--quick]

- **The ball cap is synthetic**, since no measured ball is among the shared instrument files:
  a 3/4" ball's top over 1 x 1 mm at 5 um pixels, with 80 nm of astigmatic form error and
  its apex 40 um off the map's centre. It is written as a topography file and read back
  like a measured one.
- **The roughness is real**: two non-overlapping 128 x 128 px crops of ``x3p-2.x3p`` (a
  MountainsMap x3p export, in ``../shared/topographies/`` beside the repository; the reader
  needs ``pip install .[instruments]``), one for the ball, one for the disk.

The script fits the sphere to the cap (radius, apex, form error; the case's
``[geometry] ball``), writes a ball-on-disk case, and runs ``fem-twin traction`` from pure
rolling to SRR 1 for one oil at two entrainment speeds:

- u_m = 0.5 m/s, where the film carries 99 % of the load: the traction rises from zero and
  saturates (Eyring), as an MTM's does;
- u_m = 0.2 m/s, where the asperities carry a fifth of it: the boundary shear sets the
  level and the film's friction (the force on the ball, positive) adds to it with SRR.
  Eq 31's wall shear (``[macro] friction = "paper"``), whose Couette factor
  ``1 - 3 d1`` is negative for this roughness there, made it fall with SRR
  (docs/rolling_sliding.md).

It ends in ``OUT/measured_ball_traction.png``.  About a minute on 2 cores; ``--quick``:
32 px cells and a 33^2 ball grid.
"""

import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin import Topography, read_topography, write_topography
from fem_twin.case import load_case
from fem_twin.stages.pipeline import traction
from fem_twin.topography import extract_patch, fill_defects
from fem_twin.topography.sphere import fit_sphere

HERE = Path(sys.argv[0]).resolve().parent
SHARED = HERE.parents[1] / "shared" / "topographies"
RADIUS = 9.525e-3                                   # 3/4 inch [m]


def synthetic_cap(path: Path) -> Path:
    """The ball's top over 1 x 1 mm, 201 x 201 px: sphere, astigmatism, a shifted apex."""
    x = np.linspace(-0.5e-3, 0.5e-3, 201)
    X, Y = np.meshgrid(x, x)
    r2 = (X - 40e-6) ** 2 + (Y + 25e-6) ** 2
    form = 80e-9 * (X ** 2 - Y ** 2) / 0.5e-3 ** 2
    cap = Topography(np.sqrt(RADIUS ** 2 - r2) - RADIUS + form, (x[1] - x[0],) * 2,
                     origin=(x[0], x[0]), meta={"sample": "synthetic ball cap"})
    return write_topography(path, cap)


def crops(folder: Path, n: int):
    """Ball and disk roughness: two n x n px crops of the real x3p file."""
    raw = fill_defects(read_topography(SHARED / "x3p-2.x3p"))
    return [write_topography(folder / f"x3p-2_{part}.npz", extract_patch(raw, (n, n), start))
            for part, start in (("ball", (0, 0)), ("disk", (300, 300)))]


def write_case(out: Path, quick: bool) -> Path:
    n = 32 if quick else 128
    cap = synthetic_cap(out / "ball_cap.npz")
    ball, disk = crops(out / "patches", n)
    text = f"""name = "measured_ball_traction"
[geometry]
ball = "{cap}"
patches = [["{ball}", "{disk}"]]
patch_shape = [{n}, {n}]
[tribometer]
kind = "ball-on-disk"
load = 20.0
slide_to_roll = 0.5
boundary_friction = 0.12
[lubricant]
viscosities = [0.066]
temperatures = [24.0]
eyring_stress = 5e6
[micro]
resolution = [{n}, {n}]
h0_min = 2e-8
h0_max = 1e-6
h0_count = {8 if quick else 16}
steps = {4 if quick else 16}
[thermal]
model = "none"     # one oil temperature: the isothermal twin, as fem-twin traction runs
[macro]
coupling = "auto"
grid = {33 if quick else 73}
[sweep]
speed_max = 0.5
speed_min = 0.01
[run]
workers = {1 if quick else 0}
"""
    path = out / "ball.toml"
    path.write_text(text)
    return path


def main(out="out/measured_ball", quick=False):
    if not SHARED.is_dir():
        sys.exit(f"{SHARED} not found: this example reads the shared instrument files")
    out = Path(out)
    (out / "patches").mkdir(parents=True, exist_ok=True)
    case = load_case(write_case(out, quick))
    fit = fit_sphere(read_topography(case.geometry.ball))
    print(f"ball cap: R = {fit.radius * 1e3:.4f} mm (made with {RADIUS * 1e3:.4f}), apex at "
          f"({fit.apex[0] * 1e6:.1f}, {fit.apex[1] * 1e6:.1f}) um (made at 40, -25), form "
          f"error rms {fit.form_error_rms * 1e9:.1f} nm")
    ratios = [0.0, 0.05, 0.2, 0.5, 1.0] if quick else [0.0, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5,
                                                       0.7, 1.0]
    tables = {}
    for u_m in (0.5, 0.2):
        traction(case, out / "run", u_m, ratios, progress=not quick)
        tables[u_m] = table = np.genfromtxt(out / "run" / "traction.csv", delimiter=",",
                                            names=True)
        for row in table:
            print(f"u_m {u_m} m/s, SRR {row['slide_to_roll']:4.2f}: C_f = "
                  f"{row['friction_coefficient']:.4f} +- {row['cf_err']:.1g}, "
                  f"{row['contact_load_fraction']:.0%} of the load on the asperities")
    report(fit, tables, out / "measured_ball_traction.png")


def report(fit, tables, path):
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4), constrained_layout=True)
    f = fit.form_error
    im = a.imshow(f.heights * 1e9, extent=[f.x1[0] * 1e3, f.x1[-1] * 1e3, f.x2[0] * 1e3,
                                           f.x2[-1] * 1e3], origin="lower", cmap="RdBu_r")
    a.plot(fit.apex[0] * 1e3, fit.apex[1] * 1e3, "k+", ms=10)
    fig.colorbar(im, ax=a, label="form error [nm]")
    a.set(xlabel="$x_1$ [mm]", ylabel="$x_2$ [mm]",
          title=f"ball cap minus its sphere, R = {fit.radius * 1e3:.3f} mm")
    for u_m, table in tables.items():
        b.errorbar(100 * table["slide_to_roll"], table["friction_coefficient"],
                   yerr=table["cf_err"], marker="o", ms=4, capsize=2,
                   label=f"$u_m$ = {u_m:g} m/s, {table['contact_load_fraction'].max():.0%} "
                         "of the load on the asperities")
    b.set(xlabel="slide-to-roll ratio SRR [%]", ylabel="traction coefficient $C_f$ [-]",
          title="traction, $\\mu_0$ = 0.066 Pa s")
    b.grid(True, alpha=0.3)
    b.legend(fontsize="small")
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    args = [x for x in sys.argv[1:] if x != "--quick"]
    main(*args[:1], quick="--quick" in sys.argv)
