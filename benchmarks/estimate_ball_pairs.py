"""Group ``estimate-ball-pairs``: the ``estimate`` group on the bundled ball with every
patch pair, whose average the run reads (reference as ``estimate-ball``'s: about 25 min on
2 cores, kept in ``$FEM_TWIN_BENCH_DIR`` and read on later runs).  Checked as
``estimate``."""

from __future__ import annotations

import estimate

DEFAULT = False


def run():
    return estimate.run("ball_on_disk.toml", pairs=None)
