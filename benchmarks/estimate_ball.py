"""Group ``estimate-ball``: the ``estimate`` group on the bundled ball (its macro mesh,
graded over 145^2, 128^2 cells, 16 steps, 16 h0; its reference the mesh over 289^2, 256^2
cells, 64 steps, every one of 31 h0; kept in ``$FEM_TWIN_BENCH_DIR`` and read on later
runs).  Checked as ``estimate``."""

from __future__ import annotations

import estimate

DEFAULT = False


def run():
    return estimate.run("ball_on_disk.toml")
