"""A run's output files written on its worker processes, beside the main process's work:
the figures, ``results.nc`` and ``fields.nc``.

Written in the main process, the figures kept the workers waiting (matplotlib's layout and
text are pure Python, so they gain from processes, not threads; ``python
benchmarks/run.py stribeck`` times the bundled run end to end).
"""

from __future__ import annotations

import os


class Writers:
    """File writers run on the workers of ``executor`` (a process pool or Dask), beside what
    the main process does meanwhile, or at once without one.  :meth:`wait` returns when
    every one is written and raises the first error of any."""

    def __init__(self, executor=None):
        self.executor, self.pending = executor, []

    def write(self, writer, *args, **kwargs) -> None:
        """``writer(*args, **kwargs)``: a function that writes one or more files (its
        arguments pickle, so give files rather than large fields)."""
        if self.executor is None:
            writer(*args, **kwargs)
            return
        self.pending.append(self.executor.submit(_write, writer, args, kwargs))

    def wait(self) -> None:
        """Wait for every file written so far."""
        pending, self.pending = self.pending, []
        for future in pending:
            future.result()


def _write(writer, args, kwargs):
    """A writer in a worker process (figures without a display: Agg unless ``MPLBACKEND``
    is set)."""
    os.environ.setdefault("MPLBACKEND", "Agg")
    return writer(*args, **kwargs)
