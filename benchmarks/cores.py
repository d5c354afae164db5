"""The ``cores`` group: the bundled case end to end on 1, 2 and all workers, and on a Dask
LocalCluster of all workers (with the cluster extra).

Each run is a fresh ``fem-twin run`` of ``examples/pin_on_disk.toml`` with ``[run] workers``
(and ``scheduler = "local"``) set, in its own process and folder.  Printed per run: the
wall time, the run's own estimate, and from its task graph (``summary.json``,
:mod:`fem_twin.runtime.taskgraph`) the CPU time, the critical path and the wall times it
predicts on 16 and 64 workers.  The baseline is the one-worker run.  Checked: each run's
estimate within 0.8-1.25x of its wall time (the bar of ``estimates`` and of
``tests/test_cli.py::test_run_time_estimates_hold``).
"""

from __future__ import annotations

import importlib.util
import os
import tempfile
from pathlib import Path

from common import Check, run_case

DEFAULT = False
#: the bar of a run's printed estimate over its wall time
BAR = (0.8, 1.25)
ROOT = Path(__file__).resolve().parents[1]


def _case(folder: Path, workers: int, dask: bool) -> Path:
    """The bundled case with absolute paths and ``workers`` processes (on a Dask
    LocalCluster: ``dask``)."""
    text = (ROOT / "examples" / "pin_on_disk.toml").read_text()
    text = text.replace("../meshes/", str(ROOT / "meshes") + "/")
    line = f"workers = {workers} " + ('\nscheduler = "local" ' if dask else "")
    text = text.replace("workers = 0 ", line, 1)
    path = folder / f"case_{workers}{'_dask' * dask}.toml"
    path.write_text(text)
    return path


def _run(folder: Path, workers: int, dask: bool = False) -> tuple[float, dict]:
    """Wall time [s] of one run and its summary."""
    out = folder / f"out_{workers}{'_dask' * dask}"
    return run_case(_case(folder, workers, dask), out, ROOT)[:2]


def run():
    """The bundled case on 1, 2 and all workers (see the module docstring)."""
    counts = [(n, False) for n in sorted({1, 2, os.cpu_count() or 1})]
    if importlib.util.find_spec("distributed") is not None:          # the cluster extra
        counts.append((os.cpu_count() or 1, True))
    rows, base, ratios = [], None, []
    with tempfile.TemporaryDirectory() as tmp:
        for n, dask in counts:
            wall, summary = _run(Path(tmp), n, dask)
            graph = summary["task_graph"]
            ratios.append(summary["estimated_s"] / wall)
            base = wall if base is None else base
            where = "Dask LocalCluster of " if dask else ""
            rows.append((f"bundled case, {where}{n} worker{'s' if n > 1 else ''}", wall,
                         f"estimate {summary['estimated_s']:.0f} s; task graph "
                         f"{graph['cpu_s']:.0f} CPU s, critical path "
                         f"{graph['critical_path_s']:.0f} s, predicts "
                         f"{graph['wall_s']['16']:.0f} s on 16 workers and "
                         f"{graph['wall_s']['64']:.0f} s on 64"))
    holds = all(BAR[0] <= r <= BAR[1] for r in ratios)
    return base, rows, Check(holds, f"each run's estimate {min(ratios):.2f}-{max(ratios):.2f}x "
                                    f"its wall time, within {BAR[0]}-{BAR[1]}x")
