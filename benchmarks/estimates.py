"""The ``estimates`` group: ``fem-twin run``'s printed estimate against its run.

Each case of ``FEM_TWIN_ESTIMATE_CASES`` (default ``pin_on_disk,ball_on_disk,paper``) runs
as a fresh ``fem-twin run`` in its own process, quiet, then (``FEM_TWIN_ESTIMATE_LOAD=1``)
beside a busy loop on one core: a slower machine.  Printed per run: the wall time, the
estimate over it, the probes' factors the run printed, and the factors its own task graph
shows (its micro and macro tasks' CPU over the cost model's, :mod:`fem_twin.runtime.cost`):
what the probes should have read.  The baseline is the first run.  Checked: each estimate
within 0.8-1.25x of its wall time (the bar of
``tests/test_cli.py::test_run_time_estimates_hold``).
"""

from __future__ import annotations

import multiprocessing
import os
import re
import tempfile
from pathlib import Path

from common import Check, run_case

from fem_twin.case import load_case
from fem_twin.runtime.cost import MICRO, cost_tasks
from fem_twin.runtime.taskgraph import run_task_graph

DEFAULT = False
#: the bar of a run's printed estimate over its wall time
BAR = (0.8, 1.25)
ROOT = Path(__file__).resolve().parents[1]
#: the probes' factors as ``fem-twin run`` prints them: one, or the cells' and the points'
PRINTED = re.compile(r"takes ([\d.]+)x(?: for the cells and ([\d.]+)x for the macro points)?")


def _busy():
    """A busy loop, for the slower machine (stopped by its parent)."""
    while True:
        pass


def _run(case: str, out: Path) -> tuple[float, dict, tuple[float, float]]:
    """Wall time [s], summary and printed probe factors of one fresh run of ``case``."""
    wall, summary, printed = run_case(ROOT / "examples" / f"{case}.toml", out, ROOT)
    micro, macro = PRINTED.search(printed).groups()
    return wall, summary, (float(micro), float(macro or micro))


def _own_factors(case: str, out: Path) -> tuple[float, float]:
    """The run's micro and macro task CPU over the cost model's (the serial part aside)."""
    c = load_case(ROOT / "examples" / f"{case}.toml")
    ran, model = run_task_graph(c, out), cost_tasks(c)

    def share(tasks, micro):
        return sum(t.seconds for t in tasks if t.name.startswith(MICRO) == micro
                   and t.name != "serial")
    return share(ran, True) / share(model, True), share(ran, False) / share(model, False)


def run():
    """Rows: per case (and load), its run with the estimate's ratio and factors."""
    cases = os.environ.get("FEM_TWIN_ESTIMATE_CASES",
                           "pin_on_disk,ball_on_disk,paper").split(",")
    loads = [False, True] if os.environ.get("FEM_TWIN_ESTIMATE_LOAD") == "1" else [False]
    rows, base, ratios = [], None, []
    with tempfile.TemporaryDirectory() as tmp:
        for loaded in loads:
            for case in cases:
                busy = multiprocessing.Process(target=_busy, daemon=True) if loaded else None
                if busy:
                    busy.start()
                out = Path(tmp) / f"{case}_{loaded}"
                try:
                    wall, summary, probes = _run(case, out)
                finally:
                    if busy:
                        busy.terminate()
                own = _own_factors(case, out)
                base = wall if base is None else base
                ratios.append(summary["estimated_s"] / wall)
                rows.append((f"{case}{', beside a busy loop' if loaded else ''}", wall,
                             f"estimate {summary['estimated_s']:.1f} s = "
                             f"{summary['estimated_s'] / wall:.2f}x the run; probes "
                             f"{probes[0]:.2f}x, {probes[1]:.2f}x; its tasks "
                             f"{own[0]:.2f}x, {own[1]:.2f}x (cells, macro)"))
    holds = all(BAR[0] <= r <= BAR[1] for r in ratios)
    return base, rows, Check(holds, f"each estimate {min(ratios):.2f}-{max(ratios):.2f}x its "
                                    f"run's wall time, within {BAR[0]}-{BAR[1]}x")
