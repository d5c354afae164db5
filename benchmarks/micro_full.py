"""Group ``micro-full``: the ``micro`` group with the whole patch pair, 100 h0 x 32 steps on
2 processes, both time schemes (about 15 min on 2 cores; the goal: 300 s each).  Checked as
``micro``."""

from __future__ import annotations

import micro

DEFAULT = False


def run():
    return micro.run(full=True)
