"""Figures of a run saved one way: atomically, in the format of the file's suffix, closed.

The library never chooses a matplotlib backend for the caller's process; a script or the
CLI without a display sets ``MPLBACKEND=Agg`` (the CLI's figures go to files only, which
every backend can do).  A worker process that draws for :class:`.writers.Writers` has no
display and uses Agg unless ``MPLBACKEND`` says otherwise.
"""

from __future__ import annotations

from pathlib import Path

from .atomic import atomic_path


def save_figure(fig, path, dpi: int = 120) -> Path:
    """Write ``fig`` to ``path`` (PNG unless the suffix names another format) atomically
    and close it; returns the path."""
    import matplotlib.pyplot as plt
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", dpi=dpi)
    plt.close(fig)
    return path
