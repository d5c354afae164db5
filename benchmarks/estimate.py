"""Group ``estimate``: the C_f error estimate against refined runs, in total and part by part,
on the bundled pin; ``estimate-paper`` and ``estimate-ball`` run it on the paper case and
the bundled ball.

    FEM_TWIN_BENCH_DIR=DIR python benchmarks/run.py estimate    # about 6 min on 2 cores

The case with its first patch pair (``estimate-pairs``, ``estimate-ball-pairs``: every
pair, whose average the run reads), its first viscosity, isothermal, no speed refinement
and no band.  The reference refines everything at once: the macro grid twice as fine (a
ball's ``[macro] grid`` 2n - 1), the cells on the patches' own pixels (the measurement
holds no finer surface; twice as fine where that is finer), four times the steps, twice
the h0 candidates (a pin's and a ball's every one of them).  Each part's own change refines that
alone.  Rows, per speed: the estimate (``cf_err``), the change to the reference (the truth)
and their ratio, the effectivity (``ok``: 1 to 3, or both under 0.05 % C_f,b); then each
part's signed estimate over its own signed change (negative: the wrong sign), and the film
sensitivity; and, from a third run on the macro grid coarsened by two, the macro order
observed at each speed and the truth against the limit (the reference's own macro error
extrapolated at that order, :func:`limit_error`) with the bound over it.  Checked: the
estimate is nowhere below the truth (or both are under the floor).
``$FEM_TWIN_BENCH_DIR`` keeps the refined runs and reads a finished one again; the base run
is always made anew."""

from __future__ import annotations

import os
import shutil
import time
from dataclasses import replace

import numpy as np
from common import Check

DEFAULT = False
HERE = os.path.dirname(os.path.abspath(__file__))
#: the truth's floor: below it on both sides a speed is ``ok`` [fraction of C_f,b]
FLOOR = 5e-4
#: the parts refined one at a time, each against its own part of the estimate
PARTS = ("macro", "time", "grid", "h0")
#: the macro orders taken as asymptotic in the extrapolation to the limit (the scheme's is 2)
ORDERS = (0.5, 4.0)


def _refined(case, parts, every_h0):
    """``case`` with the ``parts`` refined: ``"macro"`` (a pin's maps resampled twice as
    fine, a ball's grid 2n - 1), ``"grid"`` (cells on the patches' own pixels, or twice as
    fine where that is finer), ``"time"`` (four times the steps), ``"h0"`` (twice the
    candidates, all of them solved with ``every_h0``)."""
    pre, micro, macro = case.preprocessing, case.micro, case.macro
    if "macro" in parts and case.tribometer.ball:
        macro = replace(macro, grid=2 * macro.grid - 1)
    elif "macro" in parts:
        pre = replace(pre, resolution=tuple(2 * n for n in pre.resolution))
    if "grid" in parts:                                 # the patches' own pixels, or 2n
        micro = replace(micro, resolution=tuple(max(2 * n, own) for n, own in zip(
            micro.resolution, case.geometry.patch_shape)))
    if "time" in parts:
        micro = replace(micro, steps=4 * micro.steps)
    if "h0" in parts:
        micro = replace(micro, h0_count=2 * (micro.h0_count - 1) + 1,
                        h0_tol=0.0 if every_h0 else micro.h0_tol)
    return replace(case, preprocessing=pre, micro=micro, macro=macro)


def _coarsened(case):
    """``case`` with the macro grid coarsened by two (a pin's maps at half the resolution, a
    ball's grid (n + 1) / 2): the third grid of the macro order."""
    pre, macro = case.preprocessing, case.macro
    if case.tribometer.ball:
        macro = replace(macro, grid=(macro.grid + 1) // 2)
    else:
        pre = replace(pre, resolution=tuple(n // 2 for n in pre.resolution))
    return replace(case, preprocessing=pre, macro=macro)


def limit_error(coarse, base, fine):
    """``(order, error)``: the macro order observed at one speed from C_f on three grids
    (``coarse``, ``base``, ``fine``, each twice as fine), and the ``fine`` grid's own error
    C_f(fine) - C_f(limit) it gives, ``(C_f(base) - C_f(fine)) / (2^p - 1)``; None where
    the changes differ in sign or the order lies outside ``ORDERS`` (no asymptotic range)."""
    d1, d2 = coarse - base, base - fine
    if d1 * d2 <= 0:
        return None
    order = float(np.log2(d1 / d2))
    return (order, d2 / (2 ** order - 1)) if ORDERS[0] <= order <= ORDERS[1] else None


def run_kept(case, name, reuse=True):
    """Run ``case`` into ``$FEM_TWIN_BENCH_DIR/name`` (or a temporary folder, then read);
    ``(wall time [s], curve, signed estimate parts by speed)``.  ``reuse``: a kept folder
    holding a finished run is read as it is (its wall time from its summary.json), even when
    the code has changed since; otherwise the folder is made anew."""
    import json
    import tempfile

    from fem_twin.stages import pipeline
    from fem_twin.stribeck.curve import read_stribeck_csv

    keep = os.environ.get("FEM_TWIN_BENCH_DIR")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(keep, name) if keep else tmp
        summary = os.path.join(out, "summary.json")
        if reuse and os.path.isfile(summary):
            seconds = json.load(open(summary))["wall_time_s"]
        else:
            if keep and not reuse:
                shutil.rmtree(out, ignore_errors=True)
            t0 = time.perf_counter()
            pipeline.run(case, out, progress=False)
            seconds = time.perf_counter() - t0
        return (seconds, read_stribeck_csv(os.path.join(out, "stribeck.csv"))[0],
                _signed_parts(out, case.tribometer.ball))


def _signed_parts(folder, ball) -> dict:
    """``{speed: signed estimate parts}`` of a run's main points (their checkpoints), over the
    curve's speed (a ``ball``'s entrainment)."""
    from fem_twin.stribeck.sweep import point_files, readable_meta

    out = {}
    for path in point_files(os.path.join(folder, "stribeck", "checkpoints")):
        read = readable_meta(path)
        if read and "signed" in read[1].get("error_estimate", {}):
            scalars, meta = read            # a ball's curve is over its entrainment speed
            speed = meta["entrainment"] if ball else scalars["speed"]
            out[float(speed)] = meta["error_estimate"]["signed"]
    return out


def subset_case(case, viscosity, pairs=1):
    """The case's first ``pairs`` patch pairs (None: all) at ``viscosity``, isothermal, no
    refinement, no band."""
    return replace(case, geometry=replace(case.geometry, patches=case.geometry.patches[:pairs]),
                   thermal=replace(case.thermal, model="none"),
                   lubricant=replace(case.lubricant, viscosities=(viscosity,),
                                     temperatures=case.lubricant.temperatures[:1]),
                   sweep=replace(case.sweep, refine=0), measured=(),
                   run=replace(case.run, patch_band=False))


def run(case_file="pin_on_disk.toml", viscosity=0.066, pairs=1):
    """The estimate of ``case_file`` (in examples/) at ``viscosity`` [Pa s] on its first
    ``pairs`` patch pairs (None: all) against its reference and each part against its own
    change (module docstring).  Baseline: the base run."""
    from fem_twin.case import load_case

    case = subset_case(load_case(os.path.join(HERE, "..", "examples", case_file)), viscosity,
                       pairs)
    every_h0 = case_file != "paper.toml"
    n = len(case.geometry.patches)
    stem = os.path.splitext(case_file)[0] + ("" if pairs == 1 else f"_{n}_pairs")
    t_base, base, signed = run_kept(case, f"{stem}_base", reuse=False)
    fine = _refined(case, PARTS, every_h0)
    t_ref, ref, _ = run_kept(fine, f"{stem}_reference")
    own = {part: run_kept(_refined(case, (part,), every_h0), f"{stem}_{part}")
           for part in PARTS}
    cb = case.tribometer.boundary_friction
    rows = [(f"baseline: {stem}, {n} patch pair{'s' * (n > 1)}, 1 viscosity", t_base, ""),
            (f"reference: all refined ({fine.micro.steps} steps, {fine.micro.h0_count} h0)",
             t_ref, "")]
    rows += [(f"{part} refined alone", t, "") for part, (t, *_) in own.items()]
    t_coarse, coarse, _ = run_kept(_coarsened(case), f"{stem}_macro_coarse")
    rows.append(("macro coarsened by two (the macro order)", t_coarse, ""))
    own = {part: c for part, (_, c, _) in own.items()}
    speeds = [_speed(i, base, ref, own, next((v for k, v in signed.items()
                                              if np.isclose(k, u, rtol=1e-6)), {}), cb,
                     coarse.friction_coefficient[i])
              for i, u in enumerate(base.speed)]
    rows += [x["row"] for x in speeds]
    lines = []
    for part in PARTS:
        r = [x["ratios"][part] for x in speeds if part in x["ratios"]]
        lines.append(f"{part}: its estimate over its own change where that exceeds 0.05 % "
                     "C_f,b: " + (f"{min(r):.2f} to {max(r):.2f}, the wrong sign at "
                                  f"{sum(x < 0 for x in r)} of {len(r)} speeds"
                                  if r else "nowhere above"))
    r = [x["signed"] for x in speeds if "signed" in x]
    lines.append("signed estimate over the signed truth where that exceeds 0.05 % C_f,b: "
                 + (f"{min(r):.2f} to {max(r):.2f}, within 1-3 at "
                    f"{sum(1 <= x <= 3 for x in r)} of {len(r)}" if r else "nowhere above"))
    r = [x["limit"] for x in speeds if "limit" in x]
    lines.append("against the limit (the reference's macro error at the observed order): the "
                 "bound over the truth where that exceeds 0.05 % C_f,b: " + (
                     f"{min(r):.2f} to {max(r):.2f}, within 1-3 at "
                     f"{sum(1 <= x <= 3 for x in r)} of {len(r)}; no asymptotic order at "
                     f"{sum('no order' in x['row'][2] for x in speeds)} of {len(speeds)} "
                     "speeds" if r else "nowhere above"))
    tol = case.sweep.error_tolerance
    above = [sum(x["sizes"][k] > tol * cb for x in speeds) for k in range(3)]
    lines.append("above the tolerance {:.2%} C_f,b: the bound at {}, the signed estimate at "
                 "{}, the truth at {} speeds".format(tol, *above))
    below = sum(x["below"] for x in speeds)
    return t_base, rows, *lines, Check(below == 0, (
        f"the C_f estimate below the truth at {below} of {base.speed.size} speeds "
        f"(within 1-3 or both under 0.05 % C_f,b at {sum(x['ok'] for x in speeds)})"))


def _speed(i, base, ref, own, parts, cb, coarse):
    """Speed ``i`` of the ``base`` curve against the ``ref`` curve and each part's ``own``
    run, with the base's signed estimate ``parts``: its row, whether the bound ``cf_err``
    is ``ok`` or ``below`` the truth, the sizes of bound, signed estimate and truth, the
    ratios of the signed estimate and of each part to their truths (where above 0.05 %),
    and the bound over the truth against the limit (``coarse``: C_f on the macro grid
    coarsened by two, :func:`limit_error`)."""
    from fem_twin.macro.estimate import signed_total

    u, cf, err = base.speed[i], base.friction_coefficient[i], base.friction_error[i]
    truth = cf - ref.friction_coefficient[i]
    estimate = signed_total({"signed": parts}) if parts else np.nan
    floor = err < FLOOR * cb and abs(truth) < FLOOR * cb
    ok = floor or 1 <= err / abs(truth) <= 3
    out = {"ok": ok, "below": not floor and err < abs(truth), "ratios": {},
           "sizes": (err, abs(estimate), abs(truth))}
    if abs(truth) >= FLOOR * cb:
        out["signed"] = estimate / truth
    notes = []
    for part in PARTS:
        change = cf - own[part].friction_coefficient[i]
        est = parts.get(part, np.nan)
        notes.append(f"{part} {est / cb:+.3%}/{change / cb:+.3%}")
        if abs(change) >= FLOOR * cb:
            out["ratios"][part] = est / change
    notes.append(f"film {parts.get('film', np.nan) / cb:+.3%}")
    limit = limit_error(coarse, cf, own["macro"].friction_coefficient[i])
    if limit is None:
        notes.append("against the limit: no order")
    else:
        to_limit = truth + limit[1]
        notes.append(f"against the limit (order {limit[0]:.2f}): truth {to_limit / cb:+.3%}, "
                     f"effectivity {err / abs(to_limit):.2f}")
        if abs(to_limit) >= FLOOR * cb:
            out["limit"] = err / abs(to_limit)
    out["row"] = (f"  {u:.4g} m/s: C_f {cf:.5f}, reference {ref.friction_coefficient[i]:.5f}",
                  0.0, f"estimate {err / cb:.3%} (signed {estimate / cb:+.3%}), truth "
                       f"{truth / cb:+.3%} C_f,b, effectivity {err / abs(truth):.2f} "
                       f"{'ok' if ok else 'OUTSIDE'}; part / own change: {', '.join(notes)}")
    return out
