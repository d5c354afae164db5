"""Results read back from an output folder: what cannot be read is set aside and recomputed.

Every stage writes atomically, so a file is either complete or absent after a crash; a file
that still cannot be read (a disk error, a truncated copy, a hand edit) must not stop every
later run.  :func:`load_or_none` returns the loaded result, or None after moving the bad file
to ``NAME.corrupt`` with a warning in the log, and the caller recomputes it.
"""

from __future__ import annotations

import logging
import os
import zipfile
from pathlib import Path

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
