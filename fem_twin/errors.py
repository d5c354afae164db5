"""Errors shared by the solvers."""

from __future__ import annotations

import numpy as np


class NotConverged(RuntimeError):
    """An iterative solver missed its tolerance; ``history`` holds its residuals."""

    def __init__(self, message, history):
        super().__init__(f"{message}; last residuals {np.array(history[-5:])}")
        self.message = message
        self.history = list(history)

    def __reduce__(self):
        # rebuilt from its arguments when it crosses to or from a worker process
        return type(self), (self.message, self.history)


class RunLocked(RuntimeError):
    """Another process holds the output folder of a run."""


class SchedulerUnreachable(RuntimeError):
    """The Dask scheduler of ``[run] scheduler`` could not be reached."""
