"""Run benchmark groups, print their tables and checked lines, and keep their results.

    python benchmarks/run.py                  # the default groups
    python benchmarks/run.py GROUP ...        # the groups named, default or not
    python benchmarks/run.py --list           # every group: default or not, what it does
    python benchmarks/run.py --compare A.json B.json    # two results of one group

A group is a module of this folder that declares ``DEFAULT = True`` or ``False`` (whether
the bare command runs it) and a ``run()`` returning ``(baseline, rows, *lines, check)``:
the baseline time [s] measured in the same run, rows of ``(label, seconds, notes)``, any
summary lines, and a :class:`common.Check`, printed last as ``check: ... : holds`` or
``FAILED: ...``.  Its name is the module's with ``-`` for ``_`` (``contact_area.py`` is
``contact-area``).  Each group's results go to ``benchmarks/results/`` (ignored by git) as
one JSON file: the commit, the machine, the date, the rows and the checked line.  The exit
status is 1 when a check failed.
"""

from __future__ import annotations

import ast
import importlib
import json
import os
import platform
import re
import subprocess
import sys
import time
import traceback
from datetime import datetime, timezone
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
sys.path.insert(0, str(HERE))
from common import Check  # noqa: E402


def groups() -> dict[str, tuple[str, bool, str]]:
    """``{name: (module, default, first line of its docstring)}`` of every group, read from
    the sources (nothing imported)."""
    out = {}
    for path in sorted(HERE.glob("*.py")):
        tree = ast.parse(path.read_text())
        default = [node.value.value for node in tree.body if isinstance(node, ast.Assign)
                   and [getattr(t, "id", None) for t in node.targets] == ["DEFAULT"]
                   and isinstance(node.value, ast.Constant)]
        if default:
            what = " ".join((ast.get_docstring(tree) or "").split())
            what = re.sub(r"^(the )?(benchmark )?(group )?``[\w-]+``( group)?: ", "", what,
                          flags=re.I)
            what = re.split(r"(?<=\.)\s|:\s", what, maxsplit=1)[0]
            out[path.stem.replace("_", "-")] = (path.stem, bool(default[0]), what)
    return out


def _git(*args) -> str | None:
    try:
        done = subprocess.run(["git", "-C", str(HERE), *args], capture_output=True, text=True,
                              timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


def machine() -> dict:
    """The CPU model, cores, Python and the numerical packages' versions."""
    import numpy
    import scipy
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None
    return {"cpu": cpu, "cores": os.cpu_count(), "usable_cores": usable,
            "system": platform.platform(), "python": platform.python_version(),
            "numpy": numpy.__version__, "scipy": scipy.__version__}


def run_group(name: str, module: str, where: Path = RESULTS) -> bool:
    """Run one group, print its table and checked line, write its JSON; whether it held."""
    start = datetime.now(timezone.utc)
    t0 = time.perf_counter()
    try:
        base, rows, *lines, check = importlib.import_module(module).run()
    except Exception as error:            # the next group still runs; this one failed
        traceback.print_exc()
        base, rows, lines = 1.0, [], []
        check = Check(False, f"the group raised {type(error).__name__}: {error}")
    wall = time.perf_counter() - t0
    print(f"\n## {name}")
    print(f"| {'case':50s} | {'time [s]':>9s} | {'x baseline':>10s} | notes")
    print(f"|{'-' * 52}|{'-' * 11}|{'-' * 12}|------")
    for label, t, note in rows:
        print(f"| {label:50s} | {t:9.4f} | {t / base:10.1f} | {note}")
    for line in lines:
        print(line)
    print(check.line())
    commit = _git("rev-parse", "HEAD")
    status = _git("status", "--porcelain", "--untracked-files=no")
    record = {
        "group": name, "date": start.isoformat(timespec="seconds"), "wall_s": round(wall, 3),
        "commit": commit, "dirty": None if status is None else bool(status),
        "machine": machine(),
        "environment": {k: v for k, v in sorted(os.environ.items())
                        if k.startswith("FEM_TWIN_") or k.endswith("_NUM_THREADS")},
        "baseline_s": base,
        "rows": [{"label": label, "seconds": t, "ratio": t / base, "notes": note}
                 for label, t, note in rows],
        "lines": list(lines), "check": check.line(), "holds": check.holds}
    where.mkdir(exist_ok=True)
    path = where / f"{name}_{start:%Y%m%dT%H%M%S}_{(commit or 'nogit')[:7]}.json"
    path.write_text(json.dumps(record, indent=1) + "\n")
    print(f"results: {path.relative_to(HERE.parent) if path.is_relative_to(HERE.parent) else path}")
    return check.holds is not False


def compare(a: str, b: str) -> None:
    """Two results of one group side by side, row by row (matched by label): the seconds
    and the ratio to each run's own baseline, and B over A of that ratio (below 1: B is
    faster, whatever the machines' speeds)."""
    old, new = (json.loads(Path(p).read_text()) for p in (a, b))
    if old["group"] != new["group"]:
        sys.exit(f"{a} is group {old['group']}, {b} is {new['group']}")
    for r in (old, new):
        print(f"{r['date']}  {(r['commit'] or '?')[:10]}{' (dirty)' * bool(r['dirty'])}  "
              f"{r['machine']['cpu']}, {r['machine']['cores']} cores")
    print(f"| {'case':50s} | {'A [s]':>9s} | {'B [s]':>9s} | {'A x base':>8s} | "
          f"{'B x base':>8s} | B/A (x base)")
    rows = {r["label"]: r for r in old["rows"]}
    for r in new["rows"]:
        o = rows.get(r["label"])
        if o is None:
            print(f"| {r['label']:50s} | {'':>9s} | {r['seconds']:9.4f} | {'':>8s} | "
                  f"{r['ratio']:8.2f} | new")
            continue
        change = f"{r['ratio'] / o['ratio']:.2f}" if o["ratio"] else ""
        print(f"| {r['label']:50s} | {o['seconds']:9.4f} | {r['seconds']:9.4f} | "
              f"{o['ratio']:8.2f} | {r['ratio']:8.2f} | {change}")
    print(f"A: {old['check']}\nB: {new['check']}")


def main(argv: list[str]) -> int:
    known = groups()
    if argv[:1] == ["--list"]:
        for name, (_, default, what) in known.items():
            what = what if len(what) <= 90 else what[:87] + "..."
            print(f"{name:20s} {'default' if default else '       '}  {what}")
        return 0
    if argv[:1] == ["--compare"] and len(argv) == 3:
        compare(*argv[1:])
        return 0
    unknown = [g for g in argv if g not in known]
    if unknown:
        print(f"unknown group(s) {', '.join(unknown)}; the groups: {', '.join(known)}",
              file=sys.stderr)
        return 2
    names = argv or [name for name, (_, default, _) in known.items() if default]
    held = [run_group(name, known[name][0]) for name in names]
    return 0 if all(held) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
