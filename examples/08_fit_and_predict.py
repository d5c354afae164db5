"""
Fit to a measured curve, predict the next
=========================================

Fit the twin to a measured Stribeck curve at 24 C, then predict the curve at 50 C.

    python examples/08_fit_and_predict.py [OUT] [--quick]

**The "measured" curves here are synthetic**: the twin itself, run on the bundled case
with a boundary friction coefficient C_f,b = 0.15 (the case says 0.192, the paper's) and
the contact 3 K warmer than the oil (frictional heating: the oil's viscosity at 27 and
53 C from the Walther law through the case's two viscosities), sampled at 9 speeds,
with 3 % seeded noise and a +-5 % scatter band, as a tribometer's three repeated tests
would give.  No real measurement is involved, so the truth is known.

Then, as a tribologist with one measured curve would:

1. ``fem_twin.studies.fitting.fit_case`` fits C_f,b and the contact temperature to the 24 C curve
   alone (least squares on C_f,dev, eq 35; the micro and macro stages run once, the fit
   re-solves nothing);
2. the fitted parameters predict the curve at 50 C with its 95 % band
   (``OUT/twin/prediction_50C.csv``): the parameters' covariance, the fitted temperature
   offset carried to 50 C, the Hersey collapse's own error and the C_f error estimate.

Prints the fitted values against the truth and how many 50 C "measured" points fall
inside the predicted band; ends in ``OUT/fit_and_predict.png``.  About 4 minutes on 2
cores at the bundled size; ``--quick``: a reduced case (48^2 macro, 16^2 micro) in about
a minute.  From the shell: ``fem-twin fit CASE m24.csv -o OUT --predict 50``.
"""

import csv
import json
import sys
from dataclasses import replace
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin.case import load_case
from fem_twin.macro.laws.viscosity import WaltherLaw
from fem_twin.stages.pipeline import run
from fem_twin.stribeck.curve import read_stribeck_csv
from fem_twin.studies.fitting import fit_case

HERE = Path(sys.argv[0]).resolve().parent
TRUE_CFB, HEATING = 0.15, 3.0          # the synthetic truth: C_f,b and the contact's +3 K


def reduced(case):
    """The bundled case at smoke-test size."""
    return replace(case, preprocessing=replace(case.preprocessing, resolution=(48, 48)),
                   micro=replace(case.micro, resolution=(16, 16), h0_count=6, steps=4),
                   geometry=replace(case.geometry, patches=case.geometry.patches[:2]),
                   sweep=replace(case.sweep, count=6, speed_max=1.0, speed_min=0.01,
                                 refine=0),
                   run=replace(case.run, patch_band=False))


def synthetic_measurements(case, out: Path) -> list[Path]:
    """The twin at the true parameters, sampled with noise: one CSV per temperature."""
    lb = case.lubricant
    law = WaltherLaw.through(lb.temperatures, lb.viscosities, lb.density)
    truth = replace(case, tribometer=replace(case.tribometer, boundary_friction=TRUE_CFB),
                    lubricant=replace(lb, viscosities=tuple(
                        float(law.viscosity(t + HEATING)) for t in lb.temperatures)))
    run(truth, out / "twin", progress=False)     # the fit reuses its geometry and factors
    rng = np.random.default_rng(24)
    files = []
    for c, t in zip(read_stribeck_csv(out / "twin" / "stribeck.csv"), lb.temperatures):
        pick = np.unique(np.linspace(1, c.speed.size - 2, 9).round().astype(int))
        cf = c.friction_coefficient[pick] * (1 + 0.03 * rng.standard_normal(pick.size))
        path = out / f"measured_{t:g}C.csv"
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["speed", "friction_coefficient", "cf_min", "cf_max"])
            w.writerows(zip(c.speed[pick], cf, 0.95 * cf, 1.05 * cf))
        files.append(path)
    return files


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def main(out="fit_and_predict", quick=False):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    case = load_case(HERE / "pin_on_disk.toml")
    case = reduced(case) if quick else replace(case, run=replace(case.run, patch_band=False))
    m24, m50 = synthetic_measurements(case, out)
    result = fit_case(case, [m24], out / "twin", ["boundary_friction", "temperature"],
                      predict_at=[50.0], progress=False)
    for name, truth in (("boundary_friction", TRUE_CFB), ("temperature_1", 24 + HEATING)):
        r = result[name]
        print(f"{name}: {r['value']:.4g} (95 %: {r['low']:.4g} to {r['high']:.4g}); "
              f"truth {truth:g}")
    pred, meas, fitted = read(out / "twin" / "prediction_50C.csv"), read(m50), read(m24)
    order = np.argsort(pred["speed_m_s"])
    lo, hi = (np.interp(np.log(meas["speed"]), np.log(pred["speed_m_s"][order]),
                        pred[k][order]) for k in ("cf_low", "cf_high"))
    inside = int(np.sum((meas["friction_coefficient"] >= lo)
                        & (meas["friction_coefficient"] <= hi)))
    print(f"50 C: {inside} of {meas['speed'].size} synthetic measured points inside the "
          "predicted 95 % band")
    (out / "fit_and_predict.json").write_text(json.dumps(
        {"fit": {k: result[k] for k in result["fit"]["parameters"]},
         "inside_band_50C": [inside, int(meas["speed"].size)]}, indent=2))

    fig, ax = plt.subplots(figsize=(6.6, 4.4))
    row = result["residuals"][0]
    ax.plot(row["speed_m_s"], row["fitted_cf"], "-", color="C0", label="fitted at 24 C")
    for m, colour, label in ((fitted, "C0", "24 C"), (meas, "C3", "50 C")):
        ax.errorbar(m["speed"], m["friction_coefficient"], fmt="s", ms=4, mfc="none",
                    color=colour, capsize=2,
                    yerr=[m["friction_coefficient"] - m["cf_min"],
                          m["cf_max"] - m["friction_coefficient"]],
                    label=f"synthetic 'measured', {label}")
    s = pred["speed_m_s"][order]
    ax.plot(s, pred["friction_coefficient"][order], "--", color="C3", label="predicted, 50 C")
    ax.fill_between(s, pred["cf_low"][order], pred["cf_high"][order], color="C3", alpha=0.2,
                    lw=0, label="95 % prediction band")
    ax.set_xscale("log")
    ax.set_xlabel("sliding speed $U$ [m/s]")
    ax.set_ylabel("friction coefficient $C_f$ [-]")
    ax.set_title("synthetic data: fitted at 24 C, predicted at 50 C", fontsize="medium")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="x-small")
    fig.tight_layout()
    path = out / "fit_and_predict.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--quick"]
    main(*args[:1], quick="--quick" in sys.argv)
