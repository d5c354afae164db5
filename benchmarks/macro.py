"""Group ``macro``: one operating point (150 N, 0.066 Pa s, 0.1 and 1 m/s), cold start, FE
and FVM, and FVM with the paper's FBNS inner solver.

Sample pin 1 on disk 1 at 128^2 and 256^2; flow factors of sample patch 1 at 64^2 (30 h0 x
8 steps, computed first).  Baseline: the FVM point at 128^2, 1 m/s.  Checked: the goal, every
FE and FVM point at 256^2 converged in under 20 s.  An FBNS point that fails says so in its
row (the paper's inner solver is an option, not the default).
"""

from __future__ import annotations

import time

import numpy as np
from common import Check, macro_factors, macro_gap

from fem_twin.errors import FemTwinError

DEFAULT = True
#: the goal for a converged 256^2 point [s]
GOAL = 20.0


def run():
    from fem_twin.macro import Lubricant, MacroSettings, solve_mixed

    ff = macro_factors()
    rows, base, fine = [], None, []
    for n in (128, 256):
        gap, spacing, face = macro_gap(n)
        for speed in (1.0, 0.1):
            cf = {}
            for method in ("fvm", "fe"):
                t0 = time.perf_counter()
                r = solve_mixed(gap, spacing, ff, load=150.0, speed=speed, face=face,
                                lubricant=Lubricant(0.066), settings=MacroSettings(method=method))
                t = time.perf_counter() - t0
                base = base or t
                cf[method] = r.friction_coefficient
                if n == 256:
                    fine.append(t)
                newton = int(r.history[:, 6].sum())
                rows.append((f"{method.upper()} {n}^2, U = {speed} m/s", t,
                             f"{r.iterations} it, {newton} Newton steps, "
                             f"C_f {r.friction_coefficient:.5f}"))
            rows.append(("  FE / FVM time; |C_f,dev|", rows[-1][1] / rows[-2][1],
                         f"{abs(cf['fe'] - cf['fvm']) / 0.19245:.2e}"))
            t0 = time.perf_counter()
            label = f"FVM + FBNS (paper's inner solver) {n}^2, U = {speed}"
            try:
                r = solve_mixed(gap, spacing, ff, load=150.0, speed=speed, face=face,
                                lubricant=Lubricant(0.066),
                                settings=MacroSettings(method="fvm", complementarity="fb"))
            except (ArithmeticError, np.linalg.LinAlgError, FemTwinError) as error:
                rows.append((label, time.perf_counter() - t0,
                             f"failed: {type(error).__name__}: {error}"))
                continue
            rows.append((label, time.perf_counter() - t0,
                         f"{r.iterations} it, {int(r.history[:, 6].sum())} Newton steps, "
                         f"C_f {r.friction_coefficient:.5f}"))
    return base, rows, Check(max(fine) < GOAL, f"every FE and FVM point at 256^2 under "
                                               f"{GOAL:.0f} s (slowest {max(fine):.1f} s)")
