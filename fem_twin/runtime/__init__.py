"""What a run costs: its estimate before it starts and its task graph after it ends.

:mod:`~fem_twin.runtime.cost` models a case's work as tasks with their seconds on the
calibration machine, :mod:`~fem_twin.runtime.machine` scales them to this machine now,
:mod:`~fem_twin.runtime.schedule` schedules tasks on N workers (both the estimate's and a
finished run's), and :mod:`~fem_twin.runtime.taskgraph` rebuilds a finished run's tasks
from its checkpoints.  The case (:mod:`fem_twin.case`) does not import this package; the
CLI asks it.  Threads per process are :mod:`fem_twin.numerics.threads`' (plumbing every
solver reads)."""
