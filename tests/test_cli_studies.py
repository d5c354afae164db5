"""The calibration studies (`fem-twin calibrate`) and the FE/FVM cross-check (`compare`)."""


import csv
import json

import numpy as np
import pytest
from sample_cases import small_case

from fem_twin.case import load_case
from fem_twin.cli import main
from fem_twin.io.layout import RunLayout


@pytest.mark.integration
def test_compare_fe_against_fvm(tmp_path):
    """fem-twin compare: both methods on one case; the differences are reported and small
    (the convergence of the difference under refinement is tested in test_micro and
    test_macro)."""
    case = small_case(tmp_path)
    out = tmp_path / "cmp"
    assert main(["compare", str(case), "-o", str(out), "--no-progress"]) == 0
    summary = json.loads((out / "compare.json").read_text())
    assert 0 < summary["max_flow_factor_diff"]["A"] < 1         # 16^2 cells: coarse
    assert summary["max_abs_cf_dev"] < 0.02                       # the 2 % bar
    # both against the converged reference (FE at 32^2, 8 steps, three h0): the reference
    # is closer to FE than to FVM only by discretisation, so both are reported, finite
    ref = summary["against_reference"]
    assert summary["reference"]["grid"] == [32, 32] and summary["reference"]["steps"] == 8
    assert set(ref) == {"fe", "fvm"} and all(0 < ref[m]["A11"] < 1 for m in ref)
    rows = list(csv.DictReader(open(out / "compare_stribeck.csv")))
    assert len(rows) == 5 and (out / "compare.png").stat().st_size > 0


@pytest.mark.integration
def test_calibration_studies(tmp_path):
    """Flat disk against measured disks, and single patches against the average (paper 3.2):
    the reference has zero deviation, the variants differ from it and stay bounded."""
    case = small_case(tmp_path)
    for study in ("disk", "patches"):
        out = tmp_path / study
        assert main(["calibrate", str(case), "--study", study, "-o", str(out),
                     "--no-progress"]) == 0
        summary = json.loads((out / "calibration.json").read_text())
        ref = summary["variants"].pop(summary["reference"])
        assert ref["max_abs_cf_dev"] == 0
        devs = [v["max_abs_cf_dev"] for v in summary["variants"].values()]
        assert all(0 < d < 1 for d in devs), devs
        assert (out / "cf_dev.png").stat().st_size > 0
    assert len(summary["variants"]) == 2                       # two patches in the small case


@pytest.mark.integration
def test_resolution_study_follows_the_papers_protocol(tmp_path, monkeypatch):
    """calibrate --study resolution (paper 3.2, Figure 10): by default 128, 256, 500, 999
    and 1997 px, the reference the measured maps' own 500 px, the two finer grids at the
    paper's five speeds only, the others at the case's speeds and those.  Run small (maps
    taken as 32 px, grids 24, 32, 48): the reference deviates by zero, the finer grid is
    compared at its five speeds, every variant has its points in stribeck.csv."""
    from fem_twin.studies import calibration
    case = load_case(small_case(tmp_path))
    cases, ref = calibration.variants(case, "resolution")
    assert list(cases) == ["128 px", "256 px", "500 px", "999 px", "1997 px"]
    assert ref == "500 px"
    fine = np.array(calibration.FINE_SPEEDS)
    for label, (variant, patch, speeds) in cases.items():
        n = int(label.split()[0])
        assert variant.preprocessing.resolution == (n, n) and patch is None
        assert np.array_equal(speeds, fine) == (n > 500)
        assert n > 500 or set(fine) | set(case.sweep.speeds) == set(speeds)

    class Maps:
        shape = (32, 32)
    monkeypatch.setattr(calibration, "read_topography", lambda path: Maps)
    out = tmp_path / "res"
    assert main(["calibrate", str(small_case(tmp_path)), "--study", "resolution",
                 "--values", "24", "32", "48", "-o", str(out), "--no-progress"]) == 0
    summary = json.loads((out / "calibration.json").read_text())
    assert summary["reference"] == "32 px"
    assert summary["variants"]["32 px"]["max_abs_cf_dev"] == 0
    assert all(0 < summary["variants"][k]["max_abs_cf_dev"] < 1 for k in ("24 px", "48 px"))
    rows = list(csv.DictReader(open(out / "stribeck.csv")))
    assert len(rows) == 10 + 10 + 5
    assert sorted(float(r["speed_m_s"]) for r in rows[20:]) == sorted(fine)


@pytest.mark.integration
def test_a_studys_pins_are_prepared_together_as_one_at_a_time(tmp_path):
    """prepare_pins (a study's variants: each step's jobs over all variants, finest first)
    writes the same pins, disks and levelled pins, byte for byte, as reconstruct_geometry
    and level_pins variant by variant."""
    from dataclasses import replace

    from fem_twin.stages.geometry import level_pins, prepare_pins, reconstruct_geometry
    case = load_case(small_case(tmp_path))
    runs = [replace(case, preprocessing=replace(case.preprocessing, resolution=(n, n)))
            for n in (24, 40)]
    together = [RunLayout(tmp_path / f"together_{i}") for i in range(2)]
    prepare_pins(list(zip(runs, together)), progress=False)
    for i, variant in enumerate(runs):
        alone = RunLayout(tmp_path / f"alone_{i}")
        reconstruct_geometry(variant, alone, False)
        level_pins(variant, alone, False)
        files = [f.relative_to(alone.root) for f in alone.root.rglob("pin_*.npz")]
        files += [f.relative_to(alone.root) for f in alone.root.rglob("disk_*.npz")]
        assert len(files) == 3 * len(case.geometry.pins) + 1
        for f in files:
            assert (together[i].root / f).read_bytes() == (alone.root / f).read_bytes(), f
