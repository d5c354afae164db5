"""
The contact's temperature
=========================

The film at the temperature of its own frictional heat (``[thermal] model = "flash"``).

    python examples/12_contact_temperature.py [OUT] [--quick]

Left: the flash temperature model against its closed forms.  The mean temperature rise of
a uniformly heated square (side 2l) on a steel half-space sliding at speed U, in units of
``q l / k``, against the Peclet number ``Pe = U l / (2 kappa)``: at rest it is 0.9464, and
a band (a strip across the motion) tends to Jaeger's ``(4/3) / sqrt(pi Pe)``.  Right: the
bundled sample pin's Stribeck curve at 24 C, isothermal and thermal (the rig's resistance
R_b = 1 K/W), with the film temperature each point settles at.  docs/thermal.md has the
model.  Ends in ``OUT/contact_temperature.png``; about 20 s on 2 cores (``--quick``: a
coarser grid, fewer speeds).
"""

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin import read_topography
from fem_twin.macro import Lubricant, MacroSettings
from fem_twin.macro.laws.thermal import ContactThermal, ThermalSettings, surface_temperature
from fem_twin.macro.laws.viscosity import WaltherLaw
from fem_twin.micro import homogenise
from fem_twin.stribeck import SweepRequest, stribeck_sweep
from fem_twin.topography import pin_face, resample_cell
from fem_twin.topography.prepare import MacroOptions, prepare_disk, prepare_patch, prepare_pin

HERE = Path(sys.argv[0]).resolve().parent
SAMPLE = HERE.parent / "meshes" / "sample"
STEEL = ThermalSettings()
L = 4e-3                                              # half-width of the source [m]


def flash_curves(peclet, n):
    """Mean rise over q l / k of a square and of a band (a strip 24 half-widths long, its
    middle third) at each Peclet number."""
    dx = 2 * L / n
    square, band = [], []
    for pe in peclet:
        u = pe * 2 * STEEL.diffusivity / L
        square.append(surface_temperature(np.ones((n, n)), (dx, dx), u, 1.0,
                                          STEEL.diffusivity).mean() / L)
        strip = surface_temperature(np.ones((24 * n, n)), (dx, dx), u, 1.0, STEEL.diffusivity)
        band.append(strip[8 * n:16 * n].mean() / L)
    return np.array(square), np.array(band)


def sample_sweep(n, speeds):
    """The Stribeck sweep of sample pin 1 on an n^2 grid at 24 C, isothermal."""
    opts = MacroOptions(resolution=(n, n))
    pin = prepare_pin(read_topography(SAMPLE / "pin_1.npz"), opts)
    disk = prepare_disk(read_topography(SAMPLE / "disk_1.npz"), opts)
    low = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_1_pin.npz")), (32, 32))
    up = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_1_disk.npz"), upper=True),
                       (32, 32))
    factors = homogenise(low, up, np.geomspace(2e-8, 1e-6, 14), steps=4)
    return SweepRequest(disk.heights - pin.heights, pin.spacing, factors, speeds, load=150.0,
                        lubricant=Lubricant(0.066), face=pin_face(pin, opts.holder_height),
                        settings=MacroSettings(track_radius=30e-3))


def main(out="out/contact_temperature", quick=False):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.4), constrained_layout=True)
    peclet = np.geomspace(0.1, 300, 7 if quick else 13)
    square, band = flash_curves(peclet, 24 if quick else 48)
    left.loglog(peclet, square, "o-", label="square source (the twin)")
    left.loglog(peclet, band, "s-", label="band source (the twin)")
    left.axhline(0.9464, color="0.5", ls=":", label="square at rest, 0.9464")
    left.loglog(peclet, 4 / (3 * np.sqrt(np.pi * peclet)), "k--",
                label="Jaeger, high Pe: (4/3) / sqrt(pi Pe)")
    left.set(xlabel="Peclet number U l / (2 kappa)", ylabel="mean rise [q l / k]",
             title="moving heat source on a steel half-space")
    left.legend(fontsize="small")
    speeds = np.geomspace(2.0, 0.005, 8 if quick else 16)
    law = WaltherLaw.through((24.0, 50.0), (0.066, 0.024), 875.0)
    sweep = sample_sweep(48 if quick else 96, speeds)
    iso = stribeck_sweep(sweep)
    hot = stribeck_sweep(replace(sweep, thermal=ContactThermal(STEEL, law)))
    right.loglog(speeds, iso.friction_coefficient, "o-", label="isothermal (the paper)")
    right.loglog(speeds, hot.friction_coefficient, "s--", label="thermal, R_b = 1 K/W")
    right.set(xlabel="sliding speed U [m/s]", ylabel="C_f", title="sample pin at 24 C")
    right.legend(loc="center left", fontsize="small")
    twin = right.twinx()
    twin.semilogx(speeds, hot.contact_temperature, "r:", label="film temperature")
    twin.set_ylabel("film temperature [C]", color="r")
    path = out / "contact_temperature.png"
    fig.savefig(path, dpi=110)
    print(f"film {hot.contact_temperature.max():.2f} C at {speeds[0]:g} m/s, C_f "
          f"{hot.friction_coefficient[0]:.5f} against {iso.friction_coefficient[0]:.5f}; "
          f"wrote {path}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default="out/contact_temperature")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    main(args.out, args.quick)
