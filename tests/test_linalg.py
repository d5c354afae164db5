"""Sparse SPD solves with a fixed pattern (fem_twin.numerics.linalg): SuperLU and MKL PARDISO."""

import pickle

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from hypothesis import given, settings
from hypothesis import strategies as st

from fem_twin.errors import InputError
from fem_twin.fvm import CellSolverFV
from fem_twin.macro.film.stencil_solver import _stencil_pattern
from fem_twin.micro import CellSolver
from fem_twin.numerics.linalg import SPDSolver, _mkl_rt, default_backend
from fem_twin.numerics.ordering import nested_dissection, subgrid_order

BACKENDS = ["superlu", pytest.param("pardiso", marks=pytest.mark.skipif(
    _mkl_rt() is None, reason="MKL not installed (pip install 'fem-twin[pardiso]')"))]


def diffusion(n, seed):
    """Periodic 5-point operator with random positive face weights plus a small mass term:
    SPD with a fixed pattern, as the cell operators."""
    rng = np.random.default_rng(seed)
    idx = np.arange(n * n).reshape(n, n)
    i = np.r_[idx.ravel(), idx.ravel()]
    j = np.r_[np.roll(idx, -1, 1).ravel(), np.roll(idx, -1, 0).ravel()]
    w = 10.0 ** rng.uniform(-6, 0, i.size)              # 1e6 contrast, like a rough gap
    K = sp.coo_matrix((np.r_[w, w, -w, -w], (np.r_[i, j, i, j], np.r_[i, j, j, i])),
                      shape=(n * n, n * n)).tocsr() + 1e-3 * sp.identity(n * n)
    K.sum_duplicates()
    K.sort_indices()
    return K


@pytest.mark.parametrize("backend", BACKENDS)
def test_factor_and_refactor_solve_exactly(backend):
    """Residual at round-off for two matrices on one pattern (the second one reuses the
    symbolic analysis), several right-hand sides."""
    K1, K2 = diffusion(24, 1), diffusion(24, 2)
    assert np.array_equal(K1.indices, K2.indices)
    solver = SPDSolver(K1.indptr, K1.indices, backend)
    rhs = np.random.default_rng(0).standard_normal((K1.shape[0], 3))
    for K in (K1, K2, K1):
        x = solver.factor(K.data).solve(rhs)
        assert np.abs(K @ x - rhs).max() < 1e-9 * np.abs(rhs).max()
        assert np.allclose(x, spla.spsolve(K.tocsc(), rhs), rtol=1e-8, atol=1e-10)
    one = solver.solve(rhs[:, 0])
    assert one.shape == (K1.shape[0],) and np.allclose(one, x[:, 0], rtol=1e-12)


@pytest.mark.parametrize("backend", BACKENDS)
def test_pickled_solver_needs_a_new_factorisation(backend):
    K = diffusion(8, 3)
    solver = SPDSolver(K.indptr, K.indices, backend).factor(K.data)
    clone = pickle.loads(pickle.dumps(solver))
    with pytest.raises(RuntimeError, match="factor"):
        clone.solve(np.ones(K.shape[0]))
    b = np.ones(K.shape[0])
    assert np.allclose(clone.factor(K.data).solve(b), solver.solve(b), rtol=1e-12)


@pytest.mark.skipif(_mkl_rt() is None, reason="MKL not installed")
@pytest.mark.parametrize("symmetric", [True, False])
def test_single_precision_factors_refine_to_double_and_release(symmetric):
    """Single-precision factors solve to single-precision accuracy (unit round-off 6e-8
    times the condition number, here under 1e-3), and a few steps of refinement with the
    residual in double precision reach round-off; after ``release`` the analysis is kept
    and the next matrix factorises."""
    K = diffusion(24, 5)
    rhs = np.random.default_rng(1).standard_normal(K.shape[0])
    solver = SPDSolver(K.indptr, K.indices, "pardiso", symmetric=symmetric, single=True)
    for _ in range(2):
        x = solver.factor(K.data).solve(rhs)
        first = np.linalg.norm(K @ x - rhs) / np.linalg.norm(rhs)
        assert x.dtype == np.float64 and 1e-12 < first < 1e-3
        for _ in range(4):
            x = x + solver.solve(rhs - K @ x)
        assert np.linalg.norm(K @ x - rhs) < 1e-13 * np.linalg.norm(rhs)
        solver.release()
    with pytest.raises(RuntimeError, match="factor"):
        solver.solve(rhs)


@pytest.mark.skipif(_mkl_rt() is None, reason="MKL not installed")
def test_pardiso_rejects_an_indefinite_matrix():
    K = diffusion(8, 4)
    K.data[K.indices == np.repeat(np.arange(64), np.diff(K.indptr))] *= -1  # flip diagonal
    with pytest.raises(np.linalg.LinAlgError, match="positive definite"):
        SPDSolver(K.indptr, K.indices, "pardiso").factor(K.data)


def test_backend_choice(monkeypatch):
    K = diffusion(4, 5)
    with pytest.raises(ValueError, match="backend"):
        SPDSolver(K.indptr, K.indices, "cholmod")
    monkeypatch.setenv("FEM_TWIN_SPARSE", "superlu")
    assert default_backend() == "superlu"
    monkeypatch.setenv("FEM_TWIN_SPARSE", "umfpack")
    with pytest.raises(ValueError, match="FEM_TWIN_SPARSE"):
        default_backend()
    monkeypatch.setenv("FEM_TWIN_SPARSE", "auto")
    assert default_backend() == ("pardiso" if _mkl_rt() is not None else "superlu")


@pytest.mark.skipif(_mkl_rt() is None, reason="MKL not installed")
@pytest.mark.parametrize("solver", [CellSolver, CellSolverFV])
def test_cell_moments_do_not_depend_on_the_backend(solver):
    rng = np.random.default_rng(6)
    h = 1e-7 * (1 + 3 * rng.random((32, 24)))
    h[rng.random(h.shape) < 0.2] = 1e-9                 # contact spots at the gap floor
    tau = 0.1 * rng.standard_normal(h.shape)
    a = solver(h.shape, (1e-7, 1.2e-7), backend="superlu").solve(h, tau)
    b = solver(h.shape, (1e-7, 1.2e-7), backend="pardiso").solve(h, tau)
    for key in a.moments:
        assert np.allclose(a.moments[key], b.moments[key], rtol=1e-9,
                           atol=1e-12 * np.abs(a.moments[key]).max()), key


def test_one_thread_while_computing_and_restored_after(monkeypatch):
    """BLAS/OpenMP pools hold one thread inside fem_twin's entry points (FEM_TWIN_THREADS
    raises it) and get their previous sizes back afterwards: importing changes nothing."""
    from threadpoolctl import threadpool_info, threadpool_limits

    from fem_twin.numerics.threads import one_thread

    inside = one_thread(lambda: {p["internal_api"]: p["num_threads"] for p in threadpool_info()})
    with threadpool_limits(limits=2):
        before = {p["internal_api"]: p["num_threads"] for p in threadpool_info()}
        assert set(inside().values()) <= {1}
        monkeypatch.setenv("FEM_TWIN_THREADS", "2")
        assert set(inside().values()) <= {1, 2}
        after = {p["internal_api"]: p["num_threads"] for p in threadpool_info()}
    assert after == before
    monkeypatch.setenv("FEM_TWIN_THREADS", "two")
    with pytest.raises(ValueError, match="FEM_TWIN_THREADS"):
        inside()


def test_anderson_mixing_is_gmres_on_a_linear_map():
    """x = G x + c with a slow contraction (spectral radius 0.95): Anderson with memory >=
    the dimension n reaches the fixed point in at most n + 1 steps (GMRES equivalence),
    where the plain iteration needs hundreds, damped or not (the damped steps span the same
    Krylov space); depth 0 is the plain iteration."""
    from fem_twin.numerics.anderson import Anderson
    rng = np.random.default_rng(5)
    n = 6
    Q = np.linalg.qr(rng.normal(size=(n, n)))[0]
    G = Q @ np.diag(np.linspace(-0.95, 0.95, n)) @ Q.T
    c = rng.normal(size=n)
    exact = np.linalg.solve(np.eye(n) - G, c)

    def solve(depth, steps, beta=1.0):
        mixer, x = Anderson(depth, beta), np.zeros(n)
        for _ in range(steps):
            x = mixer.step(x, G @ x + c - x)
        return np.linalg.norm(x - exact) / np.linalg.norm(exact)

    assert solve(depth=8, steps=n + 1) < 1e-9
    assert solve(depth=8, steps=n + 1, beta=0.5) < 1e-9
    plain = solve(depth=0, steps=n + 1)
    x = np.zeros(n)
    for _ in range(n + 1):
        x = G @ x + c
    assert plain == pytest.approx(np.linalg.norm(x - exact) / np.linalg.norm(exact), rel=1e-12)
    assert plain > 0.5


def test_pardiso_runs_the_threads_fem_twin_threads_allows():
    """FEM_TWIN_THREADS=2 when MKL first loads: MKL's OpenMP layer, and PARDISO called with
    two threads on a matrix of THREADED_UNKNOWNS or more (a lone large point), one below,
    the same factors to round-off as the default sequential layer (one process each: the
    layer is chosen at load).  The threads are those the solver asks MKL for, not timed:
    CPU over wall time depends on the machine's load."""
    if _mkl_rt() is None:
        pytest.skip("MKL not installed")
    import json
    import os
    import subprocess
    import sys

    from fem_twin.numerics.linalg import THREADED_UNKNOWNS
    script = (
        "import json, numpy as np, sys\n"
        "sys.path.insert(0, 'tests')\n"
        "from test_linalg import diffusion\n"
        "from fem_twin.numerics.linalg import SPDSolver, _mkl_rt\n"
        "lib, asked = _mkl_rt(), []\n"
        "setter = lib.MKL_Set_Num_Threads_Local\n"
        "def spy(n):\n"
        "    asked.append(n.value)\n"
        "    return setter(n)\n"
        "lib.MKL_Set_Num_Threads_Local = spy\n"
        "from threadpoolctl import threadpool_info\n"
        "out = {}\n"
        f"for n in (200, {int(np.sqrt(THREADED_UNKNOWNS)) + 2}):\n"
        "    K = diffusion(n, seed=1)\n"
        "    s = SPDSolver(K.indptr, K.indices, 'pardiso').factor(K.data)\n"
        "    del asked[:]\n"
        "    s.factor(K.data)\n"
        "    x = s.solve(np.ones(K.shape[0]))\n"
        "    out[n] = {'x': x[:50].tolist(), 'threads': max(asked)}\n"
        "mkl = [i for i in threadpool_info() if i['internal_api'] == 'mkl']\n"
        "print(json.dumps({'runs': list(out.values()), 'layer': [i.get('threading_layer') "
        "for i in mkl]}))\n")
    out = {}
    for threads in ("1", "2"):
        env = {k: v for k, v in os.environ.items() if not k.startswith("MKL_")}
        env["FEM_TWIN_THREADS"] = threads
        run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                             env=env, cwd=os.path.dirname(os.path.dirname(__file__)),
                             check=True)
        out[threads] = json.loads(run.stdout.splitlines()[-1])
    assert out["1"]["layer"] == ["sequential"] and out["2"]["layer"] == ["intel"]
    (small1, large1), (small2, large2) = out["1"]["runs"], out["2"]["runs"]
    assert (small1["threads"], large1["threads"], small2["threads"], large2["threads"]) == (
        1, 1, 1, 2)
    for one, two in ((small1, small2), (large1, large2)):
        assert np.allclose(one["x"], two["x"], rtol=1e-10, atol=0)


def test_anderson_seeded_with_the_pairs_of_a_related_map():
    """Anderson.seed: started from the differences of a run on the same linear map (as a
    coarser grid's solve hands its last pairs to the finer one), the first step already
    mixes the slow modes out: with pairs spanning the space it lands on the fixed point at
    once, and with pairs of a perturbed map it still needs fewer steps than from nothing;
    pairs() gives the last differences oldest first."""
    from fem_twin.numerics.anderson import Anderson
    rng = np.random.default_rng(7)
    n = 6
    Q = np.linalg.qr(rng.normal(size=(n, n)))[0]
    G = Q @ np.diag(np.linspace(-0.95, 0.95, n)) @ Q.T
    c = rng.normal(size=n)
    exact = np.linalg.solve(np.eye(n) - G, c)

    def run(G, mixer, steps):
        x = np.zeros(n)
        for _ in range(steps):
            x = mixer.step(x, G @ x + c - x)
        return x

    first = Anderson(8, 0.5)
    run(G, first, n + 1)
    dx, df = first.pairs(n)
    assert dx.shape == (n, n) and np.allclose(df, dx @ (G - np.eye(n)).T)
    seeded = Anderson(8, 0.5)
    seeded.seed(dx, df)
    assert np.linalg.norm(run(G, seeded, 1) - exact) < 1e-9 * np.linalg.norm(exact)
    near = G + 0.02 * Q @ np.diag(rng.uniform(-1, 1, n)) @ Q.T
    exact = np.linalg.solve(np.eye(n) - near, c)

    def steps(mixer):
        x = np.zeros(n)
        for k in range(1, 100):
            x = mixer.step(x, near @ x + c - x)
            if np.linalg.norm(x - exact) < 1e-8 * np.linalg.norm(exact):
                return k
    seeded = Anderson(8, 0.5)
    seeded.seed(*first.pairs(4))
    assert steps(seeded) < steps(Anderson(8, 0.5))


def _recursive_dissection(rows, cols, nx, out, leaf):
    """The textbook recursion of nested dissection (the oracle of the vectorised one)."""
    if len(rows) * len(cols) <= leaf * leaf or min(len(rows), len(cols)) < 3:
        out.append((rows[:, None] * nx + cols[None, :]).ravel())
    elif len(cols) >= len(rows):
        m = len(cols) // 2
        _recursive_dissection(rows, cols[:m], nx, out, leaf)
        _recursive_dissection(rows, cols[m + 1:], nx, out, leaf)
        out.append(rows * nx + cols[m])
    else:
        m = len(rows) // 2
        _recursive_dissection(rows[:m], cols, nx, out, leaf)
        _recursive_dissection(rows[m + 1:], cols, nx, out, leaf)
        out.append(rows[m] * nx + cols)


@settings(max_examples=60, deadline=None)
@given(ny=st.integers(1, 90), nx=st.integers(1, 90), leaf=st.integers(1, 6))
def test_nested_dissection_is_the_recursive_order(ny, nx, leaf):
    """The level-at-a-time dissection orders the pixels exactly as the recursion: halves
    first, separators last, each piece row-major."""
    out = []
    _recursive_dissection(np.arange(ny), np.arange(nx), nx, out, leaf)
    assert np.array_equal(nested_dissection((ny, nx), leaf), np.concatenate(out))


@pytest.mark.skipif(_mkl_rt() is None, reason="MKL not installed")
def test_pardiso_in_a_grids_dissection_order_solves_as_in_metis_order():
    """A nonsymmetric 3x3-stencil matrix on a disc of a grid (the macro Newton matrices'
    shape) factorised in the sub-grid's nested-dissection order solves to round-off, as in
    METIS's; an order that is not a permutation is refused before any work."""
    n = 40
    y, x = np.mgrid[:n, :n] - (n - 1) / 2
    inside = (x ** 2 + y ** 2 < (0.45 * n) ** 2).ravel()
    position = np.where(inside, np.cumsum(inside) - 1, -1)
    rng = np.random.default_rng(7)
    m = int(inside.sum())
    indptr, indices = _stencil_pattern((n, n), position, m)
    rows = np.repeat(np.arange(m), np.diff(indptr))
    values = np.where(rows == indices, 10.0, rng.uniform(-1.2, 0.2, indices.size))
    J = sp.csr_matrix((values, indices, indptr), shape=(m, m))
    J.sort_indices()
    rhs = rng.standard_normal(m)
    order = subgrid_order((n, n), position)
    assert np.array_equal(np.sort(order), np.arange(m))
    for own in (None, order):
        solver = SPDSolver(J.indptr, J.indices, "pardiso", symmetric=False, order=own)
        x = solver.factor(J.data).solve(rhs)
        assert np.linalg.norm(J @ x - rhs) < 1e-12 * np.linalg.norm(rhs)
    with pytest.raises(InputError, match="permutation"):
        SPDSolver(J.indptr, J.indices, "pardiso", symmetric=False, order=order[:-1])
