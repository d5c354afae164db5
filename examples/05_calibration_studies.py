"""
The paper's calibration studies
===============================

Calibration studies of paper section 3.2 on the bundled sample case (Figures 9-13).

    python examples/05_calibration_studies.py [OUT] [--quick]

Runs, at 0.066 Pa s, the filter-size study (unfiltered and 3-11 px against 11 px), the
measured-versus-flat disk study, single pins against the set average and single patches
against the patch average.  Each writes OUT/<study>/calibration.json (max ``|C_f,dev|`` per
variant), stribeck.csv, stribeck_speed.png and cf_dev.png; the example ends in
OUT/calibration_summary.png (max ``|C_f,dev|`` of every variant, eq 35).  About 10 minutes on 2
cores; interrupted studies resume.  ``--quick`` (smoke test): the pins and patches studies
of a reduced case (48^2 macro, 16^2 micro x 4 steps, 2 patches, 4 speeds).  The same from
the shell: ``fem-twin calibrate examples/pin_on_disk.toml --study filter -o OUT/filter``.
"""

import json
import sys
from dataclasses import replace
from pathlib import Path

import matplotlib.pyplot as plt

from fem_twin.case import load_case
from fem_twin.studies.calibration import calibrate

HERE = Path(sys.argv[0]).resolve().parent


def reduced(case):
    """The bundled case at smoke-test size."""
    return replace(case, preprocessing=replace(case.preprocessing, resolution=(48, 48)),
                   micro=replace(case.micro, resolution=(16, 16), h0_count=6, steps=4),
                   geometry=replace(case.geometry, patches=case.geometry.patches[:2]),
                   sweep=replace(case.sweep, count=4, speed_min=0.01, refine=0),
                   run=replace(case.run, workers=1, patch_band=False))


def main(out="calibration", quick=False):
    case = load_case(HERE / "pin_on_disk.toml")
    case = reduced(case) if quick else case
    results = {}
    for study in (("pins", "patches") if quick else ("filter", "disk", "pins", "patches")):
        summary = calibrate(case, study, Path(out) / study)
        results[study] = {k: v["max_abs_cf_dev"] for k, v in summary["variants"].items()}
        print(json.dumps({study: {k: round(v, 4) for k, v in results[study].items()}}))
    fig, axes = plt.subplots(1, len(results), figsize=(3.2 * len(results), 3.6),
                             constrained_layout=True, squeeze=False)
    for ax, (study, devs) in zip(axes[0], results.items()):
        ax.bar(range(len(devs)), [100 * v for v in devs.values()])
        ax.set_xticks(range(len(devs)), list(devs), rotation=60, ha="right", fontsize="small")
        ax.set_title(study)
        ax.set_ylabel("max $|C_{f,dev}|$ [%] (eq 35)")
    path = Path(out) / "calibration_summary.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--quick"]
    main(*args[:1], quick="--quick" in sys.argv)
