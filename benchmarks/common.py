"""What the benchmark groups share: a group's checked line (:class:`Check`), the bundled
sample's maps, the best of repeated timings, a fresh ``fem-twin run`` of a case file, and
the macro groups' inputs (sample pin 1 on disk 1, patch 1's flow factors)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fem_twin import read_topography
from fem_twin import topography as tp
from fem_twin.topography import pin_face
from fem_twin.topography.prepare import prepare_pin

SAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "meshes", "sample")


@dataclass(frozen=True)
class Check:
    """A group's last line: ``text`` names the criterion and what the run measured for it;
    ``holds`` True or False, or None where there was nothing to check."""

    holds: bool | None
    text: str

    def __post_init__(self):        # a numpy bool would not go into the results' JSON
        if self.holds is not None:
            object.__setattr__(self, "holds", bool(self.holds))

    def line(self) -> str:
        if self.holds is None:
            return f"check: {self.text}: skipped"
        return f"check: {self.text}: holds" if self.holds else f"FAILED: {self.text}"


def best_of(fn, repeat=3):
    """Minimum wall time of ``repeat`` calls [s] and the last result."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def run_case(case: Path, out: Path, cwd: Path, env=None) -> tuple[float, dict, str]:
    """Wall time [s], ``summary.json`` and standard error of one fresh ``fem-twin run`` of
    the case file ``case`` into ``out``, in a process of its own (in ``cwd``, with ``env``)."""
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "fem_twin.cli", "run", str(case), "-o",
                           str(out), "--no-progress", "--yes"], check=True,
                          capture_output=True, text=True, cwd=cwd, env=env)
    return (time.perf_counter() - start, json.loads((out / "summary.json").read_text()),
            done.stderr)


def macro_factors():
    """Flow factors of sample patch 1 at 64^2, 30 h0 x 8 steps: the macro groups' input."""
    from fem_twin.micro import homogenise
    from fem_twin.topography.prepare import prepare_patch
    low = tp.resample_cell(prepare_patch(read_topography(os.path.join(SAMPLE, "patch_1_pin.npz"))),
                           (64, 64))
    up = tp.resample_cell(prepare_patch(read_topography(os.path.join(SAMPLE, "patch_1_disk.npz")),
                                        upper=True), (64, 64))
    return homogenise(low, up, np.geomspace(2e-8, 1e-6, 30), steps=8)


def macro_gap(n):
    """Gap, spacing and pin face of sample pin 1 on disk 1 at n^2."""
    from fem_twin.topography.prepare import MacroOptions, prepare_disk
    opts = MacroOptions(resolution=(n, n))
    pin = prepare_pin(read_topography(os.path.join(SAMPLE, "pin_1.npz")), opts)
    disk = prepare_disk(read_topography(os.path.join(SAMPLE, "disk_1.npz")), opts)
    return disk.heights - pin.heights, pin.spacing, pin_face(pin, opts.holder_height)


def sample_patch_pair(n=256):
    """Sample patch pair 3 prepared at n^2 (pin, disk): the micro and contact groups' cell."""
    from fem_twin.topography.prepare import prepare_patch
    pin = prepare_patch(read_topography(os.path.join(SAMPLE, "patch_3_pin.npz")), (n, n))
    disk = prepare_patch(read_topography(os.path.join(SAMPLE, "patch_3_disk.npz")), (n, n),
                         upper=True)
    return pin, disk
