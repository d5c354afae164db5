"""Tasks with their seconds and dependencies, and their wall time on N workers: the model
of both a finished run's task graph (:mod:`fem_twin.runtime.taskgraph`) and a case's estimate
before it runs (:mod:`fem_twin.runtime.cost`)."""

from __future__ import annotations

import heapq
from dataclasses import dataclass

from ..errors import InputError


@dataclass(frozen=True)
class Task:
    """One unit of work: its ``name``, measured ``seconds`` and the tasks it waits for."""

    name: str
    seconds: float
    after: tuple[str, ...] = ()


def makespan(tasks, workers: int) -> float:
    """Wall time [s] of ``tasks`` on ``workers`` processes, scheduled greedily: the ready
    task that became ready first (then in submission order) starts on the first free
    worker."""
    if workers < 1:
        raise InputError(f"workers must be at least 1, got {workers}")
    finish, waiting = {}, list(tasks)
    free = [0.0] * workers
    while waiting:
        ready = [(max((finish[d] for d in t.after), default=0.0), i)
                 for i, t in enumerate(waiting) if all(d in finish for d in t.after)]
        if not ready:
            raise InputError("the task graph has a cycle or an unknown dependency")
        at, i = min(ready)
        task = waiting.pop(i)
        start = max(heapq.heappop(free), at)
        finish[task.name] = start + task.seconds
        heapq.heappush(free, finish[task.name])
    return max(finish.values(), default=0.0)


def critical_path(tasks) -> float:
    """The longest chain of dependent tasks [s]: the wall time on unlimited workers."""
    done = {}
    for t in tasks:                               # submission order is topological
        done[t.name] = t.seconds + max((done[d] for d in t.after), default=0.0)
    return max(done.values(), default=0.0)
