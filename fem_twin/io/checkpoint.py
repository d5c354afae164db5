"""The store of a run: keys of cached results, and results read back from an output folder.

Every cached result (a micro h0 point, a Stribeck point, a pipeline stage) is filed under
:func:`input_key`, a hash of all its inputs and the fem_twin version: a change of any input
or of the code's version makes a new key, so a stale file is never read (callers prune the
files of keys they no longer use).  Every stage writes atomically
(:func:`fem_twin.io.atomic.atomic_path`), so a file is either complete or absent after a crash; a
file that still cannot be read (a disk error, a truncated copy, a hand edit) must not stop every
later run.  :func:`load_or_none` returns the loaded result, or None after moving the bad file
to ``NAME.corrupt`` with a warning in the log, and the caller recomputes it; so does a file
whose metadata names another key or point than its own (:func:`check_made_for`).
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import zipfile
from pathlib import Path

import numpy as np

from .. import __version__
from ..errors import ForeignCheckpoint

log = logging.getLogger("fem_twin")

#: what a loader raises on a damaged or foreign file
UNREADABLE = (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile)


def load_or_none(path, loader):
    """``loader(path)``, or None if the file is missing or unreadable (then set aside)."""
    path = Path(path)
    if not path.exists():
        return None
    try:
        return loader(path)
    except UNREADABLE as err:
        aside = path.with_name(path.name + ".corrupt")
        os.replace(path, aside)
        log.warning("unreadable result %s (%s: %s): moved to %s, recomputing", path,
                    type(err).__name__, err, aside.name)
        return None


#: the entry of a checkpoint's metadata that names what it was made for
MADE_FOR = "made_for"


def made_for(key: str, at: float) -> dict:
    """The metadata entry of a checkpoint made for ``key`` at ``at`` (a speed, a separation)."""
    return {MADE_FOR: {"key": key, "at": float(at)}}


def check_made_for(meta: dict, key: str, at: float, path) -> None:
    """Refuse (:class:`~fem_twin.errors.ForeignCheckpoint`, which :func:`load_or_none` sets
    aside) a checkpoint whose metadata does not name ``key`` and ``at``: a file copied over
    another's, or made by another version of the store."""
    got = meta.get(MADE_FOR) or {}
    if got.get("key") != key or not np.isclose(got.get("at", np.nan), at, rtol=1e-9, atol=0):
        raise ForeignCheckpoint(f"{Path(path).name} was made for {got or 'an unnamed input'}, "
                                f"not {key} at {at:.9g}")


def input_key(*parts, length: int = 16) -> str:
    """Hex key of ``parts`` and the fem_twin version: arrays by dtype, shape and bytes,
    anything else by its JSON form (``str`` for what JSON cannot hold, e.g. dataclasses)."""
    h = hashlib.sha256()
    for part in (*parts, __version__):
        if isinstance(part, np.ndarray):
            a = np.ascontiguousarray(part)
            h.update(f"{a.dtype.str}{a.shape}".encode())
            h.update(a.tobytes())
        else:
            h.update(json.dumps(part, sort_keys=True, default=str).encode())
    return h.hexdigest()[:length]
