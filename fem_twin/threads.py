"""Thread pools of BLAS and OpenMP: one thread while fem_twin computes (threadpoolctl).

Measured on this project's 2-core machines: two BLAS/FFT threads made pyamg, CG and FFTs
5-50x slower under load; parallel speed comes from processes over independent work (h0
values, patches, speeds).  The entry points (``homogenise``, ``solve_mixed``,
``stribeck_sweep``, the pipeline and its worker tasks) run under :func:`one_thread`, which
limits the pools for their duration only and restores them afterwards, so importing
fem_twin changes nothing.  ``FEM_TWIN_THREADS=N`` allows N threads instead.
"""

from __future__ import annotations

import functools
import os


def thread_limit() -> int:
    """Threads allowed per process (``FEM_TWIN_THREADS``, default 1)."""
    value = os.environ.get("FEM_TWIN_THREADS", "1")
    try:
        n = int(value)
    except ValueError:
        raise ValueError(f"FEM_TWIN_THREADS must be a whole number of threads, got {value!r}") \
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
