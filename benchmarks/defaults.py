"""The ``defaults`` group: what cheaper micro settings cost and how far they move C_f.

The paper case (``examples/paper.toml``) with its first patch pair and mu_0 = 0.066 Pa s
(25 speeds, no refinement pass, no band, isothermal) on several cell grids and step counts, against
a reference at twice the macro grid (512^2), the patches' own 256 px, 128 steps and every
one of the 100 h0 candidates (``h0_tol = 0``).  Per setting: its task graph's CPU time, the
largest C_f error estimate and the largest change to the reference, both in % C_f,b, and
the speed of the latter.  ``$FEM_TWIN_BENCH_DIR`` keeps the runs; a finished run there is
read, not run again (an interrupted one resumes).  The baseline is the paper's settings.
Checked: every setting's largest estimate at least its largest true error.
"""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import replace

import numpy as np
from common import Check

from fem_twin.case import load_case
from fem_twin.stages import pipeline
from fem_twin.stribeck.curve import read_stribeck_csv

DEFAULT = False
HERE = os.path.dirname(os.path.abspath(__file__))
#: (label, cell resolution [px], time steps): the paper's settings first.
CANDIDATES = (("cells 256^2, 32 steps (the paper)", 256, 32),
              ("cells 128^2, 32 steps", 128, 32),
              ("cells 128^2, 16 steps", 128, 16),
              ("cells 256^2, 16 steps", 256, 16))


def _pair_case():
    """The paper case reduced to its first patch pair, one viscosity, one pass, isothermal
    (the film-temperature law needs two viscosities)."""
    case = load_case(os.path.join(HERE, "..", "examples", "paper.toml"))
    return replace(case, geometry=replace(case.geometry, patches=case.geometry.patches[:1]),
                   thermal=replace(case.thermal, model="none"),
                   lubricant=replace(case.lubricant, viscosities=(0.066,),
                                     temperatures=case.lubricant.temperatures[:1]),
                   sweep=replace(case.sweep, refine=0), measured=(),
                   run=replace(case.run, patch_band=False))


def _run(case, name, keep):
    """CPU time of the run's task graph [s] and its curve (kept under ``keep``/name)."""
    out = os.path.join(keep, name)
    summary = os.path.join(out, "summary.json")
    if not os.path.isfile(summary):
        pipeline.run(case, out, progress=False)
    cpu = json.load(open(summary))["task_graph"]["cpu_s"]
    return cpu, read_stribeck_csv(os.path.join(out, "stribeck.csv"))[0]


def run():
    """Rows: per setting, CPU [s], largest estimate and true error [% C_f,b]."""
    case = _pair_case()
    cb = case.tribometer.boundary_friction
    reference = replace(case, preprocessing=replace(case.preprocessing, resolution=(512, 512)),
                        micro=replace(case.micro, resolution=(256, 256), steps=128, h0_tol=0.0))
    with tempfile.TemporaryDirectory() as tmp:
        keep = os.environ.get("FEM_TWIN_BENCH_DIR") or tmp
        rows, base = [], None
        for label, cells, steps in CANDIDATES:
            run = replace(case, micro=replace(case.micro, resolution=(cells, cells), steps=steps))
            cpu, curve = _run(run, f"defaults_{cells}_{steps}", keep)
            rows.append((label, cpu, curve))
            base = base or cpu
        cpu_ref, ref = _run(reference, "defaults_reference", keep)
    table, short = [("reference: 512^2 / 256^2, 100 h0, 128 steps", cpu_ref, "")], []
    for label, cpu, curve in rows:
        true = np.abs(curve.friction_coefficient - ref.friction_coefficient) / cb
        at = int(np.argmax(true))
        short += [] if curve.friction_error.max() / cb >= true[at] else [label]
        table.append((label, cpu, f"estimate at most {curve.friction_error.max() / cb:.3%}, "
                      f"true error at most {true[at]:.3%} C_f,b (at {curve.speed[at]:.3g} m/s)"))
    return base, table, Check(not short, "every setting's largest C_f estimate at least its "
                                         "largest true error"
                                         + (f" (not {'; '.join(short)})" if short else ""))
