"""Thread pools of BLAS and OpenMP: one thread while fem_twin computes (threadpoolctl); the
heap of worker processes (:func:`worker_heap`); local process pools that stop cleanly
(:func:`process_pool`, :func:`stop_pool`).

Measured on this project's 2-core machines: two BLAS/FFT threads made pyamg, CG and FFTs
5-50x slower under load; parallel speed comes from processes over independent work (h0
values, patches, speeds).  The entry points (``homogenise``, ``solve_mixed``,
``stribeck_sweep``, the pipeline and its worker tasks) run under :func:`one_thread`, which
limits the pools for their duration only and restores them afterwards, so importing
fem_twin changes nothing.  ``FEM_TWIN_THREADS=N`` allows N threads instead.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import logging
import os
import signal
import sys
import threading
import time
from concurrent.futures import Future, ProcessPoolExecutor
from contextlib import contextmanager

from ..errors import InputError, SchedulerUnreachable


def thread_limit() -> int:
    """Threads allowed per process (``FEM_TWIN_THREADS``, default 1)."""
    value = os.environ.get("FEM_TWIN_THREADS", "1")
    try:
        n = int(value)
    except ValueError:
        raise InputError(f"FEM_TWIN_THREADS must be a whole number of threads, got {value!r}") \
            from None
    return max(1, n)


def one_thread(fn):
    """Decorator: run ``fn`` with BLAS/OpenMP pools limited to :func:`thread_limit`."""
    @functools.wraps(fn)
    def limited(*args, **kwargs):
        from threadpoolctl import threadpool_limits
        with threadpool_limits(limits=thread_limit()):
            return fn(*args, **kwargs)
    return limited


def worker_heap() -> None:
    """In a worker process (glibc): serve temporaries up to 32 MB from the heap.

    Dask's nanny starts workers with ``MALLOC_TRIM_THRESHOLD_=65536``, which fixes glibc's
    mmap threshold at 128 KB, so every grid-sized temporary becomes an mmap/munmap pair with
    fresh zeroed pages: the micro stage of one patch pair ran 2x slower in a Dask worker
    (33.7 s against 17.0 s without that setting, contact 2.8x).  32 MB, glibc's own largest
    threshold, keeps the 1997^2 grids (31.9 MB a field) on the heap and maps the 2048^2 ones
    (33.5 MB), which a heap would hold beyond their use (a 2048^2 point's peak with 64 MB,
    32 MB and none: ``FEM_TWIN_SCALE_MAX=2048 python benchmarks/run.py scale``).  Called by
    the worker tasks (also when they
    run in the calling process), once per process; a no-op without glibc."""
    global _HEAP_SET
    if _HEAP_SET or not sys.platform.startswith("linux"):
        return
    _HEAP_SET = True
    try:
        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(-3, 32 << 20)         # M_MMAP_THRESHOLD
        libc.mallopt(-1, 128 << 20)        # M_TRIM_THRESHOLD
    except (OSError, AttributeError):      # not glibc
        pass


_HEAP_SET = False


def quiet_worker() -> None:
    """Initializer of local worker processes: Ctrl-C reaches the parent alone, which stops
    the pool (:func:`stop_pool`), instead of every idle worker printing a traceback; and a
    worker whose parent is gone (kill -9, the OOM killer) exits within
    :data:`ORPHAN_POLL` seconds instead of idling on with its memory."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = os.getppid()

    def watch():
        while os.getppid() == parent:
            time.sleep(ORPHAN_POLL)
        os._exit(1)                       # nobody reads its results; checkpoints are atomic
    threading.Thread(target=watch, daemon=True, name="fem_twin-orphan-watch").start()


#: how often a local worker checks that its parent still runs [s]
ORPHAN_POLL = 1.0


def run_jobs(executor, job, items):
    """``job(item)`` for each of ``items``, yielded in order: on the workers of ``executor``
    (all submitted at once; ``job`` and the items pickle), or here one by one without one."""
    if executor is None:
        yield from map(job, items)
        return
    for future in [executor.submit(job, item) for item in items]:
        yield future.result()


@contextmanager
def side_threads():
    """Daemon threads for work that waits on the process pool (each patch's cells, the
    levelling beside them): ``submit(fn, *args)`` starts one and returns its Future,
    ``map(fn, items)`` one per item.  Joined on a normal exit; on an exception (Ctrl-C)
    left at once, so that the run's executor closes next and the process exits without
    joining threads that wait on futures a terminated pool will never finish (Python
    joins a ThreadPoolExecutor's threads at exit)."""
    threads = _SideThreads()
    yield threads
    for future in threads.futures:
        future.result()


#: the name of :func:`side_threads`' threads
SIDE_THREAD = "fem_twin-side"


def side_threads_alive() -> bool:
    """Whether a thread of :func:`side_threads` still runs (after Ctrl-C, one may be inside
    native code, which aborts the process when the interpreter finalises around it: the
    command line then leaves at once, its files already closed)."""
    return any(t.name == SIDE_THREAD and t.is_alive() for t in threading.enumerate())


class _SideThreads:
    """The executor of :func:`side_threads`: a daemon thread per task."""

    def __init__(self):
        self.futures = []

    def submit(self, fn, *args) -> Future:
        future = Future()

        def run():
            if future.set_running_or_notify_cancel():
                try:
                    future.set_result(fn(*args))
                except BaseException as err:       # handed to the waiting thread
                    future.set_exception(err)
        threading.Thread(target=run, daemon=True, name=SIDE_THREAD).start()
        self.futures.append(future)
        return future

    def map(self, fn, items):
        return [f.result() for f in [self.submit(fn, item) for item in items]]


def quiet_resource_tracker() -> None:
    """Start multiprocessing's resource tracker (one per program) with its standard error
    on the null device: after Ctrl-C it warned of a LocalCluster's leaked semaphore, two
    lines beside the run's one (it still cleans up).  The command line calls it first."""
    from multiprocessing import resource_tracker
    saved, null = os.dup(2), os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 2)
        resource_tracker.ensure_running()
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(null)


def process_pool(workers: int) -> ProcessPoolExecutor:
    """A local pool of ``workers`` processes started by :func:`quiet_worker`."""
    return ProcessPoolExecutor(workers, initializer=quiet_worker)


def stop_pool(pool: ProcessPoolExecutor, failed: bool = False) -> None:
    """Shut ``pool`` down: wait for it after success; after a failure or Ctrl-C terminate
    its workers at once (finished work is already in the checkpoints, written atomically,
    and the rest is cancelled)."""
    if not failed:
        pool.shutdown()
        return
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        process.terminate()
    pool.shutdown(wait=False, cancel_futures=True)


#: Dask settings for processes that compute: no statistical profiler (it samples every
#: task's stack every 10 ms), event-loop ticks, system and memory monitors at 1-5 s instead
#: of 20-500 ms, no GIL monitor: a task's wall time exceeds its thread's CPU time by
#: 7-10 % in a default worker, 2 % with these, 0.5 % in a process-pool worker (32 cell
#: tasks of the bundled case on 2 cores; docs: Performance).  A LocalCluster of
#: ``[run] scheduler = "local"`` runs with them; ``DASK_ENVIRONMENT`` sets them for
#: ``dask worker`` (docs: Performance).
DASK_CONFIG = {"distributed.worker.profile.enabled": False,
               "distributed.admin.tick.interval": "1s",
               "distributed.admin.system-monitor.interval": "5s",
               "distributed.admin.system-monitor.gil.enabled": False,
               "distributed.worker.memory.monitor-interval": "1s"}
#: the same as environment variables for the processes of ``dask scheduler``/``dask worker``
DASK_ENVIRONMENT = {"DASK_" + k.upper().replace(".", "__").replace("-", "_"): str(v)
                    for k, v in DASK_CONFIG.items()}


@contextmanager
def executor_for(workers: int = 0, scheduler: str | None = None):
    """Local process pool of ``workers`` processes (0 = all cores; ``[run] workers``) or the
    executor of the Dask cluster at ``scheduler`` (``[run] scheduler``: an address, or
    ``"local"`` for a LocalCluster of ``workers`` processes of one thread each, with
    :data:`DASK_CONFIG`); None for one worker.  ``executor.n_workers``: how many
    processes serve it (the micro stage cuts its h0 values into 4 tasks per worker)."""
    workers = workers or os.cpu_count() or 1
    if scheduler:
        with _dask_client(scheduler, workers) as client:
            executor = client.get_executor()
            executor.n_workers = max(1, len(client.scheduler_info()["workers"]))
            yield executor
        return
    if workers <= 1:
        yield None
        return
    pool = process_pool(workers)
    pool.n_workers = workers
    try:
        yield pool
    except BaseException:
        stop_pool(pool, failed=True)
        raise
    stop_pool(pool)


def _quiet_dask() -> None:
    """Silence Dask's own logging in this process: the run says what ended it, in one line
    (a closing cluster's workers warned of each cancelled task)."""
    logging.getLogger("distributed").setLevel(logging.CRITICAL)


@contextmanager
def workers_ignore_ctrl_c():
    """Start processes that ignore Ctrl-C (SIGINT; an ignored signal stays ignored in a
    child) from birth: the terminal sends it to the whole process group, and a LocalCluster
    or a probe whose workers died of it printed their tracebacks and hung its close.  The
    run alone stops, then closes them; a Ctrl-C while they start (a few seconds) is lost.
    The main thread only (Python's signal rule)."""
    before = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


@contextmanager
def _dask_client(scheduler: str, workers: int):
    """A Dask client of the scheduler at the address ``scheduler``, or of a LocalCluster
    of ``workers`` processes (``"local"``), closed on exit."""
    import dask
    from distributed import Client, LocalCluster
    if scheduler == "local":
        with dask.config.set(DASK_CONFIG):
            with workers_ignore_ctrl_c():
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1,
                                       processes=True, dashboard_address=None)
            with cluster, Client(cluster) as client:
                try:
                    yield client
                except BaseException:           # Ctrl-C, a failed task: close in silence
                    _quiet_dask()
                    with contextlib.suppress(Exception):
                        client.run(_quiet_dask)
                    raise
        return
    try:
        client = Client(scheduler, timeout="5s")
    except (OSError, TimeoutError) as err:
        raise SchedulerUnreachable(f"could not reach the Dask scheduler "
                                   f"{scheduler} ([run] scheduler): {err}") from err
    with client:
        yield client
