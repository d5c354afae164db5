"""The ``cores`` group: the bundled case end to end on 1, 2 and all workers, and on a Dask
LocalCluster of all workers (with the cluster extra).

Each run is a fresh ``fem-twin run`` of ``examples/pin_on_disk.toml`` with ``[run] workers``
(and ``scheduler = "local"``) set, in its own process and folder.  Printed per run: the
wall time, the run's own estimate, and from its task graph (``summary.json``,
:mod:`fem_twin.runtime.taskgraph`) the CPU time, the critical path and the wall times it
predicts on 16 and 64 workers.  The baseline is the one-worker run.
"""

from __future__ import annotations

import importlib.util
import os
import tempfile
from pathlib import Path

from common import run_case

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


def bench_cores():
    """The bundled case on 1, 2 and all workers (see the module docstring)."""
    counts = [(n, False) for n in sorted({1, 2, os.cpu_count() or 1})]
    if importlib.util.find_spec("distributed") is not None:          # the cluster extra
        counts.append((os.cpu_count() or 1, True))
    rows, base = [], None
    with tempfile.TemporaryDirectory() as tmp:
        for n, dask in counts:
            wall, summary = _run(Path(tmp), n, dask)
            graph = summary["task_graph"]
            base = wall if base is None else base
            where = "Dask LocalCluster of " if dask else ""
            rows.append((f"bundled case, {where}{n} worker{'s' if n > 1 else ''}", wall,
                         f"estimate {summary['estimated_s']:.0f} s; task graph "
                         f"{graph['cpu_s']:.0f} CPU s, critical path "
                         f"{graph['critical_path_s']:.0f} s, predicts "
                         f"{graph['wall_s']['16']:.0f} s on 16 workers and "
                         f"{graph['wall_s']['64']:.0f} s on 64"))
    return base, rows
