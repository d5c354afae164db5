"""Calibration studies of paper section 3.2 on the bundled sample case (Figures 9-13).

    python examples/calibration_studies.py [OUT]

Runs, at 0.066 Pa s, the filter-size study (unfiltered and 3-11 px against 11 px), the
measured-versus-flat disk study, single pins against the set average and single patches
against the patch average.  Each writes OUT/<study>/calibration.json (max |C_f,dev| per
variant), stribeck.csv, stribeck_speed.png and cf_dev.png.  About 10 minutes on 2 cores;
interrupted studies resume.  The same from the shell:
``fem-twin calibrate examples/pin_on_disk.toml --study filter -o OUT/filter``.
"""

import json
import sys
from pathlib import Path

from fem_twin.calibration import calibrate
from fem_twin.case import load_case

HERE = Path(__file__).resolve().parent


def main(out="calibration"):
    case = load_case(HERE / "pin_on_disk.toml")
    for study in ("filter", "disk", "pins", "patches"):
        summary = calibrate(case, study, Path(out) / study)
        print(json.dumps({study: {k: round(v["max_abs_cf_dev"], 4)
                                  for k, v in summary["variants"].items()}}))


if __name__ == "__main__":
    main(*sys.argv[1:])
