"""Group ``estimate-paper``: the ``estimate`` group on the paper case (256^2, 100 h0, 32
steps; reference 512^2, 199 h0, 128 steps: a few hours on 2 cores, kept in
``$FEM_TWIN_BENCH_DIR`` and read on later runs).  Checked as ``estimate``."""

from __future__ import annotations

import estimate

DEFAULT = False


def run():
    return estimate.run("paper.toml")
