"""Direct solves of symmetric positive-definite systems that share one sparsity pattern.

The cell problems (eqs 8-10) factorise a new operator at every h0 and time step on one
pattern; the factorisation is 85 % of the roughness-scale time.  Backends:
``"superlu"`` (scipy's, no pivoting, in the caller's fill-reducing order; always there)
and ``"pardiso"`` (MKL PARDISO's Cholesky through ``ctypes``: METIS and the symbolic
analysis once per pattern, then numeric factorisations by the two-level algorithm; about
3x faster on a 256^2 cell; ``pip install "fem-twin[pardiso]"``, an optional extra under
the Intel Simplified Software License).  MKL runs sequentially: parallel speed comes from
processes; ``FEM_TWIN_THREADS=N`` before MKL loads gives N PARDISO threads on matrices of
``THREADED_UNKNOWNS`` or more, idle threads sleeping at once (``KMP_BLOCKTIME=0``).
``backend=None`` reads ``FEM_TWIN_SPARSE`` (``auto``: PARDISO when ``libmkl_rt`` loads,
else SuperLU); the two agree to about 1e-11 (tested).  Measurements: ``python
benchmarks/run.py micro`` (the cell step on both) and ``scale`` (the macro points).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import glob
import os
import sys
from functools import lru_cache

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import InputError, MissingDependency, NotPositiveDefinite, SolverError
from .ordering import is_permutation
from .threads import thread_limit

BACKENDS = ("superlu", "pardiso")
#: PARDISO uses the threads ``FEM_TWIN_THREADS`` allows only on matrices of at least this
#: many unknowns: below, waking the sleeping threads for each small solve costs more than
#: they bring (``python benchmarks/run.py scale`` with ``FEM_TWIN_THREADS`` 1 and 2)
THREADED_UNKNOWNS = 1 << 17


@lru_cache(maxsize=1)
def _mkl_rt():
    """The loaded ``libmkl_rt``, or None when MKL is not installed.  Its threading layer
    is chosen here, once per process: OpenMP (``INTEL``) when :func:`thread_limit` allows
    more than one thread and Intel's OpenMP runtime lies beside MKL, else ``SEQUENTIAL``
    (a user's ``MKL_THREADING_LAYER`` wins)."""
    candidates = [os.environ.get("FEM_TWIN_MKL_RT"), ctypes.util.find_library("mkl_rt"),
                  *sorted(glob.glob(os.path.join(sys.prefix, "lib", "libmkl_rt.so*")), key=len)]
    for path in filter(None, candidates):
        threaded = thread_limit() > 1 and bool(glob.glob(os.path.join(
            os.path.dirname(os.path.abspath(path)), "libiomp5.so*")))
        os.environ.setdefault("MKL_THREADING_LAYER", "INTEL" if threaded else "SEQUENTIAL")
        if threaded:                # idle OpenMP threads sleep at once instead of spinning
            os.environ.setdefault("KMP_BLOCKTIME", "0")     # beside the numpy work between
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        lib.pardiso.restype = None
        lib.MKL_Set_Num_Threads_Local.restype = ctypes.c_int
        return lib
    return None


def default_backend() -> str:
    """The backend that ``backend=None`` selects (see the module docstring)."""
    choice = os.environ.get("FEM_TWIN_SPARSE", "auto").strip().lower()
    if choice == "auto":
        return "pardiso" if _mkl_rt() is not None else "superlu"
    if choice not in BACKENDS:
        raise InputError(f"FEM_TWIN_SPARSE must be 'auto' or one of {BACKENDS}, got {choice!r}")
    return choice


class SPDSolver:
    """Factorise and solve SPD matrices with the fixed CSR pattern ``(indptr, indices)``.

    The pattern is that of the full symmetric matrix, column indices sorted in each row.
    ``factor(values)`` takes the values in that CSR order; ``solve(rhs)`` solves for one or
    more right-hand sides (columns).  ``symmetric=False``: general square matrices (LU;
    PARDISO matrix type 11 with pivot perturbation, whose count after ``factor`` is
    ``perturbed``: a caller that needs an exact step checks it).  ``single=True`` (PARDISO
    only): the factors in single precision, half the memory (667k unknowns of the 3x3
    stencil: 0.97 against 1.28 GiB), not always faster (it depends on the processor);
    ``solve`` is then
    accurate to about 1e-5 relative and the caller refines.  ``order`` (PARDISO only): the
    unknowns in the order of elimination, a fill-reducing order the caller knows better
    than METIS (a grid's nested dissection, :mod:`fem_twin.numerics.ordering`); None: METIS.
    ``release()`` frees the factors and keeps the analysis.
    """

    def __init__(self, indptr, indices, backend: str | None = None, symmetric: bool = True,
                 single: bool = False, order=None):
        self.backend = default_backend() if backend is None else backend
        if self.backend not in BACKENDS:
            raise InputError(f"backend must be one of {BACKENDS}, got {self.backend!r}")
        self._indptr = np.asarray(indptr)
        self._indices = np.asarray(indices)
        self.n = self._indptr.size - 1
        self.symmetric = symmetric
        self.perturbed = 0
        if self.backend == "pardiso" and not symmetric:
            self._upper = slice(None)
            self._ia = np.asarray(self._indptr, dtype=np.int32)    # no copy if int32
            self._ja = np.asarray(self._indices, dtype=np.int32)
        elif self.backend == "pardiso":
            if _mkl_rt() is None:
                raise MissingDependency("the 'pardiso' backend needs MKL: pip install "
                                  "'fem-twin[pardiso]' (or use backend='superlu')")
            rows = np.repeat(np.arange(self.n), np.diff(self._indptr))
            self._upper = self._indices >= rows
            counts = np.bincount(rows[self._upper], minlength=self.n)
            self._ia = np.r_[0, np.cumsum(counts)].astype(np.int32)
            self._ja = self._indices[self._upper].astype(np.int32)
        self._lu = None
        self.dtype = np.float32 if single and self.backend == "pardiso" else np.float64
        self._a = None
        self._order = (np.zeros(self.n, np.int32) if order is None
                       else np.asarray(order, dtype=np.int32))   # read by PARDISO: kept alive
        self._own_order = order is not None
        if order is not None and not is_permutation(self._order, self.n):
            raise InputError(f"order must be a permutation of the {self.n} unknowns")
        self._pt = np.zeros(64, dtype=np.int64)     # PARDISO's opaque handle
        self._analysed = False

    def __getstate__(self):                         # a factorisation does not travel
        state = self.__dict__.copy()
        state.update(_lu=None, _a=None, _pt=np.zeros(64, dtype=np.int64), _analysed=False)
        return state

    def __del__(self):                              # release PARDISO's memory
        if getattr(self, "_analysed", False):
            try:
                self._free(-1)
            except Exception:                       # interpreter shutdown: nothing to free
                pass

    def factor(self, values) -> "SPDSolver":
        """Factorise the matrix with CSR data ``values`` (PARDISO keeps them: values already
        in the factors' precision and a full pattern are not copied)."""
        values = np.asarray(values)
        if self.backend == "superlu":
            # the CSR pattern read as CSC is the transpose: the same matrix when symmetric
            K = sp.csc_matrix((values.astype(float, copy=False), self._indices, self._indptr),
                              shape=(self.n, self.n))
            self._lu = spla.splu(K if self.symmetric else K.T.tocsc(), permc_spec="NATURAL",
                                 diag_pivot_thresh=0.0 if self.symmetric else 0.1,
                                 options={"SymmetricMode": True})
            return self
        self._a = np.ascontiguousarray(values[self._upper], dtype=self.dtype)
        if not self._analysed:
            self._pardiso(11, np.zeros((self.n, 1), self.dtype))
            self._analysed = True
        self._pardiso(22, np.zeros((self.n, 1), self.dtype))
        return self

    def solve(self, rhs) -> np.ndarray:
        rhs = np.asarray(rhs, dtype=float)
        if self.backend == "superlu":
            if self._lu is None:
                raise SolverError("factor() a matrix before solve()")
            return self._lu.solve(rhs)
        if self._a is None:
            raise SolverError("factor() a matrix before solve()")
        # all columns in one call: 1.4-2.3x faster than one call a column for 2-5 columns of
        # a 48^2-256^2 cell (``python benchmarks/run.py micro`` times the cell step that
        # calls it)
        b = np.asfortranarray(rhs.reshape(self.n, -1), dtype=self.dtype)
        return self._pardiso(33, b).reshape(rhs.shape).astype(float, copy=False)

    def release(self) -> None:
        """Free the factors (PARDISO phase 0), keep the ordering and symbolic analysis; the
        next ``factor`` computes them anew."""
        if self._analysed and self._a is not None:
            self._free(0)
        self._lu = self._a = None

    def _free(self, phase):
        """PARDISO ``phase`` 0 (the factors) or -1 (everything), the memory given back to
        the system rather than kept in MKL's pool."""
        self._pardiso(phase, np.zeros((self.n, 1), self.dtype))
        _mkl_rt().mkl_free_buffers()

    def _pardiso(self, phase, b):
        """One call of MKL's ``pardiso`` (``b`` of ``self.dtype``; zero-based indices, METIS
        ordering; Cholesky, or LU with pivot perturbation 1e-13 for general matrices; no
        refinement steps: callers check the residual)."""
        lib = _mkl_rt()
        iparm = np.zeros(64, dtype=np.int32)
        iparm[[0, 1, 9, 34]] = 1, 2, 8, 1           # own settings, METIS, eps 1e-8, 0-based
        iparm[23] = 1                               # the two-level factorisation
        iparm[4] = self._own_order                  # the caller's order instead of METIS
        iparm[27] = self.dtype == np.float32        # single precision arrays and factors
        if not self.symmetric:
            iparm[9] = 13                            # pivot perturbation 1e-13
        mtype = 2 if self.symmetric else 11
        x = np.zeros_like(b, order="F")
        a = self._a if self._a is not None else np.zeros(self._ja.size, self.dtype)
        error = ctypes.c_int32(0)
        i32 = ctypes.POINTER(ctypes.c_int32)

        def ref(v):
            return ctypes.byref(ctypes.c_int32(v))

        # this thread's MKL threads for the call (no effect on the sequential layer); one
        # below THREADED_UNKNOWNS, where waking the others costs more than they bring
        threads = thread_limit() if self.n >= THREADED_UNKNOWNS else 1
        previous = lib.MKL_Set_Num_Threads_Local(ctypes.c_int(threads))
        lib.pardiso(self._pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)), ref(1), ref(1),
                    ref(mtype), ref(phase), ref(self.n), a.ctypes.data_as(ctypes.c_void_p),
                    self._ia.ctypes.data_as(i32), self._ja.ctypes.data_as(i32),
                    self._order.ctypes.data_as(i32), ref(b.shape[1]),
                    iparm.ctypes.data_as(i32), ref(0), b.ctypes.data_as(ctypes.c_void_p),
                    x.ctypes.data_as(ctypes.c_void_p), ctypes.byref(error))
        lib.MKL_Set_Num_Threads_Local(ctypes.c_int(previous))
        if error.value == -4:
            raise NotPositiveDefinite("PARDISO: the matrix is not positive definite "
                                      "(zero or negative pivot)")
        if error.value != 0:
            raise SolverError(f"PARDISO phase {phase} failed with error {error.value}")
        if phase == 22:
            self.perturbed = int(iparm[13])
        return x
