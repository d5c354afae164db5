"""
FE against FVM flow factors
===========================

FE against FVM flow factors on the bundled roughness patches at full resolution (issue 6).

    python examples/03_fe_fvm_flow_factors.py [OUT] [--steps N] [--workers W] [--quick]

Homogenises each of the six bundled patch pairs (256 x 256 px cut, as the bundled case)
with both methods at h0 = 0.1, 0.15, 0.3, 0.6, 1 um and N sliding steps (default 8), and
writes OUT/fe_fvm_flow_factors.csv with, per patch (and for the patch average) and h0,
the differences of
:func:`fem_twin.studies.compare.flow_factor_differences`: ``max |Delta A| / max |A|``
(likewise b, C),
``|Delta d|`` (absolute, d is O(1) and crosses zero) and ``|Delta h_m| / h0``.  About 2 minutes on
2 cores with 8 steps, 10 minutes with the paper's 32.  The factors themselves are kept as
OUT/patch_<k>_<method>.npz (``FlowFactors.load``), so a rerun only recomputes what is
missing.

Then FE and FVM against a converged reference (FE on the cell refined 2x to 512^2 with
twice the steps) for patches 1 and 3 (``--reference-patches``; about 10 minutes more).

Last, for sample patch 3 at h0 = 0.15 um (18 % contact, the first, steady step), it solves
the cell problems again on the gap refined 2x and 4x by bilinear interpolation: the table
shows how far each method is from the continuum of that gap, and how the FVM's two face
rules compare (``face="bilinear"``, the default, against the two-point ``"arithmetic"``).
"""

import argparse
import sys
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin.fvm import CellSolverFV
from fem_twin.io.files import read_topography
from fem_twin.io.table import write_csv
from fem_twin.micro import CellSolver, FlowFactors, average, homogenise
from fem_twin.micro.sliding import CellSettings, sliding_contacts, sliding_pass
from fem_twin.studies.compare import flow_factor_differences
from fem_twin.topography import resample_cell
from fem_twin.topography.prepare import prepare_patch

SAMPLE = Path(sys.argv[0]).resolve().parent.parent / "meshes" / "sample"
H0 = np.array([0.1e-6, 0.15e-6, 0.3e-6, 0.6e-6, 1e-6])


def patch_pair(k, shape=(256, 256), resolution=None):
    pin = prepare_patch(read_topography(SAMPLE / f"patch_{k}_pin.npz"), shape)
    disk = prepare_patch(read_topography(SAMPLE / f"patch_{k}_disk.npz"), shape, upper=True)
    if resolution:
        pin, disk = resample_cell(pin, resolution), resample_cell(disk, resolution)
    return pin, disk


def bilinear_refinement(h, f):
    """Periodic bilinear interpolation of a pixel field by an integer factor ``f``."""
    ny, nx = h.shape
    t = np.arange(f) / f
    hx = np.stack([(1 - s) * h + s * np.roll(h, -1, axis=1) for s in t], axis=2)
    hx = hx.reshape(ny, nx * f)
    return np.stack([(1 - s) * hx + s * np.roll(hx, -1, axis=0) for s in t],
                    axis=1).reshape(ny * f, nx * f)


def factors(moments):
    """A11, A22, A12, b1, C11, d1 of one step (eqs 13-16 without the time average)."""
    hm = moments["h"]
    A = moments["h3_grad"] / hm ** 3
    return [A[0, 0], A[1, 1], A[0, 1], 1 - moments["h3_g1"][0] / hm,
            moments["h_grad"][0, 0] / hm, moments["h_g1"][0] * hm]


def refinement_study(k=3, h0=0.15e-6):
    pin, disk = patch_pair(k)
    settings = CellSettings(steps=8)
    shapes = sliding_pass(pin.heights, disk.heights, pin.spacing, settings).shapes
    contact = sliding_contacts(shapes[:1], pin.spacing, settings, h0)[0]
    print(f"\npatch {k}, h0 = {h0 * 1e6:.2f} um, first step, "
          f"contact fraction {contact.contact_fraction:.3f}")
    print(f"{'refine':>6} {'method':>14} " + " ".join(
        f"{n:>8}" for n in ("A11", "A22", "A12", "b1", "C11", "d1")))
    solvers = {"FE": CellSolver, "FVM bilinear": CellSolverFV,
               "FVM arithmetic": lambda s, d: CellSolverFV(s, d, face="arithmetic")}
    for f in (1, 2, 4):
        gap = bilinear_refinement(contact.gap, f)
        spacing = tuple(s / f for s in pin.spacing)
        for name, make in solvers.items():
            row = factors(make(gap.shape, spacing).solve(gap).moments)
            print(f"{f:>6} {name:>14} " + " ".join(f"{x:8.5f}" for x in row), flush=True)


def main():
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().split("\n")[0])
    parser.add_argument("out", nargs="?", default="fe_fvm")
    parser.add_argument("--steps", type=int, default=8)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--reference-patches", type=int, nargs="*", default=[1, 3],
                        help="patches also computed at 512^2 with twice the steps")
    parser.add_argument("--quick", action="store_true", help="smoke-test size")
    args = parser.parse_args()
    if args.quick:
        args.steps, args.reference_patches = 2, []
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows, worst, patches = [], {}, {"fe": [], "fvm": []}
    print(f"{'patch':>7} {'h0 [um]':>8} {'A':>8} {'b':>8} {'C':>8} {'|dd|':>8} {'h_m':>8}"
          f" {'FE/FVM time':>11}")
    for k in ([1, "average"] if args.quick else [*range(1, 7), "average"]):
        if k == "average":
            fe, fv, ratio = average(patches["fe"]), average(patches["fvm"]), float("nan")
        else:
            pin, disk = patch_pair(k, resolution=(32, 32) if args.quick else None)
            seconds = {}
            for method in ("fe", "fvm"):
                path = out / f"patch_{k}_{method}_{args.steps}steps.npz"
                t0 = time.perf_counter()
                if path.is_file():                 # reloaded: no time to report
                    ff, t0 = FlowFactors.load(path), float("nan")
                else:
                    ff = homogenise(pin, disk, H0, steps=args.steps, method=method,
                                    workers=args.workers)
                    ff.save(path)
                seconds[method] = time.perf_counter() - t0
                patches[method].append(ff)
            fe, fv = patches["fe"][-1], patches["fvm"][-1]
            ratio = seconds["fe"] / seconds["fvm"]
        diff = flow_factor_differences(fe, fv)
        for i, h0 in enumerate(H0):
            row = {"patch": k, "h0": h0, **{key: float(diff[key][i])
                                            for key in ("A", "b", "C", "d", "h_m")}}
            rows.append(row)
            for key in ("A", "b", "C", "d"):
                worst[key] = max(worst.get(key, 0.0), row[key])
            print(f"{k:>7} {h0 * 1e6:8.2f} " + " ".join(
                f"{row[key] * (1 if key == 'd' else 100):7.3f}{' ' if key == 'd' else '%'}"
                for key in ("A", "b", "C", "d", "h_m")) + f" {ratio:11.2f}", flush=True)
    write_csv(out / "fe_fvm_flow_factors.csv",
              {("h0_m" if k == "h0" else k): [r[k] for r in rows] for k in rows[0]})
    print("worst: " + ", ".join(f"{k} {v * (1 if k == 'd' else 100):.3f}"
                                + ("" if k == "d" else " %") for k, v in worst.items()))
    plot(rows, out / "fe_fvm_flow_factors.png")
    if not args.quick:
        against_reference(out, args, patches)
        refinement_study()


def plot(rows, path):
    """FE-FVM differences of A, b (relative) and d (absolute) versus h0, one line a patch."""
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.6), constrained_layout=True)
    for ax, key, label in zip(axes, ("A", "b", "d"), ("max |ΔA| / max |A|",
                                                      "max |Δb| / max |b|", "|Δd|")):
        for k in dict.fromkeys(r["patch"] for r in rows):
            sel = [r for r in rows if r["patch"] == k]
            ax.semilogy([r["h0"] * 1e6 for r in sel], [max(r[key], 1e-12) for r in sel],
                        "o-" if k == "average" else ".-", lw=2 if k == "average" else 1,
                        label=f"patch {k}")
        ax.set_xlabel("$h_0$ [µm]")
        ax.set_title(f"FE - FVM: {label}")
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize="small")
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


def against_reference(out, args, patches):
    """FE and FVM against a converged reference: FE on the cell refined 2x (512^2, periodic
    bilinear) with twice the steps, for the patches of ``--reference-patches``."""
    print(f"\nagainst the reference (FE, 512^2, {2 * args.steps} steps): "
          "max |Delta A| / max |A|, likewise b, |Delta d|")
    print(f"{'patch':>7} {'h0 [um]':>8} {'FE A':>8} {'FVM A':>8} {'FE b':>8} {'FVM b':>8}"
          f" {'FE |dd|':>8} {'FVM |dd|':>8}")
    for k in args.reference_patches:
        path = out / f"patch_{k}_reference_{2 * args.steps}steps.npz"
        if path.is_file():
            ref = FlowFactors.load(path)
        else:
            pin, disk = (resample_cell(t, (512, 512)) for t in patch_pair(k))
            ref = homogenise(pin, disk, H0, steps=2 * args.steps, workers=args.workers,
                             error_estimate=False)
            ref.save(path)
        fe = flow_factor_differences(patches["fe"][k - 1], ref)
        fv = flow_factor_differences(patches["fvm"][k - 1], ref)
        for i, h0 in enumerate(H0):
            print(f"{k:>7} {h0 * 1e6:8.2f} " + " ".join(
                f"{d[key][i] * (1 if key == 'd' else 100):7.3f}{' ' if key == 'd' else '%'}"
                for key in ("A", "b", "d") for d in (fe, fv)), flush=True)


if __name__ == "__main__":
    main()
