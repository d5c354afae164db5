"""The ``peers`` group: the statistical mixed-lubrication model (Patir-Cheng flow and shear
factors, Greenwood-Tripp contact with McCool's summits: :mod:`fem_twin.peers`) beside the
twin, both against the deterministic reference (docs/peers.md).

1. The steady pad of the ``deterministic`` group (sample pair 1 at 32 px on the pin at
   rest, 1 MPa, 1 um crown, the bundled oil at 24 C) at eps = 1/2, 1/4, 1/8 over its 8
   speeds: load share and C_f of the deterministic solution, the twin and the peer.
2. Both bodies rough, the disk's roughness moving (the ``unsteady`` group's pads: pair 1,
   and the x3p-2 crops when ../shared is there, isoviscous oil on both sides), at
   eps = 1/4 over the knee's three speeds (the crops: its middle one), against
   :func:`fem_twin.macro.reference.time_resolved.solve_time_resolved`.
3. The bundled pin and the paper case run twice (``fem-twin run``'s pipeline), with
   ``[micro] model = "cells"`` and ``"average-flow"``: per viscosity the largest C_f
   difference, the knee speeds (half the load on asperities) and the slowest point's C_f,
   and each run's wall time.  ``$FEM_TWIN_BENCH_DIR`` keeps the runs (a finished one is read).

Times are per point (1, 2) or per run (3); the baseline is the peer's bundled run.  The
summary line gives both models' worst gaps to the deterministic pads and the curves' times;
checked: the twin's worst C_f gap below the average-flow model's.
"""

from __future__ import annotations

import os
import tempfile
import time
from dataclasses import replace

import deterministic as D  # the benchmarks' sibling modules
import numpy as np
import unsteady as U
from common import Check

from fem_twin.case import load_case
from fem_twin.stages import pipeline
from fem_twin.stribeck.analysis import knee_speed
from fem_twin.stribeck.curve import read_stribeck_csv
from fem_twin.studies import verification as V

DEFAULT = False
HERE = os.path.dirname(os.path.abspath(__file__))
#: the steady pad's tile counts
STEADY_TILES = (2, 4, 8)
#: the moving pads' tile count
MOVING_TILES = 4


def _point_rows(label, twin, peer, cfb):
    """One row per speed: share and C_f of the deterministic solution / twin / peer."""
    return [(f"{label}, U {a.speed:.3g} m/s", 0.0,
             f"share {a.share_det:.3f} / {a.share:.3f} / {b.share:.3f}, C_f {a.cf_det:.4f}: "
             f"twin {100 * a.cf_gap(cfb):+.2f}, peer {100 * b.cf_gap(cfb):+.2f} % C_f,b")
            for a, b in zip(twin, peer)]


def _steady(rows):
    """The steady pad's points at each eps; the finest eps's (twin, peer) pairs."""
    pad = V.sample_pad(D.SAMPLE, D.PIXELS)
    cfb = pad.settings.boundary_friction
    twin_ff, peer_ff = V.pad_factors(pad, D.H0), V.pad_average_flow(pad)
    for n in STEADY_TILES:
        det = V.deterministic_sweep(pad, n, D.SPEEDS)
        twin = V.compared(det, V.twin_sweep(pad, n, D.SPEEDS, twin_ff), n)
        peer = V.compared(det, V.twin_sweep(pad, n, D.SPEEDS, peer_ff), n)
        rows += _point_rows(f"steady pad, eps 1/{n}", twin, peer, cfb)
    return twin, peer, cfb


def _moving(rows):
    """Both bodies rough at eps 1/4: pair 1 over the knee, the x3p-2 crops at its middle."""
    twin_all, peer_all = [], []
    for name, pad in U.pads().items():
        if name == "pair 3":
            continue
        speeds = U.KNEE if name == "pair 1" else U.MIDDLE
        det = V.time_resolved_sweep(pad, MOVING_TILES, speeds)
        twin = V.compared(det, V.twin_sweep(pad, MOVING_TILES, speeds,
                                            V.pad_factors(pad, U.H0)), MOVING_TILES)
        peer = V.compared(det, V.twin_sweep(pad, MOVING_TILES, speeds,
                                            V.pad_average_flow(pad)), MOVING_TILES)
        rows += _point_rows(f"both rough, {name}, eps 1/{MOVING_TILES}", twin, peer,
                            pad.settings.boundary_friction)
        twin_all += twin
        peer_all += peer
    return twin_all, peer_all


def _run(case, name, keep):
    """Wall time [s] (None if read back) and curves of ``case`` run into ``keep``/name."""
    out = os.path.join(keep, name)
    seconds = None
    if not os.path.isfile(os.path.join(out, "summary.json")):
        t0 = time.perf_counter()
        pipeline.run(case, out, progress=False)
        seconds = time.perf_counter() - t0
    return seconds, read_stribeck_csv(os.path.join(out, "stribeck.csv"))


def _curves(rows, keep):
    """Both cases with the cells and the peer: the curves' gaps, knees and times."""
    times = {}
    for label, path in (("bundled pin", "pin_on_disk.toml"), ("paper case", "paper.toml")):
        case = load_case(os.path.join(HERE, "..", "examples", path))
        cfb = case.tribometer.boundary_friction
        runs = {model: _run(replace(case, micro=replace(case.micro, model=model)),
                            f"peers_{path[:-5]}_{model}", keep)
                for model in ("cells", "average-flow")}
        times[label] = {m: r[0] for m, r in runs.items()}
        for twin, peer in zip(runs["cells"][1], runs["average-flow"][1]):
            at = peer.speed
            cf = np.interp(np.log(at), np.log(twin.speed[::-1]),
                           twin.friction_coefficient[::-1])
            gap = (peer.friction_coefficient - cf) / cfb
            k = int(np.argmax(np.abs(gap)))
            rows.append((f"{label}, mu_0 {twin.viscosity:g} Pa s", 0.0,
                         f"peer - twin at most {100 * gap[k]:+.1f} % C_f,b (at {at[k]:.3g} "
                         f"m/s); knee {knee_speed(twin):.3g} / {knee_speed(peer):.3g} m/s; "
                         f"slowest C_f {twin.friction_coefficient[np.argmin(twin.speed)]:.4f} / "
                         f"{peer.friction_coefficient[np.argmin(peer.speed)]:.4f}"))
    return times


def run():
    """The rows of the module docstring, the summary line and the check."""
    rows = []
    twin, peer, cfb = _steady(rows)
    twin_moving, peer_moving = _moving(rows)
    pairs_twin, pairs_peer = twin + twin_moving, peer + peer_moving
    with tempfile.TemporaryDirectory() as tmp:
        times = _curves(rows, os.environ.get("FEM_TWIN_BENCH_DIR") or tmp)
    for label, t in times.items():
        rows.append((f"{label}: run time, cells / average flow", 0.0,
                     " / ".join("read back" if s is None else f"{s:.0f} s" for s in t.values())))
    worst = {k: max(abs(p.cf_gap(cfb)) for p in pairs) for k, pairs in
             (("peer", pairs_peer), ("twin", pairs_twin))}
    bundled = times["bundled pin"]
    summary = (f"average flow vs deterministic: worst |C_f - C_f,det| = "
               f"{100 * worst['peer']:.2f} % C_f,b; twin: {100 * worst['twin']:.2f} % C_f,b; "
               f"curve time average flow {_seconds(bundled['average-flow'])}, twin "
               f"{_seconds(bundled['cells'])}")
    return bundled["average-flow"] or 1.0, rows, summary, Check(
        worst["twin"] < worst["peer"], f"the twin's worst |C_f - C_f,det| "
                                       f"{100 * worst['twin']:.2f} % C_f,b below the average-flow "
                                       f"model's {100 * worst['peer']:.2f} %")


def _seconds(value) -> str:
    """A run's wall time, or that it was read back."""
    return "read back" if value is None else f"{value:.0f} s"


def draw(keep, path):
    """The bundled pin's curves of both models from the runs kept in ``keep`` (C_f and the
    asperities' share of the load against speed) into ``path``: the figure of
    docs/peers.md (``python benchmarks/peers.py KEEP docs/_static/peers_bundled.png``)."""
    import matplotlib.pyplot as plt
    fig, (cf, share) = plt.subplots(1, 2, figsize=(10, 4), sharex=True)
    for model, style in (("cells", "o-"), ("average-flow", "s--")):
        curves = read_stribeck_csv(os.path.join(keep, f"peers_pin_on_disk_{model}",
                                                "stribeck.csv"))
        for curve, colour in zip(curves, ("C0", "C3")):
            label = f"{'twin' if model == 'cells' else 'average flow'}, " \
                    f"mu_0 {curve.viscosity:g} Pa s"
            cf.plot(curve.speed, curve.friction_coefficient, style, color=colour, ms=4,
                    label=label)
            share.plot(curve.speed, curve.contact_load_fraction, style, color=colour, ms=4)
    cf.set(xscale="log", xlabel="U [m/s]", ylabel="C_f", title="bundled pin")
    share.axhline(0.5, color="grey", lw=0.8)
    share.set(xscale="log", xlabel="U [m/s]", ylabel="asperity share of the load")
    cf.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    import sys
    draw(*sys.argv[1:3])
