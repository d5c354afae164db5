"""fem_twin's exceptions: one root, :class:`FemTwinError`, that every error of the package
derives from (bad input also derives from ``ValueError``, solver failures from
``RuntimeError``), so ``except FemTwinError`` catches exactly what fem_twin raises."""

from __future__ import annotations

import numpy as np


class FemTwinError(Exception):
    """Root of fem_twin's exceptions."""


class InputError(FemTwinError, ValueError):
    """Bad input (a case file, a topography file, an argument), found before work starts."""


class NotConverged(FemTwinError, RuntimeError):
    """An iterative solver missed its tolerance; ``history`` holds its residuals."""

    def __init__(self, message, history):
        super().__init__(f"{message}; last residuals {np.array(history[-5:])}")
        self.message = message
        self.history = list(history)

    def __reduce__(self):
        # rebuilt from its arguments when it crosses to or from a worker process
        return type(self), (self.message, self.history)


class RunLocked(FemTwinError, RuntimeError):
    """Another process holds the output folder of a run."""


class SchedulerUnreachable(FemTwinError, RuntimeError):
    """The Dask scheduler of ``[run] scheduler`` could not be reached."""


class MixedNotConverged(NotConverged):
    """The coupled macro iteration failed; ``history`` holds the residual rows."""


class ReynoldsNotConverged(NotConverged):
    """The complementarity Newton loop failed; ``history`` holds the residuals."""
