"""Group ``paper``: a reduced paper case and the whole-twin extrapolation.

The paper's case (examples/paper.toml: 6 patch pairs at 256^2 x 32 steps over the paper's
100 h0 candidates, adaptive h0; 2 viscosities x 25 speeds (+ refinement, ~37 points) at
256^2; patch band: 12 more sweeps at 64^2, the nested solves' coarsest grid; 2 cores).
Measured here: sample patch pair 3 at 256^2, adaptive h0 on 2 processes, and the previous
method's cost of one h0 (10 of the 100, serial); 8 consecutive speeds of the paper's 25
(0.53 -> 0.07 m/s) at 256^2 with the macro groups' flow factors (patch 1 at 64^2, 30 h0),
the first point cold, and the same speeds on the band's grids (128^2, "coarse", the default
before; 64^2, "coarsest").  Baseline: the measured micro time of one h0.  Checked: adaptive
h0 solves the twin's cells faster than all 100 h0 (the previous method).
"""

from __future__ import annotations

import os
import time

import numpy as np
from common import Check, macro_factors, macro_gap, sample_patch_pair

DEFAULT = True
HERE = os.path.dirname(os.path.abspath(__file__))


def run():
    from fem_twin.case import load_case
    from fem_twin.macro import Lubricant
    from fem_twin.macro.nested import nested_levels
    from fem_twin.macro.point import coarsened
    from fem_twin.micro import DEFAULT_H0, homogenise
    from fem_twin.stribeck import SweepRequest, stribeck_sweep

    case = load_case(os.path.join(HERE, "..", "examples", "paper.toml"))
    cores, patches, n_mu = 2, len(case.geometry.patches), len(case.lubricant.viscosities)
    pin, disk = sample_patch_pair()
    t0 = time.perf_counter()
    homogenise(pin, disk, DEFAULT_H0[::10], workers=1, error_estimate=False)
    per_h0 = (time.perf_counter() - t0) / 10
    t0 = time.perf_counter()
    ad = homogenise(pin, disk, DEFAULT_H0, workers=cores, h0_tol=case.micro.h0_tol)
    t_pair = time.perf_counter() - t0
    gap, spacing, face = macro_gap(256)
    speeds = np.geomspace(2.0, 0.01, case.sweep.count)[6:14]
    ff = macro_factors()          # smooth factors (30 h0): 10 h0 kink p_con, the sweep stalls
    t0 = time.perf_counter()
    stribeck_sweep(SweepRequest(gap, spacing, ff, speeds[:1], load=150.0,
                                lubricant=Lubricant(0.066),
                   face=face))
    cold = time.perf_counter() - t0
    t0 = time.perf_counter()
    curve = stribeck_sweep(SweepRequest(gap, spacing, ff, speeds, load=150.0,
                                        lubricant=Lubricant(0.066),
                           face=face))
    warm = (time.perf_counter() - t0 - cold) / (speeds.size - 1)
    band = []                                  # a point on each of the band's grids
    grid = (gap, spacing, face)
    for _ in range(nested_levels(gap.shape)):
        grid = coarsened(*grid)
        t0 = time.perf_counter()
        stribeck_sweep(SweepRequest(grid[0], grid[1], ff, speeds, load=150.0,
                                    lubricant=Lubricant(0.066),
                       face=grid[2]))
        band.append((time.perf_counter() - t0) / speeds.size)
    coarse, coarsest = band[0], band[-1]
    dense = per_h0 * case.micro.h0_count * patches / cores
    micro = t_pair * patches
    points = case.sweep.count * 1.5                      # refinement adds ~50 % (bundled)
    sweep = cold + (points - 1) * warm
    macro_avg = sweep * n_mu / min(cores, n_mu)
    macro_band = sweep * patches * n_mu / cores
    coarse_band = points * coarse * patches * n_mu / cores
    coarsest_band = points * coarsest * patches * n_mu / cores
    rows = [
        ("micro: one h0 (32 steps, 256^2), measured", per_h0, "serial, 10 of the 100 h0"),
        ("micro: one patch pair, adaptive h0, measured", t_pair,
         f"{len(ad)} of {case.micro.h0_count} h0 on {cores} processes, error estimate "
         f"included; h0 bound {max(ad.meta['error_estimate']['h0'].values()):.1e}"),
        ("macro: cold 256^2 point, measured", cold, f"{speeds[0]:.2f} m/s"),
        ("macro: warm 256^2 point, measured", warm,
         f"{int(curve.iterations[1:].sum())} coupling iterations over {speeds.size - 1} "
         f"speeds {speeds[1]:.2f} -> {speeds[-1]:.2f} m/s"),
        ("paper twin, micro, all 100 h0 (extrapolated)", dense,
         f"{case.micro.h0_count} h0 x {patches} pairs / {cores} cores: the previous method"),
        ("paper twin, micro, adaptive h0 (extrapolated)", micro,
         f"{patches} pairs; {dense / micro:.1f}x faster than all 100 h0"),
        ("paper twin, Stribeck sweeps (extrapolated)", macro_avg,
         f"{points:.0f} points x {n_mu} viscosities / {cores} cores"),
        ("macro: warm 128^2 point of the band's grid, measured", coarse,
         f"the same speeds, every other node; {warm / coarse:.1f}x cheaper"),
        ("paper twin, patch band on the full grid (extrapolated)", macro_band,
         f"{patches * n_mu} single-patch sweeps / {cores} cores (band_grid = \"full\")"),
        ("paper twin, patch band at 128^2 (extrapolated)", coarse_band,
         f"{patches * n_mu} sweeps / {cores} cores (band_grid = \"coarse\"); "
         f"{macro_band / coarse_band:.1f}x faster than the full grid"),
        ("macro: warm 64^2 point of the band's grid, measured", coarsest,
         f"the same speeds, every fourth node; {warm / coarsest:.1f}x cheaper"),
        ("paper twin, patch band at 64^2 (extrapolated)", coarsest_band,
         f"{patches * n_mu} sweeps / {cores} cores (the default, \"coarsest\"); "
         f"{coarse_band / coarsest_band:.1f}x faster than at 128^2"),
        ("paper twin, whole (extrapolated)", micro + macro_avg + coarsest_band,
         f"{(micro + macro_avg + coarsest_band) / 60:.1f} min; "
         f"{(micro + macro_avg + coarse_band) / 60:.1f} min with the band at 128^2, "
         f"{(micro + macro_avg + macro_band) / 60:.0f} min on the full grid, "
         f"{(micro + macro_avg) / 60:.1f} min without a band"),
    ]
    return per_h0, rows, Check(dense > micro, f"adaptive h0 solves the paper twin's cells "
                                              f"{dense / micro:.1f}x faster than all 100 h0")
