"""Command line: the commands and steps, and the main job's companions (`example`,
`validate`, estimates)."""


import csv
import json
import os
import subprocess
import sys

import numpy as np
import pytest
from conftest import ROOT
from sample_cases import small_case

from fem_twin import Topography, read_topography, write_topography
from fem_twin.case import load_case
from fem_twin.cli import main
from fem_twin.errors import SolverError
from fem_twin.micro import FlowFactors
from fem_twin.runtime.cost import estimated_seconds


def test_help_lists_pipeline_stages(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--help"])
    assert exit_.value.code == 0
    out = capsys.readouterr().out
    for stage in ("run", "topography", "contact", "homogenise", "mesh", "sample"):
        assert stage in out


def test_console_script_runs():
    out = subprocess.run([sys.executable, "-m", "fem_twin.cli", "topography", "--help"],
                         capture_output=True, text=True, check=True).stdout
    for step in ("fill", "level", "clip", "filter", "resample", "patch", "flip", "mount"):
        assert step in out


def test_topography_steps_write_files(tmp_path):
    z = np.random.default_rng(0).normal(size=(40, 50)) * 1e-7
    z[5, 5] = np.nan
    write_topography(tmp_path / "raw.npz", Topography(z, 1e-6))
    assert main(["topography", "fill", str(tmp_path / "raw.npz"), str(tmp_path / "f.npz")]) == 0
    assert main(["topography", "filter", str(tmp_path / "f.npz"), str(tmp_path / "g.txt"),
                 "--fwhm", "3"]) == 0
    assert main(["topography", "refine", str(tmp_path / "g.txt"), str(tmp_path / "r.npz"),
                 "--factor", "2"]) == 0
    r = read_topography(tmp_path / "r.npz")
    assert r.shape == (79, 99) and r.mask is None
    assert main(["mesh", str(tmp_path / "r.npz"), str(tmp_path / "r.vtu"), "--periodic"]) == 0
    assert (tmp_path / "r.vtu").stat().st_size > 0


def test_contact_level_and_average_steps(tmp_path, capsys):
    pins = []
    for k in (1, 2):
        out = tmp_path / f"pin{k}.npz"
        assert main(["topography", "prepare-pin", str(ROOT / "meshes" / "sample" / f"pin_{k}.npz"),
                     str(out), "--resolution", "48", "48"]) == 0
        pins.append(str(out))
    capsys.readouterr()
    assert main(["contact", "level", pins[0], str(tmp_path / "lev.npz")]) == 0
    report = json.loads(capsys.readouterr().out)
    assert max(abs(r) for r in report["residuals"]) < 1e-6
    assert main(["contact", "average", *pins, "-o", str(tmp_path / "avg.npz")]) == 0
    assert read_topography(tmp_path / "avg.npz").shape == (48, 48)


@pytest.mark.integration
def test_homogenise_run_average_and_fields(tmp_path, capsys):
    """CLI micro stage: two patch pairs -> flow factors, CSV, plot, VTU/PVD, then average."""
    from fem_twin.io.mesh import read_vtu
    from fem_twin.micro import homogenise
    outs = []
    for k in (1, 2):
        pin, disk = tmp_path / f"pin{k}.npz", tmp_path / f"disk{k}.npz"
        src = ROOT / "meshes" / "sample"
        assert main(["topography", "prepare-patch", str(src / f"patch_{k}_pin.npz"), str(pin),
                     "--shape", "16", "16"]) == 0
        assert main(["topography", "prepare-patch", str(src / f"patch_{k}_disk.npz"), str(disk),
                     "--shape", "16", "16", "--upper"]) == 0
        out = tmp_path / f"ff{k}"
        extra = ["--fields", "2e-7"] if k == 1 else []
        assert main(["homogenise", "run", str(pin), str(disk), "-o", str(out), "--h0", "1e-7",
                     "1e-6", "4", "--steps", "4", "--workers", "1", "--no-progress",
                     *extra]) == 0
        ff = FlowFactors.load(out / "flow_factors.npz")
        api = homogenise(read_topography(pin), read_topography(disk), np.geomspace(1e-7, 1e-6, 4),
                         steps=4)
        assert np.array_equal(ff.A, api.A) and (out / "flow_factors.png").stat().st_size > 0
        outs.append(ff)
    _, fields = read_vtu(tmp_path / "ff1" / "fields" / "cell_h0_200nm_003.vtu")
    assert {"gap", "asperity_pressure", "chi_1", "chi_2", "chi_3"} <= set(fields)
    assert fields["gap"].min() >= 1e-9
    assert (tmp_path / "ff1" / "fields" / "cell_h0_200nm.pvd").is_file()
    assert main(["homogenise", "average", str(tmp_path / "ff1" / "flow_factors.npz"),
                 str(tmp_path / "ff2" / "flow_factors.npz"), "-o", str(tmp_path / "avg")]) == 0
    mean = FlowFactors.load(tmp_path / "avg" / "flow_factors.npz")
    assert np.allclose(mean.A, (outs[0].A + outs[1].A) / 2, rtol=1e-14)


def test_homogenise_run_with_adaptive_h0(tmp_path, capsys):
    """--h0-tol: a subset of the N candidates is solved, the same as the API's, and the h0
    error estimate is printed beside the time and grid ones."""
    from fem_twin.micro import homogenise
    pin, disk = tmp_path / "pin.npz", tmp_path / "disk.npz"
    src = ROOT / "meshes" / "sample"
    assert main(["topography", "prepare-patch", str(src / "patch_3_pin.npz"), str(pin),
                 "--shape", "16", "16"]) == 0
    assert main(["topography", "prepare-patch", str(src / "patch_3_disk.npz"), str(disk),
                 "--shape", "16", "16", "--upper"]) == 0
    capsys.readouterr()
    assert main(["homogenise", "run", str(pin), str(disk), "-o", str(tmp_path / "ff"), "--h0",
                 "1e-7", "1e-6", "40", "--steps", "4", "--h0-tol", "0.01", "--workers", "1",
                 "--no-progress"]) == 0
    printed = json.loads(capsys.readouterr().out)
    ff = FlowFactors.load(tmp_path / "ff" / "flow_factors.npz")
    api = homogenise(read_topography(pin), read_topography(disk), np.geomspace(1e-7, 1e-6, 40),
                     steps=4, h0_tol=0.01)
    assert printed["points"] == len(ff) == len(api) < 40 and np.array_equal(ff.h0, api.h0)
    assert {"time", "grid", "h0"} <= set(printed["estimated_relative_error"])
    assert main(["homogenise", "run", str(pin), str(disk), "-o", str(tmp_path / "bad"),
                 "--h0-tol", "2", "--no-progress"]) == 2


def test_macro_point_step(tmp_path, capsys):
    """fem-twin macro point: same operating point as the API, fields in npz and VTU."""
    from fem_twin.macro import Lubricant, MixedResult, solve_mixed
    from fem_twin.micro import homogenise
    src = ROOT / "meshes" / "sample"
    pin, disk = tmp_path / "pin.npz", tmp_path / "disk.npz"
    assert main(["topography", "prepare-pin", str(src / "pin_1.npz"), str(pin),
                 "--resolution", "32", "32"]) == 0
    assert main(["topography", "prepare-disk", str(src / "disk_1.npz"), str(disk),
                 "--resolution", "32", "32"]) == 0
    rng = np.random.default_rng(3)
    rough = [Topography(rng.normal(size=(16, 16)) * 5e-8, 5e-7) for _ in range(2)]
    ff = homogenise(*rough, np.geomspace(2e-8, 1e-6, 6), steps=2)
    ff.save(tmp_path / "ff.npz")
    capsys.readouterr()
    assert main(["macro", "point", str(pin), str(tmp_path / "ff.npz"), "--disk", str(disk),
                 "--speed", "0.5", "-o", str(tmp_path / "pt")]) == 0
    out = json.loads(capsys.readouterr().out)
    p, d = read_topography(pin), read_topography(disk)
    api = solve_mixed(d.heights - p.heights, p.spacing, ff, load=150.0, speed=0.5,
                      lubricant=Lubricant(0.066), face=p.heights > -0.5e-3)
    assert out["friction_coefficient"] == api.friction_coefficient
    assert MixedResult.load(tmp_path / "pt" / "point.npz").h_d == api.h_d
    assert (tmp_path / "pt" / "point.vtu").stat().st_size > 0


@pytest.mark.integration
def test_validate_an_existing_run_against_a_measured_curve(tmp_path, capsys):
    """Fem-twin validate OUT measured.csv, speeds in m/s or rpm with the
    case's sliding radius: a 'measured' curve 1 % of C_f,b above the simulated one gives
    C_f,dev = -1 % at every measured speed inside the simulated range."""
    case = small_case(tmp_path)
    out = tmp_path / "o"
    assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 0
    rows = [r for r in csv.DictReader(open(out / "stribeck.csv"))
            if float(r["viscosity_Pa_s"]) == 0.024]
    cfb = 1 / (3 * 3 ** 0.5)
    speeds = [float(r["speed_m_s"]) for r in rows]
    (tmp_path / "m.csv").write_text("speed,friction_coefficient\n" + "".join(
        f"{u!r},{float(r['friction_coefficient']) + 0.01 * cfb!r}\n" for u, r in
        zip(speeds, rows)))
    rpm = [u * 60 / (2 * np.pi * 30e-3) for u in speeds]
    (tmp_path / "rpm.csv").write_text("speed,cf\n" + "".join(
        f"{n!r},{float(r['friction_coefficient']) + 0.01 * cfb!r}\n" for n, r in
        zip(rpm, rows)))
    for name, extra in (("m", []), ("rpm", ["--rpm"])):
        assert main(["validate", str(out), str(tmp_path / f"{name}.csv"), "--viscosity",
                     "0.024", *extra]) == 0
        assert "max |C_f,dev| = 1.00%" in capsys.readouterr().out
        dev = [float(r["cf_dev"]) for r in csv.DictReader(open(out / f"validation_{name}.csv"))]
        assert np.allclose(dev, -0.01, atol=1e-8)
        assert (out / f"validation_{name}.png").stat().st_size > 0
    assert main(["validate", str(out), str(tmp_path / "rpm.csv")]) == 2     # rpm as m/s
    assert "--rpm" in capsys.readouterr().err


@pytest.mark.integration
def test_example_case_ships_with_the_package(tmp_path, capsys):
    """`fem-twin example DIR` writes the bundled case (package data, so it
    is there after a non-editable install, as in CI) and regenerates its sample twin; the
    case is the repository's example with its paths, and its files are the bundled ones."""
    from importlib.resources import files
    shipped = files("fem_twin.cases").joinpath("pin_on_disk.toml").read_text()
    repo = (ROOT / "examples" / "pin_on_disk.toml").read_text()
    assert shipped == repo.replace("../meshes/sample/", "meshes/sample/")
    assert main(["example", str(tmp_path / "ex")]) == 0
    case = load_case(tmp_path / "ex" / "pin_on_disk.toml")
    for pair in case.geometry.patches[:1]:
        for path in pair:
            a = read_topography(path)
            b = read_topography(ROOT / "meshes" / "sample" / path.name)
            assert np.array_equal(a.heights, b.heights)
    assert "fem-twin run" in capsys.readouterr().out


def test_run_time_estimates_hold():
    """Fem-twin run's estimate lies within 0.8-1.25x of the wall time measured on 2 cores,
    the calibration machine's costs scaled by the two probes of fem_twin.runtime.machine
    taken before the same run (`benchmarks/run.py estimates`, AMD EPYC): the
    bundled, ball and paper cases with PARDISO, quiet and beside a busy loop on one of the
    two cores (a slower machine, the probes run side by side as the workers), and with
    SuperLU (FEM_TWIN_SPARSE=superlu, a machine without MKL, where the cells slow down
    1.3x, a pin's points 1.4x and a ball's not at all; the cells' probe then reads the
    run's cells times SUPERLU_CELLS).  The wall times and the probes'
    factors as the runs printed them (docs/performance.md)."""
    from fem_twin.runtime.machine import Slowdown
    cases = {name: load_case(ROOT / "examples" / f"{name}.toml")
             for name in ("pin_on_disk", "paper", "ball_on_disk")}
    runs = [("pin_on_disk", 77.4, (0.60, 0.67)), ("ball_on_disk", 79.4, (0.65, 0.64)),
            ("paper", 134.8, (0.59, 0.68)),
            ("pin_on_disk", 117.6, (0.94, 1.00)), ("ball_on_disk", 113.7, (0.87, 0.97)),
            ("paper", 197.5, (0.85, 1.00)),                         # beside a busy loop
            ("pin_on_disk", 128.5, (1.10, 0.88)), ("ball_on_disk", 91.5, (1.10, 0.67)),
            ("paper", 215.1, (1.10, 0.87))]                         # SuperLU
    for name, wall, factors in runs:
        estimate = estimated_seconds(cases[name], 2, Slowdown(*factors))
        assert 0.8 < estimate / wall < 1.25, (name, factors, estimate, wall)


def test_the_estimate_follows_the_machine_speed(monkeypatch, capsys):
    """The machine ran the same work up to 1.9x slower from hour to hour,
    so the estimate scales by probes of the micro stage and of a macro point timed before
    the run: a machine twice as slow gets twice the estimate, one slower at the macro
    points alone a longer Stribeck stage alone.  Each probe is one thread's time of real
    work, and the printed durations read as a person would write them."""
    import fem_twin.runtime.machine as speed
    from fem_twin.cli.runs import _confirm_cost, duration
    from fem_twin.runtime.cost import MICRO, cost_tasks
    monkeypatch.delenv("FEM_TWIN_SLOWDOWN")                   # the probes themselves
    for kind in ("micro", "macro"):                # a time, whatever the machine's load
        seconds = speed.probe_seconds(kind, repeats=1)
        assert np.isfinite(seconds) and seconds > 0
    monkeypatch.setenv("FEM_TWIN_SPARSE", "pardiso")   # the timed probes' backend, as read
    case = load_case(ROOT / "examples" / "pin_on_disk.toml")
    estimates = []
    for factor in (1.0, 2.0):
        monkeypatch.setattr(speed, "probe_together",
                            lambda kind, n: factor * speed.REFERENCE_SECONDS[kind])
        estimates.append(_confirm_cost(case, yes=True))
    assert estimates[1] == pytest.approx(2 * estimates[0])
    assert "takes 2x the calibration machine's time" in capsys.readouterr().err
    serial = sum(t.seconds for t in cost_tasks(case) if not t.name.startswith(MICRO))
    slow = speed.Slowdown(1.0, 3.0)                           # the macro points alone
    assert estimated_seconds(case, 1, slow) == pytest.approx(
        estimated_seconds(case, 1) + 2 * serial)
    assert str(slow) == "1x for the cells and 3x for the macro points"
    monkeypatch.setenv("FEM_TWIN_SPARSE", "superlu")          # its cells read long
    superlu = speed.slowdown()
    assert (superlu.micro, superlu.macro) == pytest.approx((2 * speed.SUPERLU_CELLS, 2.0))
    monkeypatch.setattr(speed, "probe_together", lambda kind, n: 100.0)
    assert speed.slowdown() == speed.Slowdown(*speed.BOUNDS[1:] * 2)
    monkeypatch.setenv("FEM_TWIN_SLOWDOWN", "0.5")            # forced: no probe
    assert speed.slowdown() == speed.Slowdown(0.5, 0.5)
    for bad in ("fast", "nan", "-1", "0", "inf", "40"):       # refused, not clipped
        monkeypatch.setenv("FEM_TWIN_SLOWDOWN", bad)
        with pytest.raises(ValueError, match="FEM_TWIN_SLOWDOWN.*0.25 to 4"):
            speed.slowdown()
    with pytest.raises(ValueError, match="workers a whole number"):
        speed.slowdown(workers="2")
    assert [duration(s) for s in (85, 250, 1529)] == ["85 s", "4.2 min", "25 min"]


@pytest.mark.integration
def test_the_probes_run_side_by_side_as_the_workers_will(monkeypatch):
    """With two workers each probe runs in two processes at once, their repeats started
    together, so a load on another core slows the probes as it slows the run's workers
    (docs/performance.md: beside a busy loop the probes read 1.6x, the run took 1.5x).  A
    process whose miniature fails stops the others and the probe says so, without hanging."""
    import fem_twin.runtime.machine as speed
    seconds = speed.probe_together("micro", 2)
    assert 0.05 < seconds < 3.0
    monkeypatch.setitem(speed._MINIATURES, "micro", lambda: 1 / 0)
    assert np.isnan(speed.probe_together("micro", 2))
    monkeypatch.delenv("FEM_TWIN_SLOWDOWN", raising=False)
    if (os.cpu_count() or 1) >= 2:                             # one core: one process
        with pytest.raises(SolverError, match="speed probe failed"):
            speed.slowdown(workers=2)


def test_the_probes_time_on_the_workers_heap():
    """A probe in a fresh process times its miniature on the heap the workers run on
    (fem_twin.numerics.threads.worker_heap), not on glibc's default one, where the pin's
    point took 1.2x as long and by how much depended on what the process had run before
    (docs/performance.md, "The probes' heap")."""
    code = ("import fem_twin.runtime.machine as m, fem_twin.numerics.threads as t; "
            "assert not t._HEAP_SET; m.probe_seconds('micro', repeats=1); print(t._HEAP_SET)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True)
    assert done.stdout.strip() == "True"


def test_more_local_workers_than_cores_share_them(monkeypatch):
    """Local workers beyond the machine's cores share its cores: the bundled case with
    ``[run] workers = 64`` is estimated as on all the cores there are (a ball run with 4
    workers on 2 cores was estimated at 29 s and took 57 s)."""
    from dataclasses import replace

    import fem_twin.runtime.machine as speed
    from fem_twin.cli.runs import _confirm_cost
    monkeypatch.setattr(speed, "probe_together", lambda kind, n: speed.REFERENCE_SECONDS[kind])
    case = load_case(ROOT / "examples" / "pin_on_disk.toml")
    many, own = (_confirm_cost(replace(case, run=replace(case.run, workers=n)), yes=True)
                 for n in (64, os.cpu_count() or 1))
    assert many == pytest.approx(own)
