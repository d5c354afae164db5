"""
Real measured roughness
=======================

A twin of real measured roughness: x3p and MountainsMap patches on the bundled macro pin.

    python examples/06_real_roughness.py [OUT] [--quick]

Reads two real instrument files from ``../shared/topographies/`` (beside the repository:
``x3p-2.x3p``, a MountainsMap x3p export, 650 x 650 px; ``mnt-2.mnt``, polished Si,
1280 x 960 px; the readers need ``pip install .[instruments]``), cuts two non-overlapping
N x N px patches of each without interpolation (one for the pin, one for the disk), and runs
the main job on the bundled case with these two patch pairs instead of the synthetic sample
patches: micro stage at the crops' own pixels, then a Stribeck sweep at mu_0 = 0.066 Pa s on
the bundled macro pins.  The same job with the first two synthetic sample patches (cut at
256 px and resampled to N) is the comparison.  Prints what the measured roughness changes
(Sq, flow factors, where the Stribeck curve turns, max ``|C_f,dev|`` of eq 35) and ends in
``OUT/real_roughness.png``.  N = 128 (about 3 minutes on 2 cores); ``--quick``: N = 32 and a
smoke-test sweep.
"""

import sys
from dataclasses import replace
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin import read_topography, write_topography
from fem_twin.case import load_case
from fem_twin.micro import FlowFactors
from fem_twin.stages.pipeline import run
from fem_twin.stribeck import friction_deviation, read_stribeck_csv
from fem_twin.topography import extract_patch, fill_defects

HERE = Path(sys.argv[0]).resolve().parent
SHARED = HERE.parents[1] / "shared" / "topographies"
FILES = {"x3p-2.x3p": ((0, 0), (300, 300)), "mnt-2.mnt": ((0, 0), (500, 700))}


def crops(folder: Path, n: int) -> list[tuple[Path, Path]]:
    """(pin, disk) patch files of N x N original pixels cut from each instrument file."""
    folder.mkdir(parents=True, exist_ok=True)
    pairs = []
    for name, starts in FILES.items():
        raw = fill_defects(read_topography(SHARED / name))
        files = []
        for part, start in zip(("pin", "disk"), starts):
            path = folder / f"{Path(name).stem}_{part}.npz"
            write_topography(path, extract_patch(raw, (n, n), start))
            files.append(path)
        pairs.append(tuple(files))
    return pairs


def variant(case, n, quick, patches=None):
    """The bundled case at this study's settings (real patches if given)."""
    geometry = case.geometry if patches is None else replace(
        case.geometry, patches=tuple(patches), patch_shape=(n, n))
    geometry = replace(geometry, patches=geometry.patches[:2])
    micro = replace(case.micro, resolution=(n, n), h0_max=2e-6,
                    **(dict(steps=4, h0_count=14) if quick else dict(h0_count=20)))
    sweep = replace(case.sweep, **(dict(count=5, speed_min=0.01, refine=0) if quick else {}))
    preprocessing = replace(case.preprocessing, resolution=(48, 48) if quick else (128, 128))
    lubricant = replace(case.lubricant, viscosities=(0.066,), temperatures=(24.0,))
    thermal = replace(case.thermal, model="none")   # one viscosity: no viscosity-temperature law
    return replace(case, name=case.name + ("_real" if patches else "_synthetic"),
                   geometry=geometry, micro=micro, sweep=sweep, lubricant=lubricant,
                   thermal=thermal, preprocessing=preprocessing,
                   run=replace(case.run, patch_band=False))


def turning_speed(curve, level):
    """Sliding speed where C_f first rises through ``level`` from the fast end [m/s]."""
    order = np.argsort(curve.speed)
    u, cf = curve.speed[order], curve.friction_coefficient[order]
    above = np.nonzero(cf >= level)[0]
    if above.size == 0 or above[-1] + 1 >= u.size:
        return float("nan")
    i = above[-1]
    return float(np.exp(np.interp(level, [cf[i + 1], cf[i]], np.log([u[i + 1], u[i]]))))


def main(out="out/real_roughness", quick=False):
    if not SHARED.is_dir():
        sys.exit(f"{SHARED} not found: this example reads the shared instrument files")
    out, n = Path(out), 32 if quick else 128
    case = load_case(HERE / "pin_on_disk.toml")
    results = {}
    for label, patches in (("real", crops(out / "patches", n)), ("synthetic", None)):
        run(variant(case, n, quick, patches), out / label, progress=not quick)
        results[label] = (read_stribeck_csv(out / label / "stribeck.csv")[0],
                          FlowFactors.load(out / label / "micro" / "flow_factors.npz"),
                          [read_topography(out / label / "geometry" / f"patch_{k}_{side}.npz")
                           for k in (1, 2) for side in ("low", "up")])
    report(results, case.tribometer.boundary_friction, out / "real_roughness.png")


def report(results, cfb, path):
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4), constrained_layout=True)
    for label, (curve, ff, pins) in results.items():
        sq = ", ".join(f"{a.rms_height() * 1e9:.0f}/{b.rms_height() * 1e9:.0f}"
                       for a, b in zip(pins[::2], pins[1::2]))
        turn = turning_speed(curve, cfb / 2)
        print(f"{label:>9}: Sq pin/disk of the two pairs {sq} nm; "
              f"A11 at 0.2 um {ff.at(0.2e-6).A[0, 0]:.3f}, "
              f"p_con at 0.1 um {ff.at(0.1e-6).p_con * 1e-6:.1f} MPa; C_f = C_f,b/2 at "
              f"U = {turn:.3g} m/s")
        a.semilogx(curve.speed, curve.friction_coefficient, "o-", ms=3,
                   label=f"{label} (Sq pin/disk {sq} nm)")
        b.plot(ff.h0 * 1e6, ff.A[:, 0, 0], ".-", label=f"{label} A11")
    real, synthetic = results["real"][0], results["synthetic"][0]
    dev = friction_deviation(real.friction_coefficient, synthetic.at_hersey(real.hersey), cfb)
    dev = np.where(np.isfinite(dev), dev, 0.0)      # refined speeds differ: same range only
    print(f"the measured roughness moves C_f by up to {np.abs(dev).max():.1%} of C_f,b "
          f"(eq 35) at U = {real.speed[np.argmax(np.abs(dev))]:.3g} m/s")
    a.set(xlabel="sliding speed $U$ [m/s]", ylabel="$C_f$ [-]",
          title="Stribeck curve, $\\mu_0$ = 0.066 Pa s")
    b.set(xlabel="$h_0$ [µm]", ylabel="$A_{11}$ [-]", title="pressure flow factor (eq 13)")
    for ax in (a, b):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    args = [x for x in sys.argv[1:] if x != "--quick"]
    main(*args[:1], quick="--quick" in sys.argv)
