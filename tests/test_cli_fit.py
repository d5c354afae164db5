"""`fem-twin fit`, `validate` and `run --from-fit` on the bundled case at reduced size."""


import csv
import json
import re

import pytest
from sample_cases import small_case

from fem_twin.cli import main
from fem_twin.stribeck.curve import read_stribeck_csv


def measured_from_run(out, folder, speeds):
    """'Measured' CSVs made of a run's own curves at C_f,b = 0.15 (their force parts), at
    the ``speeds`` slice of each curve; their paths."""
    cfb = 1 / (3 * 3 ** 0.5)
    files = []
    for c in read_stribeck_csv(out / "stribeck.csv"):
        cf = (c.hydrodynamic_friction + 0.15 / cfb * c.boundary_force) / 150.0
        path = folder / f"m{c.viscosity:g}.csv"
        path.write_text("speed,friction_coefficient\n" + "".join(
            f"{float(u)!r},{float(f)!r}\n" for u, f in zip(c.speed[speeds], cf[speeds])))
        files.append(str(path))
    return files


@pytest.mark.integration
def test_fit_a_case_to_measured_curves(tmp_path, capsys):
    """Fem-twin fit CASE measured.csv -o OUT --params ... --predict T: the
    'measured' curves are the run's own at C_f,b = 0.15 (its two viscosities, 24 and 50 C in
    the case), so the fit returns C_f,b = 0.15 and the case's temperatures, writes fit.json,
    fit.png and a predicted curve with its band, and refuses an unknown parameter before
    any work."""
    case = small_case(tmp_path)
    out = tmp_path / "o"
    assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 0
    cfb = 1 / (3 * 3 ** 0.5)
    files = measured_from_run(out, tmp_path, slice(1, -1))
    assert main(["fit", str(case), *files, "-o", str(out), "--no-progress", "--predict", "37",
                 "--params", "boundary_friction,temperature,load_share"]) == 0
    fit = json.loads((out / "fit.json").read_text())
    assert fit["boundary_friction"]["value"] == pytest.approx(0.15, rel=2e-3)
    for k, t in ((1, 24.0), (2, 50.0)):
        assert abs(fit[f"temperature_{k}"]["value"] - t) < 0.5
    # the curves were made at load share 1, the upper bound of the fit (the case resumes;
    # only the first viscosity's sweeps at the other shares are new)
    assert fit["load_share"]["value"] == pytest.approx(1.0, abs=1e-3)
    assert (out / "fit.png").is_file() and "boundary_friction = 0.15" in capsys.readouterr().out
    pred = list(csv.DictReader(open(out / "prediction_37C.csv")))
    assert all(float(r["cf_low"]) < float(r["friction_coefficient"]) < float(r["cf_high"])
               for r in pred)
    assert main(["fit", str(case), files[0], "-o", str(tmp_path / "x"), "--params",
                 "load"]) == 2
    assert main(["fit", str(case), files[0], "-o", str(tmp_path / "x"), "--predict",
                 "323"]) == 2                                     # kelvin typed as C
    assert not (tmp_path / "x").exists()
    # the fitted twin run at 120 N: prediction.csv is the run's own curve with its band
    case120 = tmp_path / "case120.toml"
    case120.write_text(case.read_text().replace("load = 150.0 ", "load = 120.0 "))
    assert main(["run", str(case120), "-o", str(tmp_path / "o120"), "--no-progress",
                 "--from-fit", str(out / "fit.json")]) == 0
    pred = list(csv.DictReader(open(tmp_path / "o120" / "prediction.csv")))
    run120 = list(csv.DictReader(open(tmp_path / "o120" / "stribeck.csv")))
    for p, r in zip(pred, run120, strict=True):       # the same points, solved from other
        assert float(p["friction_coefficient"]) == pytest.approx(     # starts: equal to the
            float(r["friction_coefficient"]), abs=2e-4 * cfb)  # coupling's 6.8e-5 C_f,b, x3
        assert float(p["cf_low"]) < float(p["friction_coefficient"]) < float(p["cf_high"])
    assert main(["run", str(case120), "-o", str(tmp_path / "y"), "--from-fit",
                 str(files[0])]) == 2                                  # not a fit.json


@pytest.mark.integration
def test_fit_the_rigs_thermal_resistance(tmp_path, capsys):
    """Fem-twin fit --params boundary_friction,bulk_resistance sweeps each
    curve at the other RESISTANCES (checkpointed in OUT/fit) and recovers the case's own
    R_b = 1 K/W and C_f,b = 0.15 from the thermal run's own curves; the isothermal twin
    refuses the parameter before any work."""
    case = small_case(tmp_path)
    out = tmp_path / "o"
    assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 0
    files = measured_from_run(out, tmp_path, slice(None))
    params = "boundary_friction,bulk_resistance"
    assert main(["fit", str(case), *files, "-o", str(out), "--no-progress", "--params",
                 params]) == 0
    fit = json.loads((out / "fit.json").read_text())
    assert fit["bulk_resistance"]["value"] == pytest.approx(1.0, abs=0.05)
    assert fit["boundary_friction"]["value"] == pytest.approx(0.15, rel=2e-3)
    assert "bulk_resistance" in capsys.readouterr().out
    iso = tmp_path / "iso.toml"
    iso.write_text(re.sub(r"\n(bulk_resistance|spot_radius) = .*", "", case.read_text()
                          ).replace('model = "flash"', 'model = "none"'))
    assert main(["fit", str(iso), *files, "-o", str(tmp_path / "x"), "--params", params]) == 2
    assert "needs the thermal twin" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_fit_validate_and_from_fit_refuse_what_they_cannot_use(tmp_path, capsys):
    """Checked against the case before any work, exit 2 and one line:
    a fit whose measured speeds lie outside the case's sweep (it returned the starting
    values with a zero-width interval), a measured C_f below zero, a predicted load 1000x
    below the case's (kN typed as N), a zero or negative
    --radius, a fit.json with an implausible C_f,b (it ran and reported C_f up to 4.2)."""
    case = small_case(tmp_path)
    far = tmp_path / "far.csv"
    far.write_text("speed,friction_coefficient\n" + "".join(
        f"{u!r},0.05\n" for u in (10.0, 20.0, 30.0)))
    out = tmp_path / "o"
    assert main(["fit", str(case), str(far), "-o", str(out), "--params", "boundary_friction",
                 "--no-progress"]) == 2
    assert "no measured point lies inside" in capsys.readouterr().err
    assert not (out / "geometry").exists()
    negative = tmp_path / "neg.csv"
    negative.write_text("speed,friction_coefficient\n0.1,-0.02\n0.2,0.01\n")
    assert main(["fit", str(case), str(negative), "-o", str(out), "--params",
                 "boundary_friction", "--no-progress"]) == 2
    assert "[0, 1]" in capsys.readouterr().err
    good_curve = tmp_path / "ok.csv"
    good_curve.write_text("speed,friction_coefficient\n0.1,0.05\n0.2,0.04\n0.5,0.03\n")
    assert main(["fit", str(case), str(good_curve), "-o", str(out), "--params",   # kN as N
                 "boundary_friction", "--predict-load", "0.15", "--no-progress"]) == 2
    assert "more than 10x from the case's 150 N" in capsys.readouterr().err
    assert not (out / "geometry").exists()
    (tmp_path / "afile").write_text("")
    for bad in (["--params", "bogus"], ["-o", str(tmp_path / "afile")]):   # before the banner
        assert main(["fit", str(case), str(good_curve), "-o", str(out), "--params",
                     "boundary_friction", "--no-progress", *bad]) == 2
        err = capsys.readouterr().err
        assert "estimated" not in err and err.count("\n") == 1, err
    (out / "stribeck.csv").parent.mkdir(parents=True, exist_ok=True)
    (out / "stribeck.csv").write_text("speed_m_s,hersey,friction_coefficient,viscosity_Pa_s\n"
                                      "0.1,1e-7,0.01,0.066\n1.0,1e-6,0.02,0.066\n")
    good = tmp_path / "good.csv"
    good.write_text("speed,friction_coefficient\n10,0.01\n20,0.02\n")
    for radius in ("0", "-0.03"):
        assert main(["validate", str(out), str(good), "--rpm", "--radius", radius]) == 2
        assert "--radius" in capsys.readouterr().err
    head = ("speed_m_s,hersey,friction_coefficient,viscosity_Pa_s,hydrodynamic_friction_N,"
            "boundary_force_N,contact_load_fraction,h_d_m,iterations\n")
    row = "{},1e-7,{},0.066,0.1,1.0,0.5,2e-7,3\n"
    (out / "stribeck.csv").write_text(head + row.format(0.1, 0.05) + row.format(1.0, 0.02))
    other_oil = tmp_path / "oil.csv"                   # its own column picks its curve
    other_oil.write_text("speed,friction_coefficient,viscosity_Pa_s\n0.2,0.01,0.024\n"
                         "0.5,0.02,0.024\n")
    assert main(["validate", str(out), str(other_oil)]) == 2
    assert "no curve at mu_0 = 0.024 Pa s" in capsys.readouterr().err
    (out / "stribeck.csv").write_text(head + row.format(0.1, "nan") + row.format(1.0, 0.02))
    assert main(["validate", str(out), str(tmp_path / "ok.csv")]) == 2
    assert "holds a non-finite C_f" in capsys.readouterr().err
    fit = tmp_path / "fit.json"
    fit.write_text(json.dumps({"fit": {"parameters": ["boundary_friction"]},
                               "case": {"temperatures": [24.0, 50.0], "law": None},
                               "boundary_friction": {"value": 5.0, "low": 4.0, "high": 6.0}}))
    assert main(["run", str(case), "-o", str(tmp_path / "p"), "--from-fit", str(fit)]) == 2
    assert "boundary_friction" in capsys.readouterr().err
    assert not (tmp_path / "p" / "geometry").exists()


@pytest.mark.integration
def test_measured_curves_at_two_loads_and_a_prediction_at_a_third(tmp_path, capsys):
    """A measured CSV with ``load_N`` and ``viscosity_Pa_s`` columns is fitted against the
    twin swept at that load and oil (checkpointed in OUT/fit/): the run's own curve at
    150 N and the twin's at 300 N, both at C_f,b = 0.15, return C_f,b = 0.15 with the
    loads in fit.json; ``--predict-load 225`` writes the fitted twin at 225 N with its
    band, which holds the twin's cf_err there; tau_0 with alpha from one load is refused
    before any work."""
    case = small_case(tmp_path)
    out, heavy = tmp_path / "o", tmp_path / "heavy"
    assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 0
    light = measured_from_run(out, tmp_path, slice(1, -1))[0]
    (tmp_path / "heavy.toml").write_text(case.read_text().replace("load = 150.0",
                                                                  "load = 300.0"))
    assert main(["run", str(tmp_path / "heavy.toml"), "-o", str(heavy), "--no-progress"]) == 0
    cfb = 1 / (3 * 3 ** 0.5)
    c = read_stribeck_csv(heavy / "stribeck.csv")[0]
    cf = (c.hydrodynamic_friction + 0.15 / cfb * c.boundary_force) / 300.0
    (tmp_path / "m300.csv").write_text("speed,friction_coefficient,load_N,viscosity_Pa_s\n"
                                       + "".join(f"{float(u)!r},{float(f)!r},300,"
                                                 f"{float(c.viscosity)!r}\n"
                                                 for u, f in zip(c.speed[1:-1], cf[1:-1])))
    args = ["fit", str(case), light, str(tmp_path / "m300.csv"), "-o", str(out),
            "--no-progress"]
    assert main([*args, "--params", "boundary_friction", "--predict-load", "225"]) == 0
    fit = json.loads((out / "fit.json").read_text())
    assert fit["boundary_friction"]["value"] == pytest.approx(0.15, rel=2e-3)
    assert fit["case"]["loads_N"] == [150.0, 300.0]
    rows = list(csv.DictReader(open(out / "prediction_225N.csv")))
    assert {"speed_m_s", "friction_coefficient", "cf_low", "cf_high"} <= set(rows[0])
    assert all(float(r["cf_low"]) <= float(r["friction_coefficient"]) <= float(r["cf_high"])
               for r in rows)
    # the band holds the twin's own error at that load, as the run's curves do (it was
    # missing: the fit's sweeps at other loads ran without the estimate)
    assert all(float(r["cf_err"]) >= 0 for r in rows)
    assert main(["fit", str(case), light, "-o", str(out), "--no-progress", "--params",
                 "shear_strength,pressure_coefficient"]) == 2
    assert "two or more loads" in capsys.readouterr().err


@pytest.mark.integration
def test_fit_the_plateau_and_predict_the_mixed_regime(tmp_path, capsys):
    """`fem-twin fit --plateau 0.5`: C_f,b from the points where the twin's asperities
    carry half the load, 0.15 recovered; the other points predicted from it, reported apart
    (fit.json's plateau, the printed lines) and exact here (the measured curves are the
    twin's own at 0.15); the temperature is refused with it before any work."""
    case = small_case(tmp_path)
    out = tmp_path / "o"
    assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 0
    files = measured_from_run(out, tmp_path, slice(None))
    assert main(["fit", str(case), *files, "-o", str(out), "--no-progress", "--params",
                 "boundary_friction", "--plateau", "0.5"]) == 0
    fit = json.loads((out / "fit.json").read_text())
    assert fit["boundary_friction"]["value"] == pytest.approx(0.15, rel=1e-3)
    p = fit["plateau"]
    assert p["fitted"]["points"] >= 2 and p["predicted"]["points"] >= 4
    assert p["predicted"]["max_abs_cf_dev"] < 1e-3
    assert "predicted:" in capsys.readouterr().out
    assert main(["fit", str(case), *files, "-o", str(tmp_path / "x"), "--params",
                 "boundary_friction,temperature", "--plateau"]) == 2
    assert not (tmp_path / "x").exists()
