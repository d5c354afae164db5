"""Group ``estimate-pairs``: the ``estimate`` group on the bundled pin with every patch pair
(the run reads their average, in which the pairs' own cell-grid errors largely cancel;
reference as ``estimate``'s: about 40 min on 2 cores, kept in ``$FEM_TWIN_BENCH_DIR`` and
read on later runs).  Checked as ``estimate``."""

from __future__ import annotations

import estimate

DEFAULT = False


def run():
    return estimate.run("pin_on_disk.toml", pairs=None)
