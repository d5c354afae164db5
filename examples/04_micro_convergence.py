"""
Convergence of the flow factors
===============================

Convergence of the flow factors on the bundled sample patches: time steps and grid.

    python examples/04_micro_convergence.py [OUT] [--patches 1 3] [--workers 2] [--quick]

For each patch pair, at h0 = 0.1, 0.14, 0.3, 0.6 um:

- time: N_t = 4, 8, 16, 32, 64 at 128 px with the exact squeeze term (the default), against
  N_t = 128 (every pixel translation of the 128 px cell);
- grid: the periodic patches resampled to 32, 64, 128 px (N_t = 16) against the measured
  256 px, with the observed order from the last three grids;
- schemes: the paper's backward difference (32, 128 steps), the exact squeeze term (32) and
  the adaptive instants (time_tol 0.005) against the exact scheme at 128 steps, with times.

Prints relative differences of A11, b1, d1, C11, p_con, h_m and writes them to
``OUT/micro_convergence.json`` (default ``out/micro_convergence``) and ends in
``OUT/micro_convergence.png`` (largest error over h0 versus N_t and versus the grid).  About
10 minutes per patch on 2 cores; ``--quick`` (smoke test): patch 1 at 32 px, N_t 2, 4
against 8, grids 16, 32 against 64, no scheme study.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin.io.files import read_topography
from fem_twin.micro import homogenise
from fem_twin.topography import resample_cell
from fem_twin.topography.prepare import prepare_patch

SAMPLE = Path(sys.argv[0]).resolve().parent.parent / "meshes" / "sample"
H0 = np.array([0.1e-6, 0.14e-6, 0.3e-6, 0.6e-6])
NAMES = ("A11", "b1", "d1", "C11", "p_con", "h_m")
FULL = dict(cell=128, steps=(4, 8, 16, 32, 64), ref_steps=128, grids=(32, 64, 128),
            ref_grid=256, grid_steps=16, schemes=True)
QUICK = dict(cell=32, steps=(2, 4), ref_steps=8, grids=(16, 32), ref_grid=64, grid_steps=2,
             schemes=False)


def patch_pair(k, shape):
    pin = prepare_patch(read_topography(SAMPLE / f"patch_{k}_pin.npz"), (256, 256))
    disk = prepare_patch(read_topography(SAMPLE / f"patch_{k}_disk.npz"), (256, 256), upper=True)
    if shape != 256:
        pin, disk = resample_cell(pin, (shape, shape)), resample_cell(disk, (shape, shape))
    return pin, disk


def values(ff):
    return np.stack([ff.A[:, 0, 0], ff.b[:, 0], ff.d[:, 0], ff.C[:, 0, 0], ff.p_con, ff.h_m])


def relative(a, ref):
    """|a - ref| / |ref| per quantity and h0 (absolute for d1, which crosses zero: / max)."""
    scale = np.abs(ref)
    scale[2] = np.abs(ref[2]).max()
    return np.abs(a - ref) / np.maximum(scale, 1e-300)


def study(k, workers, size=FULL):
    out = {"time": {}, "grid": {}}
    pin, disk = patch_pair(k, size["cell"])
    runs = {nt: values(homogenise(pin, disk, H0, steps=nt, workers=workers))
            for nt in (*size["steps"], size["ref_steps"])}
    ref = size["ref_steps"]
    for nt in size["steps"]:
        out["time"][nt] = relative(runs[nt], runs[ref]).tolist()
        print(f"patch {k} N_t {nt:4d} vs {ref}: " + _row(out["time"][nt]), flush=True)
    if size["schemes"]:
        out["schemes"] = schemes(pin, disk, runs[ref], workers)
        for name, row in out["schemes"].items():
            print(f"patch {k} {name:>22} vs exact {ref}: " + _row(row["error"])
                  + f"  time x{row['time_ratio']:.2f} of exact 32", flush=True)
    top = size["ref_grid"]
    grids = {n: values(homogenise(*patch_pair(k, n), H0, steps=size["grid_steps"],
                                  workers=workers)) for n in (*size["grids"], top)}
    for n in size["grids"]:
        out["grid"][n] = relative(grids[n], grids[top]).tolist()
        print(f"patch {k} {n:4d} px vs {top}: " + _row(out["grid"][n]), flush=True)
    n1, n2 = size["grids"][-2:]
    d1, d2 = grids[n1] - grids[n2], grids[n2] - grids[top]
    with np.errstate(divide="ignore", invalid="ignore"):
        order = np.log2(np.abs(d1) / np.abs(d2))
    out["order"] = order.tolist()
    print(f"patch {k} observed order {n1}/{n2}/{top}: " + " ".join(
        f"{n} {np.nanmedian(o):.2f}" for n, o in zip(NAMES, order)), flush=True)
    out[f"values_{top}"] = grids[top].tolist()
    return out


def plot(result, path):
    """Largest relative error over h0 of each quantity versus N_t and versus the grid."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for k, res in result["patches"].items():
        for ax, kind, xlabel in zip(axes, ("time", "grid"), ("time steps $N_t$",
                                                             "cell grid [px]")):
            x = sorted(res[kind], key=int)
            err = np.array([np.asarray(res[kind][n]).max(axis=1) for n in x])
            for i, name in enumerate(NAMES[:5]):
                ax.loglog([int(n) for n in x], np.maximum(err[:, i], 1e-8), ".-",
                          label=f"patch {k} {name}")
            ax.set_xlabel(xlabel)
            ax.set_ylabel("max relative error over $h_0$")
            ax.grid(True, which="both", alpha=0.3)
    axes[0].set_title("time: against the finest $N_t$")
    axes[1].set_title("grid: against the finest grid")
    axes[1].legend(fontsize="x-small", ncol=2)
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


def schemes(pin, disk, reference, workers):
    """The paper's backward difference (32 and 128 steps), the exact scheme (32) and the
    adaptive instants (from 32, time_tol 0.005) against the exact scheme at 128 steps (every
    pixel translation of the 128 px cell), with wall times relative to exact 32."""
    variants = {"backward, 32 steps": dict(steps=32, time_derivative="backward",
                                           moving="upper"),
                "backward, 128 steps": dict(steps=128, time_derivative="backward",
                                            moving="upper"),
                "exact, 32 steps": dict(steps=32),
                "adaptive, tol 0.005": dict(steps=32, time_tol=0.005)}
    out, seconds = {}, {}
    for name, kw in variants.items():
        t0 = time.perf_counter()
        ff = homogenise(pin, disk, H0, workers=workers, error_estimate=False, **kw)
        seconds[name] = time.perf_counter() - t0
        out[name] = {"error": relative(values(ff), reference).tolist(),
                     "steps_used": ff.meta["steps_used"]}
    for name in out:
        out[name]["time_ratio"] = seconds[name] / seconds["exact, 32 steps"]
    return out


def _row(rel):
    rel = np.asarray(rel)
    return " ".join(f"{n} {rel[i].max() * 100:6.2f}%" for i, n in enumerate(NAMES))


def main():
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().split("\n")[0])
    parser.add_argument("out", nargs="?", default="out/micro_convergence", type=Path)
    parser.add_argument("--patches", type=int, nargs="+", default=[1, 3])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--quick", action="store_true", help="smoke-test size")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    size = QUICK if args.quick else FULL
    patches = [1] if args.quick else args.patches
    result = {"h0": H0.tolist(), "quantities": NAMES,
              "patches": {k: study(k, args.workers, size) for k in patches}}
    path = args.out / "micro_convergence.json"
    path.write_text(json.dumps(result, indent=1))
    print(f"wrote {path}")
    plot(result, args.out / "micro_convergence.png")


if __name__ == "__main__":
    main()
