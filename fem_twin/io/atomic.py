"""Atomic file writes: a crash never leaves a half-written result behind."""

from __future__ import annotations

import contextlib
import os
import re
import tempfile
from pathlib import Path

from ..errors import FileSystemError

#: the name :func:`atomic_path` gives its temporary file: ``.NAME.`` plus mkstemp's eight
#: random characters plus a suffix
TEMPORARY = re.compile(r"\..+\.[a-z0-9_]{8}(\.[A-Za-z0-9]+)?")


@contextlib.contextmanager
def atomic_path(path, suffix: str | None = None):
    """Yield a temporary path beside ``path``; move it onto ``path`` only on success.

    ``suffix`` (default: that of ``path``) lets writers that choose a format by file
    extension see the right one.
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.",
                                   suffix=path.suffix if suffix is None else suffix)
    except OSError as err:           # /proc, a read-only mount: the path's, not the temporary's
        raise FileSystemError(err.errno, _unwritable(path, err)) from None
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)   # mkstemp creates 0600; give the file ordinary permissions
    try:
        yield Path(tmp)
        try:
            os.replace(tmp, path)
        except OSError as err:
            raise FileSystemError(err.errno, _unwritable(path, err)) from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _unwritable(path: Path, err: OSError) -> str:
    """The message of a file that cannot be written at ``path`` (exit 4), naming it."""
    return f"cannot write {path} ({err.strerror}); give another place"


def remove_debris(folder) -> int:
    """Delete the temporary files of :func:`atomic_path` that an interrupted process (kill
    -9, a full disk) left anywhere under ``folder``; the caller holds the folder (its run
    lock), so no writer is using them.  Returns how many were removed."""
    gone = 0
    for path in Path(folder).rglob(".*"):
        if path.is_file() and TEMPORARY.fullmatch(path.name):
            with contextlib.suppress(FileNotFoundError):
                path.unlink()
                gone += 1
    return gone
