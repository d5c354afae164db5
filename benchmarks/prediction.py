"""A prediction at a second temperature and load, checked on data the fit did not see.

    python benchmarks/prediction.py OUT      # hours on 2 cores (the fine twin)

"Measured" curves from a finer twin than the default (256 px cells, every h0 candidate,
4x the time steps) under a known shear law (alpha 0.12, c_T 0.003 /K about 24 C, thermal
model on) at 24 and 50 C and 150 N, and at 24 C and 300 N.  The default twin of the same
case (shear law, c_T started at 0.001) is fitted with ``fem-twin fit --plateau`` on the
150 N curves' plateau points (alpha and c_T), predicts their mixed regime and, with
``--predict-load 300``, the 300 N curve.  Prints one row per point: the fine twin's C_f,
the prediction and its 95 % band (the fit's intervals and the twin's cf_err), and the
miss in % C_f,b; the last line counts the predicted points inside their band.
"""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from scipy.interpolate import PchipInterpolator

ROOT = Path(__file__).resolve().parents[1]
CFB = 1 / (3 * 3 ** 0.5)
LAW = ('law = "shear"\npressure_coefficient = 0.12\ntemperature_coefficient = 0.003\n'
       "#")


def case(text: str, fine: bool, load: float = 150.0) -> str:
    """The bundled case file with the shear law (fine: the truth's, 256 px cells, all h0,
    128 steps; else the fit's start) at ``load`` [N]."""
    text = text.replace("../meshes/", str(ROOT / "meshes") + "/")
    text = text.replace('law = "constant"', LAW if fine else
                        'law = "shear"\ntemperature_coefficient = 0.001\n#')
    text = text.replace("load = 150.0 ", f"load = {load:g} ")
    if fine:
        for old, new in (("resolution = [128, 128]      # patches", "resolution = [256, 256] #"),
                         ("steps = 32 ", "steps = 128 "), ("h0_tol = 0.01", "h0_tol = 0   ")):
            assert old in text
            text = text.replace(old, new)
    return text


def fem_twin(*args) -> None:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    subprocess.run([sys.executable, "-m", "fem_twin.cli", *map(str, args), "--no-progress",
                    "--yes"], check=True, env=env)


def curves(path: Path) -> dict:
    out = {}
    for r in csv.DictReader(open(path)):
        out.setdefault(float(r["viscosity_Pa_s"]), []).append(
            (float(r["speed_m_s"]), float(r["friction_coefficient"])))
    return {mu: np.array(sorted(v)) for mu, v in out.items()}


def main(out: Path) -> None:
    text = (ROOT / "examples" / "pin_on_disk.toml").read_text()
    out.mkdir(parents=True, exist_ok=True)
    for name, fine, load in (("fine150", True, 150.0), ("fine300", True, 300.0),
                             ("twin", False, 150.0)):
        (out / f"{name}.toml").write_text(case(text, fine, load))
        fem_twin("run", out / f"{name}.toml", "-o", out / name)
    fine = curves(out / "fine150" / "stribeck.csv")
    measured = []
    for mu, arr in sorted(fine.items(), reverse=True):
        path = out / f"m{mu:g}.csv"
        path.write_text("speed,friction_coefficient\n" + "".join(
            f"{float(u)!r},{float(c)!r}\n" for u, c in arr))
        measured.append(path)
    fem_twin("fit", out / "twin.toml", *measured, "-o", out / "twin", "--params",
             "pressure_coefficient,temperature_coefficient", "--plateau", "--predict-load",
             300)
    report(out)


def report(out: Path) -> None:
    fit = json.loads((out / "twin" / "fit.json").read_text())
    print({k: round(fit[k]["value"], 6) for k in fit["fit"]["parameters"]})
    rows = [(f"{'24' if r['curve'] == 1 else '50'} C, 150 N", u, f, m, c, lo, hi)
            for r in fit["plateau"]["rows"] for u, f, m, c, lo, hi in zip(
                r["speed_m_s"], r["fitted"], r["measured_cf"], r["cf"], r["cf_low"],
                r["cf_high"])]
    heavy = curves(out / "fine300" / "stribeck.csv")[0.066]
    truth = PchipInterpolator(np.log(heavy[:, 0]), heavy[:, 1])
    rows += [("24 C, 300 N", float(r["speed_m_s"]), False, float(truth(np.log(float(
        r["speed_m_s"])))), float(r["friction_coefficient"]), float(r["cf_low"]),
        float(r["cf_high"])) for r in csv.DictReader(open(out / "twin" / "prediction_300N.csv"))
        if float(r["viscosity_Pa_s"]) == 0.066]
    print("| curve | U [m/s] | role | fine twin | predicted | 95 % band | miss % C_f,b |")
    print("|---|---|---|---|---|---|---|")
    for name, u, fitted, m, c, lo, hi in rows:
        print(f"| {name} | {u:.4g} | {'fitted' if fitted else 'predicted'} | {m:.5f} | "
              f"{c:.5f} | {lo:.5f}-{hi:.5f} | {100 * (c - m) / CFB:+.2f} |")
    predicted = [r for r in rows if not r[2]]
    inside = sum(lo <= m <= hi for *_, m, c, lo, hi in predicted)
    worst = max(abs(c - m) for *_, m, c, lo, hi in predicted) / CFB
    print(f"prediction: {inside} of {len(predicted)} predicted points inside their band, "
          f"largest miss {worst:.2%} C_f,b")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("prediction_out"))
