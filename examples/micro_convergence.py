"""Convergence of the flow factors on the bundled sample patches: time steps and grid.

    python examples/micro_convergence.py [OUT] [--patches 1 3] [--workers 2]

For each patch pair, at h0 = 0.1, 0.14, 0.3, 0.6 um:
- time: N_t = 4, 8, 16, 32, 64 at 128 px with the exact squeeze term (the default), against
  N_t = 128 (every pixel translation of the 128 px cell);
- grid: the periodic patches resampled to 32, 64, 128 px (N_t = 16) against the measured
  256 px, with the observed order from the last three grids;
- schemes: the paper's backward difference (32, 128 steps), the exact squeeze term (32) and
  the adaptive instants (time_tol 0.005) against the exact scheme at 128 steps, with times.
Prints relative differences of A11, b1, d1, C11, p_con, h_m and writes them to
``OUT/micro_convergence.json`` (default ``out/micro_convergence``).  About 10 minutes per
patch on 2 cores.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from fem_twin.io.files import read_topography
from fem_twin.micro import homogenise
from fem_twin.topography import resample_cell
from fem_twin.topography.prepare import prepare_patch

SAMPLE = Path(__file__).resolve().parent.parent / "meshes" / "sample"
H0 = np.array([0.1e-6, 0.14e-6, 0.3e-6, 0.6e-6])
NAMES = ("A11", "b1", "d1", "C11", "p_con", "h_m")


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


def study(k, workers):
    out = {"time": {}, "grid": {}}
    pin, disk = patch_pair(k, 128)
    runs = {nt: values(homogenise(pin, disk, H0, n_steps=nt, workers=workers))
            for nt in (4, 8, 16, 32, 64, 128)}
    for nt in (4, 8, 16, 32, 64):
        out["time"][nt] = relative(runs[nt], runs[128]).tolist()
        print(f"patch {k} N_t {nt:4d} vs 128: " + _row(out["time"][nt]), flush=True)
    out["schemes"] = schemes(pin, disk, runs[128], workers)
    for name, row in out["schemes"].items():
        print(f"patch {k} {name:>22} vs exact 128: " + _row(row["error"])
              + f"  time x{row['time_ratio']:.2f} of exact 32", flush=True)
    grids = {n: values(homogenise(*patch_pair(k, n), H0, n_steps=16, workers=workers))
             for n in (32, 64, 128, 256)}
    for n in (32, 64, 128):
        out["grid"][n] = relative(grids[n], grids[256]).tolist()
        print(f"patch {k} {n:4d} px vs 256: " + _row(out["grid"][n]), flush=True)
    d1, d2 = grids[64] - grids[128], grids[128] - grids[256]
    with np.errstate(divide="ignore", invalid="ignore"):
        order = np.log2(np.abs(d1) / np.abs(d2))
    out["order"] = order.tolist()
    print(f"patch {k} observed order 64/128/256: " + " ".join(
        f"{n} {np.nanmedian(o):.2f}" for n, o in zip(NAMES, order)), flush=True)
    out["values_256"] = grids[256].tolist()
    return out


def schemes(pin, disk, reference, workers):
    """The paper's backward difference (32 and 128 steps), the exact scheme (32) and the
    adaptive instants (from 32, time_tol 0.005) against the exact scheme at 128 steps (every
    pixel translation of the 128 px cell), with wall times relative to exact 32."""
    variants = {"backward, 32 steps": dict(n_steps=32, time_derivative="backward"),
                "backward, 128 steps": dict(n_steps=128, time_derivative="backward"),
                "exact, 32 steps": dict(n_steps=32),
                "adaptive, tol 0.005": dict(n_steps=32, time_tol=0.005)}
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
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="out/micro_convergence", type=Path)
    parser.add_argument("--patches", type=int, nargs="+", default=[1, 3])
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    result = {"h0": H0.tolist(), "quantities": NAMES,
              "patches": {k: study(k, args.workers) for k in args.patches}}
    path = args.out / "micro_convergence.json"
    path.write_text(json.dumps(result, indent=1))
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
