"""The gallery: every numbered example runs at reduced size (--quick) and ends in a figure."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("[0-9][0-9]_*.py"))
SHARED = ROOT.parent / "shared" / "topographies"


#: one number per example, read from its output at ``--quick`` size, and the range it
#: must fall in with the reason (measured); the two examples on the shared
#: instrument files have none (they skip in a fresh clone)
PINNED = {
    "01_topography_pipeline": (r"pin 3: .*Sq=([\d.e-]+) m", 3.88e-4, 4.04e-4,
                               "the seeded sample pin's face shape (3.96e-4 m)"),
    "02_hertz_contact": (r"elastic: load [\d.]+ N, peak ([\d.]+) p0", 0.98, 1.02,
                         "Hertz: the elastic peak is p0 (0.999)"),
    "03_fe_fvm_flow_factors": (r"worst: A ([\d.]+) %", 0.0, 5.0,
                               "FE and FVM flow factors agree in A within 5 % (2.6 %)"),
    "04_micro_convergence": (r"observed order 16/32/64: .* p_con ([\d.-]+)", 1.3, 2.5,
                             "p_con converges at about second order in the cell grid (1.79; "
                             "at 2 steps and 16-64 px the flow factors' orders are noise)"),
    "05_calibration_studies": (r'"patch 1": ([\d.]+)', 0.07, 0.095,
                               "patch 1's C_f,dev against the average (0.0829)"),
    "07_ehl_point_contact": (r"Mourier contact 97\^2: h_c ([\d.]+) nm", 200.0, 215.0,
                             "the central film of Mourier's contact (207.7 nm)"),
    "08_fit_and_predict": (r"50 C: (\d+) of 4 synthetic", 4, 4,
                           "every 50 C point inside the predicted band"),
    "10_friction_on_the_pin": (r"outlet film 1 um: .*twin [\d.]+ N \(([+-][\d.]+)%\)", -0.5,
                               0.5, "the twin within 0.5 % of the resolved slider (+0.09 %)"),
    "11_rotating_disk": (r"largest difference ([\d.]+) % C_f,b", 0.0, 0.5,
                         "the turning disk against its sector solution (0.21 %)"),
    "12_contact_temperature": (r"film ([\d.]+) C at 2 m/s", 25.0, 30.0,
                               "the oil at 24 C plus its rise (27.2 C)"),
    "13_deterministic_mixed": (r"eps 1/8: worst \|C_f - C_f,det\| ([\d.]+) %", 0.0, 4.0,
                               "the twin against the deterministic pad at eps 1/8 (2.77 %)"),
    "15_sealed_pockets": (r"sealed: .* the floor from 0.5 to 2 nm moves it by up to ([\d.]+) %",
                          0.0, 3.0, "sealed, s_C hardly feels the gap floor (0.8 %; leaking "
                          "26 %)"),
    "16_moving_roughness": (r"eps 1/8: worst \|C_f - C_f,det\| ([\d.]+) %", 0.0, 4.5,
                            "the twin against the time-resolved pad, both rough, at eps 1/8 "
                            "(2.95 %)"),
    "17_average_flow": (r"eps 1/2, average flow: worst \|C_f - C_f,det\| ([\d.]+) %", 15.0,
                        30.0, "the statistical model's gap on the pad, 5-8x the twin's (22.6 %; "
                        "the twin 3.6 %)"),
    "18_graded_ball_mesh": (r"graded mesh over the 97\^2 grid: \d+ nodes, h_c ([\d.]+) nm",
                            200.0, 215.0, "the central film on the graded mesh, as on the "
                            "grid (206.8 nm against 207.7 nm)"),
    "14_boundary_law": (r"shear_strength: ([\d.e+]+) ", 2.4e7, 3.6e7,
                        "the fitted tau_0 within 20 % of the truth, 30 MPa (33.3 MPa)"),
}


def test_the_gallery_is_numbered_and_complete():
    assert len(EXAMPLES) >= 6
    assert [p.name[:2] for p in EXAMPLES] == [f"{i + 1:02d}" for i in range(len(EXAMPLES))]


@pytest.mark.slow
@pytest.mark.parametrize("script", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_runs_and_ends_in_a_figure(script, tmp_path):
    """Each example at --quick size writes its figure last, and the number it pins
    (:data:`PINNED`) falls in its range; ``pytest -m slow`` runs them (about 4 minutes),
    and so does .ci/run."""
    if "real_roughness" in script.name or "measured_ball" in script.name:
        if not SHARED.is_dir():
            pytest.skip(f"{SHARED} absent (a fresh clone): the real instrument files live "
                        "beside the repository")
        pytest.importorskip("SurfaceTopography")
    target = tmp_path / ("figure.png" if script.name[:2] in ("01", "02") else "out")
    env = dict(os.environ, MPLBACKEND="Agg", OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, str(script), str(target), "--quick"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=600, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    pngs = [target] if target.suffix == ".png" else sorted(target.rglob("*.png"))
    assert pngs and all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in pngs)
    assert "wrote" in proc.stdout.splitlines()[-1]                  # the figure comes last
    if script.stem in PINNED:
        pattern, low, high, why = PINNED[script.stem]
        found = re.search(pattern, proc.stdout)
        assert found, f"{script.stem} no longer prints {pattern!r}"
        assert low <= float(found.group(1)) <= high, (why, found.group(0))
