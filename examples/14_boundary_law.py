"""
A boundary-shear law fitted at two loads, predicted at a third
==============================================================

Below the Stribeck knee the asperities carry the load and their shear sets C_f. Eq 32's
constant C_f,b cannot tell two loads apart there. The shear law of ``[boundary]``,
``tau_0 a_r + alpha (p_con + p a_r)`` on the real contact area, can: the real area and the
asperity load grow at different rates with the load
(:mod:`fem_twin.macro.laws.boundary_laws`, docs/model.md "Boundary friction").

    python examples/14_boundary_law.py [OUT] [--quick]

**The "measured" curves here are synthetic**: the twin on the bundled pin 1 with the flow
factors of patch pair 1, run with a known law (tau_0 = 30 MPa, alpha = 0.08) at 150 and
300 N, with 1 % seeded noise. Then, as a tribologist with curves at two loads would:

1. fit tau_0 and alpha to both curves (:func:`fem_twin.stribeck.fit.fit_curves`, from the
   constant-law twin's real contact area and asperity load: nothing is solved again);
2. predict the curve at 225 N with its 95 % band
   (:func:`fem_twin.stribeck.prediction.predict`);
3. compare a constant C_f,b fitted at 150 N alone, carried to 300 N.

Prints the fitted values against the truth, where the true curves lie against the law's
band (the band is the fitted parameters', not the measurements' noise) and the constant
law's miss at 300 N; ends in ``OUT/boundary_law.png``. About 5 s on 2 cores
(``--quick``: 12 simulated speeds instead of 20).
From the shell: ``fem-twin fit CASE m150.csv m300.csv --params
shear_strength,pressure_coefficient --predict-load 225`` with ``load_N`` columns.
"""

import argparse
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin.io.files import read_topography
from fem_twin.macro import BOUNDARY_FRICTION, BoundaryLaw, Lubricant, MacroSettings
from fem_twin.micro import homogenise
from fem_twin.stribeck import SweepRequest, stribeck_sweep
from fem_twin.stribeck.curve import MeasuredCurve
from fem_twin.stribeck.fit import FitModel, fit_curves
from fem_twin.stribeck.prediction import predict
from fem_twin.topography import pin_face, resample_cell
from fem_twin.topography.prepare import MacroOptions, prepare_disk, prepare_patch, prepare_pin

SAMPLE = Path(sys.argv[0]).resolve().parents[1] / "meshes" / "sample"
TRUTH = BoundaryLaw(law="shear", shear_strength=30e6, pressure_coefficient=0.08)
LOADS, PREDICTED = (150.0, 300.0), 225.0


def sample_pin():
    """Pin 1 on disk 1 at 32^2 nodes, and the flow factors of patch pair 1 at 32^2 px."""
    opts = MacroOptions(resolution=(32, 32))
    pin = prepare_pin(read_topography(SAMPLE / "pin_1.npz"), opts)
    disk = prepare_disk(read_topography(SAMPLE / "disk_1.npz"), opts)
    low = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_1_pin.npz")), (32, 32))
    up = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_1_disk.npz"),
                                     upper=True), (32, 32))
    factors = homogenise(low, up, np.geomspace(2e-8, 1e-6, 14), steps=4)
    return disk.heights - pin.heights, pin.spacing, pin_face(pin, opts.holder_height), factors


def main(out="out/boundary_law", quick=False):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    gap, dx, face, factors = sample_pin()
    sweep = lambda load, speeds, law=BoundaryLaw(): stribeck_sweep(SweepRequest(  # noqa: E731
        gap, dx, factors, speeds, load=load, face=face, lubricant=Lubricant(0.066),
        settings=MacroSettings(boundary=law)))
    simulated = np.geomspace(2.0, 0.004, 12 if quick else 20)
    speeds, rng = np.geomspace(1.0, 0.01, 9), np.random.default_rng(3)
    twin = {load: sweep(load, simulated) for load in (*LOADS, PREDICTED)}
    truth = {load: sweep(load, speeds, TRUTH).friction_coefficient
             for load in (*LOADS, PREDICTED)}
    measured = {load: MeasuredCurve(speeds, cf * (1 + 0.01 * rng.standard_normal(cf.size)))
                for load, cf in truth.items()}
    both = FitModel(tuple(twin[load] for load in LOADS), BOUNDARY_FRICTION, LOADS[0], None,
                    loads=LOADS)
    law = fit_curves(both, [measured[load] for load in LOADS],
                     ["shear_strength", "pressure_coefficient"], start_temperatures=None)
    for name in ("shear_strength", "pressure_coefficient"):
        v = law[name]
        print(f"{name}: {v['value']:.4g} (95 %: {v['low']:.4g} to {v['high']:.4g}), "
              f"truth {getattr(TRUTH, name):.4g}")
    constant = fit_curves(FitModel((twin[150.0],), BOUNDARY_FRICTION, 150.0, None),
                          [measured[150.0]], ["boundary_friction"], start_temperatures=None)
    fig, ax = plt.subplots(figsize=(6.6, 4.4))
    for k, load in enumerate((*LOADS, PREDICTED)):
        colour = f"C{k}"
        model = FitModel((twin[load],), BOUNDARY_FRICTION, load, None)
        band = predict(model, law, speeds, None, curve=0)
        ax.fill_between(speeds, band["cf_low"], band["cf_high"], color=colour, alpha=0.2)
        ax.plot(speeds, band["cf"], "-", color=colour, label=f"shear law, {load:g} N"
                + (" (predicted)" if load == PREDICTED else " (fitted)"))
        ax.plot(speeds, measured[load].friction_coefficient, "o", color=colour, ms=4,
                mfc="none", label=f"'measured', {load:g} N")
        if load == 300.0:
            carried = predict(model, constant, speeds, None, curve=0)["cf"]
            ax.plot(speeds, carried, "--", color=colour, label="constant C_f,b from 150 N")
            miss = np.abs(carried - measured[load].friction_coefficient).max()
            print(f"constant C_f,b = {constant['boundary_friction']['value']:.4f} from 150 N "
                  f"misses 300 N by up to {100 * miss / BOUNDARY_FRICTION:.2f} % C_f,b")
        inside = np.sum((band["cf_low"] <= truth[load]) & (truth[load] <= band["cf_high"]))
        worst = np.abs(band["cf"] - truth[load]).max() / BOUNDARY_FRICTION
        print(f"{load:g} N: the true curve inside the law's 95 % band at {inside} of "
              f"{speeds.size} speeds, at most {100 * worst:.2f} % C_f,b from it (the "
              "simulated curve read between its speeds)")
    ax.set(xscale="log", yscale="log", xlabel="sliding speed U [m/s]", ylabel="C_f")
    ax.legend(fontsize="x-small")
    fig.tight_layout()
    path = out / "boundary_law.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default="out/boundary_law")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    main(args.out, args.quick)
