"""fem_twin's exceptions: one root, :class:`FemTwinError`, that every error the package
raises on purpose derives from, so ``except FemTwinError`` catches exactly what fem_twin
raises.  Each also derives from the builtin a caller would expect: bad input
(:class:`InputError`) from ``ValueError``, solver failures (:class:`NotConverged`,
:class:`SolverError`) from ``RuntimeError``, files (:class:`FileSystemError`,
:class:`MissingFile`) from ``OSError`` / ``FileNotFoundError``, an absent optional package
(:class:`MissingDependency`) from ``ImportError``.  A test walks every ``raise`` of the
package and fails on a bare builtin."""

from __future__ import annotations

import numpy as np


class FemTwinError(Exception):
    """Root of fem_twin's exceptions."""


class InputError(FemTwinError, ValueError):
    """Bad input (a case file, a topography file, an argument), found before work starts."""


class ForeignCheckpoint(FemTwinError, ValueError):
    """A checkpoint made for another key or point than the one it is read as (set aside
    and recomputed like a damaged one)."""


class FileSystemError(FemTwinError, OSError):
    """A file or folder of a run cannot be read or written as it should."""


class MissingFile(FileSystemError, FileNotFoundError):
    """A file the user named (or a run should have written) does not exist."""


class MissingDependency(FemTwinError, ImportError):
    """An optional package that the chosen option needs is not installed."""


class SolverError(FemTwinError, RuntimeError):
    """A linear solver or an internal consistency check failed (please report it)."""


class NotPositiveDefinite(FemTwinError, np.linalg.LinAlgError):
    """A matrix that should be symmetric positive definite has a zero or negative pivot."""


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
