"""Run the benchmarks and print wall times with ratios to a same-run baseline.

    python benchmarks/run.py [GROUP ...]
"""

from __future__ import annotations

import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from fem_twin import read_topography  # noqa: E402
from fem_twin import topography as tp  # noqa: E402
from fem_twin.topography.prepare import prepare_pin  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLE = os.path.join(HERE, "..", "meshes", "sample")


def best_of(fn, repeat=3):
    """Minimum wall time of ``repeat`` calls [s] and the last result."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def bench_topography():
    """Macro pin reconstruction at 500^2 against one rfft2+irfft2 of the same grid."""
    raw = read_topography(os.path.join(SAMPLE, "pin_1.npz"))
    z = np.nan_to_num(raw.heights)
    base, _ = best_of(lambda: np.fft.irfft2(np.fft.rfft2(z), s=z.shape), 5)
    rows = [("baseline: rfft2+irfft2 500^2", base, "")]
    t_fill, filled = best_of(lambda: tp.fill_defects(raw))
    rows.append(("fill_defects (Laplace) 500^2", t_fill, f"{(~raw.valid).sum()} holes"))
    t_filt, _ = best_of(lambda: tp.gaussian_filter(filled, 9))
    rows.append(("gaussian_filter 9 px 500^2", t_filt, ""))
    t_ref, _ = best_of(lambda: tp.refine(filled, 4))
    rows.append(("refine 500 -> 1997", t_ref, ""))
    t_pin, _ = best_of(lambda: prepare_pin(raw))
    rows.append(("prepare_pin (whole chain, 256^2 out)", t_pin, ""))
    return base, rows


GROUPS = {"topography": bench_topography}


def main(argv):
    groups = argv or list(GROUPS)
    for name in groups:
        base, rows = GROUPS[name]()
        print(f"\n## {name}")
        print(f"| {'case':42s} | {'time [s]':>9s} | {'x baseline':>10s} | notes")
        print(f"|{'-' * 44}|{'-' * 11}|{'-' * 12}|------")
        for label, t, note in rows:
            print(f"| {label:42s} | {t:9.4f} | {t / base:10.1f} | {note}")


if __name__ == "__main__":
    main(sys.argv[1:])
