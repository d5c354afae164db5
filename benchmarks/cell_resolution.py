"""Group ``cell-resolution``: C_f of the bundled pin over its cells' resolution, against the
patches' own 256 pixels.

    FEM_TWIN_BENCH_DIR=DIR python benchmarks/run.py cell-resolution    # about 5 min on 2 cores

The ``estimate`` group's base case (first patch pair, 0.066 Pa s, isothermal) with ``[micro]
resolution`` n^2 for n in ``SIDES``, each patch resampled from its 256 px.  Rows, per speed in
contact (contact load share above 1 %): C_f(n) - C_f(256) [% C_f,b] for every n, and the
grid part of the estimate of the case's own cells (its ``[micro] resolution``), signed.
Baseline: that run.  Checked: the case's cells within 0.5 % C_f,b of the patches' own
pixels at every speed."""

from __future__ import annotations

import os
from dataclasses import replace

import numpy as np
from common import Check
from estimate import HERE, run_kept, subset_case

DEFAULT = False
#: the cells' sides [px], each a multiple of the case's steps (whole-pixel instants); the
#: last is the patches' own
SIDES = (64, 96, 128, 192, 256)


def run():
    from fem_twin.case import load_case

    case = subset_case(load_case(os.path.join(HERE, "..", "examples", "pin_on_disk.toml")), 0.066)
    base_side = case.micro.resolution[0]
    runs = {n: run_kept(replace(case, micro=replace(case.micro, resolution=(n, n))),
                         f"pin_on_disk_cells{n}", reuse=n != base_side) for n in SIDES}
    cb = case.tribometer.boundary_friction
    own, base = runs[SIDES[-1]][1], runs[base_side][1]
    rows = [(f"cells {n}^2", t, "") for n, (t, *_) in runs.items()]
    worst = 0.0
    for i, u in enumerate(base.speed):
        worst = max(worst, abs(base.friction_coefficient[i] - own.friction_coefficient[i]) / cb)
        if base.contact_load_fraction[i] < 0.01:
            continue
        ref = own.friction_coefficient[i]
        moved = ", ".join(f"{n}: {(c.friction_coefficient[i] - ref) / cb:+.3%}"
                          for n, (_, c, _) in runs.items() if n != SIDES[-1])
        grid = next((v["grid"] for k, v in runs[base_side][2].items()
                     if np.isclose(k, u, rtol=1e-6)), np.nan) / cb
        rows.append((f"  {u:.4g} m/s", 0.0, f"C_f(n) - C_f(256): {moved}; the {base_side}^2 "
                                            f"run's grid part {grid:+.3%}"))
    return runs[base_side][0], rows, Check(worst < 5e-3, (
        f"the {base_side}^2 cells at most {worst:.3%} C_f,b from the patches' own pixels"))
