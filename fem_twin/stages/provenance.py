"""What a run's results depend on: the provenance written into every result, and the hash
of the case settings each cached stage depends on."""

from __future__ import annotations

import time
from pathlib import Path

from ..case import Case
from ..io.checkpoint import input_key


def provenance(case: Case) -> dict:
    """fem_twin version, git commit of the source when it is a checkout, case file hash."""
    import hashlib
    import subprocess

    from .. import __version__
    commit = None
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                                cwd=Path(__file__).parent, timeout=10).stdout.strip() or None
    except (OSError, subprocess.SubprocessError):
        pass
    digest = (hashlib.sha256(case.source.read_bytes()).hexdigest()[:16]
              if case.source is not None else None)
    return {"fem_twin_version": __version__, "git_commit": commit,
            "case_file": (str(Path(case.source).resolve()) if case.source is not None
                          else None), "case_sha256": digest,
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z")}


def stage_keys(case: Case) -> dict:
    """Hash of the case settings each cached stage depends on."""
    def key(*parts):
        return input_key(repr(parts))

    g = case.geometry
    files = [(str(p), p.stat().st_mtime_ns, p.stat().st_size)
             for p in (*g.pins, *g.disks, *(q for pair in g.patches for q in pair))]
    geometry = key(files, g, case.preprocessing)
    return {"geometry": geometry,
            "levelling": key(geometry, case.materials, case.macro.pin),
            "micro": key(geometry, case.micro, case.materials, case.macro.friction)}
