"""How a command ends for its user: one line and a documented exit code
(docs/troubleshooting.md), for a failure and for Ctrl-C."""

from __future__ import annotations

import logging
import os
import sys

from ..errors import NotConverged, RunLocked, SchedulerUnreachable
from ..numerics.threads import side_threads_alive

#: exit codes (docs/troubleshooting.md): exception types -> (code, label, advice)
EXIT_CODES = (
    ((ValueError, FileNotFoundError, IsADirectoryError, NotADirectoryError), 2, "error",
     "check the input named above"),
    ((NotConverged,), 3, "not converged",
     "the residual history is in run.log; see docs/troubleshooting.md"),
    ((OSError,), 4, "file system", "check free space and write permission of the folder"),
    ((SchedulerUnreachable,), 5, "cluster", "start the scheduler or remove [run] scheduler"),
    ((RunLocked,), 6, "busy", ""),
)



def interrupted(command: str) -> int:
    """Ctrl-C: one line, exit 130; where a thread beside the run's stages still runs (the
    levelling beside the cells, maybe inside C code that aborts when the interpreter
    finalises around it), the process leaves at once, its pool, cluster and lock closed."""
    print(f"fem-twin {command}: interrupted; finished work is kept, run the same command "
          "again to resume", file=sys.stderr)
    if side_threads_alive():
        sys.stdout.flush()
        sys.stderr.flush()
        logging.shutdown()
        os._exit(130)
    return 130


def report(command: str, err: Exception) -> int:
    """Print one line (what, and what to do) and return the documented exit code."""
    for types, code, label, advice in EXIT_CODES:
        if isinstance(err, types):
            hint = f" ({advice})" if advice and code != 2 else ""
            print(f"fem-twin {command}: {label}: {_one_line(err)}{hint}", file=sys.stderr)
            return code
    print(f"fem-twin {command}: internal error: {type(err).__name__}: {_one_line(err)} "
          "(run again with --debug for the traceback, and please report it)", file=sys.stderr)
    return 1


def _one_line(err: Exception) -> str:
    text = " ".join(str(err).split())
    return text if len(text) < 400 else text[:400] + " ..."
