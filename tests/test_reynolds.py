"""Rigid-gap Reynolds with JFO cavitation (eqs 17-18, A = I, b = e1), FE and FVM.

1D closed forms are checked on the centre row of a strip 40 times wider (x2) than long (x1):
side leakage from the ambient edges decays like exp(-pi x2 / L1) and is invisible there.
"""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from fem_twin.macro import ReynoldsNotConverged, solve_reynolds

MU, U = 0.05, 1.0


def strip(h_x, dx, ny=41, wide=40):
    length = dx * (len(h_x) - 1)
    return np.tile(h_x, (ny, 1)), (dx, wide * length / (ny - 1)), ny // 2


@pytest.mark.parametrize("method", ["fe", "fvm"])
@pytest.mark.parametrize("K, W_ref", [(0.5, 2.623252e4), (1.0, 3.177662e4), (2.0, 2.958369e4)])
def test_inclined_slider(method, K, W_ref):
    """docs/references.md slider loads; second order: 2e-4 at 101 nodes, 4x less at 201."""
    L, ho = 20e-3, 10e-6
    errs = []
    for nx in (101, 201):
        x = np.linspace(0, L, nx)
        h, dx, c = strip(ho * (1 + K * (1 - x / L)), x[1])
        r = solve_reynolds(h, dx, U, MU, method=method)
        xi = x / L
        p_ex = 6 * MU * U * L / ho ** 2 * K * xi * (1 - xi) / ((2 + K) * (1 + K * (1 - xi)) ** 2)
        errs.append(abs(np.trapezoid(r.pressure[c], x) / W_ref - 1))
        assert np.abs(r.pressure[c] - p_ex).max() < 1e-3 * p_ex.max()
        assert r.cavity_fraction.max() == 0
    assert errs[1] < 1e-3 and 3.5 < errs[0] / errs[1] < 4.5


@pytest.mark.parametrize("method", ["fe", "fvm"])
def test_rayleigh_step_converges_first_order(method):
    """Step in the middle of a cell face: first order, 0.16 % at 201 nodes, 0.08 % at 401."""
    L1, L2, h1, h2 = 12e-3, 8e-3, 20e-6, 10e-6
    p_max = 6 * MU * U * L1 * L2 * (h1 - h2) / (h1 ** 3 * L2 + h2 ** 3 * L1)
    errs = []
    for nx in (201, 401):
        x = np.linspace(0, L1 + L2, nx)
        h_x = np.where(x < L1 - 1e-12, h1, h2)
        h, dx, c = strip(h_x, x[1])
        r = solve_reynolds(h, dx, U, MU, method=method)
        errs.append(abs(np.trapezoid(r.pressure[c], x) / (p_max * (L1 + L2) / 2) - 1))
    assert errs[1] < 1e-2 and 1.8 < errs[0] / errs[1] < 2.2


def swift_stieber(x_in):
    """Rupture X_c and W' / (mu u_m R / h0) for a flooded inlet at X = -x_in (quadrature)."""
    def p(X, Xc):
        return quad(lambda s: (s * s - Xc * Xc) / (1 + s * s) ** 3, -x_in, X)[0]
    Xc = brentq(lambda Xc: p(Xc, Xc), 0.01, 2)
    w = quad(lambda X: p(X, Xc), -x_in, Xc, limit=200)[0]
    return Xc, 24 * w        # (6 mu U b^2 / h0^2) / (mu U/2 R / h0) = 24 with b^2 = 2 R h0


def test_swift_stieber_reference_quadrature():
    """The quadrature reproduces docs/references.md for an inlet at -infinity."""
    Xc, W = swift_stieber(1e3)
    assert Xc == pytest.approx(0.47513, abs=2e-5) and W == pytest.approx(4.8950, rel=1e-4)


def face_flux(h, theta):
    """The liquid flux per unit U/2 through each x1-face of a row: the face gap times the
    upstream liquid fraction, ``h_f (1 - theta_up)`` (:mod:`fem_twin.macro.film.couette`)."""
    return (h[:-1] + h[1:]) / 2 * (1 - theta[:-1])


def cylinder_load(nx, method, couette="central"):
    """Swift-Stieber cylinder on a plane, inlet at X = -6: W' / (mu u_m R / h0), x, the
    centre row's gap, theta and pressure."""
    R, h0, x_in = 10e-3, 5e-6, 6.0
    b = np.sqrt(2 * R * h0)
    x = np.linspace(-x_in * b, x_in * b, nx)
    h, dx, c = strip(h0 * (1 + (x / b) ** 2), x[1] - x[0], ny=21)
    r = solve_reynolds(h, dx, U, MU, method=method, couette=couette)
    return (np.trapezoid(r.pressure[c], x) / (MU * U / 2 * R / h0), x / b, h[c],
            r.cavity_fraction[c], r.pressure[c])


@pytest.mark.parametrize("method", ["fe", "fvm"])
def test_swift_stieber_rupture_and_load_converge_at_second_order(method):
    """Cylinder on plane with the inlet at X = -6 (exact: X_c = 0.4736, W' = 4.582): the JFO
    solution ruptures with Swift-Stieber conditions.  The central Couette flux converges at
    second order (measured -0.93 %, -0.24 %, -0.063 % at 100, 200, 400 cells: orders 1.97,
    1.93; bar: within 0.3 % at 400 cells, order above 1.8 on both refinements), and in the
    cavity the scheme's liquid flux ``h_f (1 - theta_up)`` is constant to round-off."""
    Xc_ex, W_ex = swift_stieber(6.0)
    errors = []
    for nx in (101, 201, 401):
        W, X, h, theta, p = cylinder_load(nx, method)
        errors.append(abs(W / W_ex - 1))
        assert abs(X[np.argmax(theta > 0)] - Xc_ex) < 2 * (X[1] - X[0])
        assert np.all(p[theta > 0] == 0) and np.all(theta[X < 0] == 0)
        flow = face_flux(h, theta)
        tail = ((theta > 0) & (X < 0.9 * 6.0))[:-1]
        assert np.ptp(flow[tail][1:]) < 1e-12 * flow[tail].max()
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert errors[-1] < 3e-3 and np.all(orders > 1.8)


def test_swift_stieber_with_the_papers_upwind_flux_is_first_order():
    """``couette="upwind"`` (the paper's scheme): +5.8 % at 200 cells, +3.0 % at 400,
    order 0.98, and the upwind liquid flux ``h (1 - theta)`` constant in the cavity."""
    Xc_ex, W_ex = swift_stieber(6.0)
    errors = []
    for nx in (201, 401):
        W, X, h, theta, _ = cylinder_load(nx, "fe", couette="upwind")
        errors.append(W / W_ex - 1)
        tail = (theta > 0) & (X < 0.9 * 6.0)
        assert np.ptp((h * (1 - theta))[tail][1:]) < 1e-12 * h[tail].max()
    assert 0.9 < np.log2(errors[0] / errors[1]) < 1.1 and 0.02 < errors[1] < 0.04


@pytest.mark.parametrize("method", ["fe", "fvm"])
def test_pocket_carries_no_load_and_fills_to_h1_over_h2(method):
    """Parallel slider with a pocket: exact JFO solution p = 0, theta = 1 - h1/h2.  The
    node beside the pocket's outlet wall sees the face gap (h1 + h2) / 2; the liquid flux
    through every face is U h1 / 2 (mass conservation, round-off)."""
    L, h1, h2 = 20e-3, 10e-6, 20e-6
    x = np.linspace(0, L, 201)
    h, dx, c = strip(np.where((x > 6e-3) & (x < 10e-3), h2, h1), x[1])
    r = solve_reynolds(h, dx, U, MU, method=method, ambient_pressure=1e5,
                       cavitation_pressure=1e5)
    assert abs(r.load) < 1e-12 * MU * U * L ** 2 / h1 ** 2
    theta = r.cavity_fraction[c]
    pocket = (x > 6e-3 + x[1]) & (x < 10e-3 - x[1])
    assert np.allclose(theta[pocket], 1 - h1 / h2, rtol=1e-12)
    assert np.allclose(face_flux(h[c], theta), h1, rtol=1e-12)
    assert np.all(r.pressure >= 1e5 - 1e-6)


def test_cavitation_pressure_and_ambient_shift():
    """p_hd >= p_cav everywhere; the load is measured against the ambient pressure."""
    R, h0 = 10e-3, 5e-6
    b = np.sqrt(2 * R * h0)
    x = np.linspace(-4 * b, 4 * b, 201)
    h, dx, c = strip(h0 * (1 + (x / b) ** 2), x[1] - x[0], ny=21)
    r = solve_reynolds(h, dx, U, MU, ambient_pressure=1e5, cavitation_pressure=8e4)
    assert r.pressure.min() >= 8e4 - 1e-6 and r.cavity_fraction.max() > 0
    assert np.all(r.pressure[r.cavity_fraction > 0] == 8e4)


def test_fe_and_fvm_differ_in_2d_but_converge_together():
    """A 2D bump with cavitation: the 9- and 5-point Poiseuille operators differ at second
    order (measured 0.10 %, 0.026 %, 0.0063 % at 33^2, 65^2, 129^2)."""
    diffs = []
    for n in (33, 65):
        x = np.linspace(-1, 1, n)
        X, Y = np.meshgrid(x, x)
        h = 5e-6 * (1 + 2 * X ** 2 + 2 * Y ** 2 + 0.5 * X)
        dx = (2e-3 / (n - 1), 2e-3 / (n - 1))
        fe = solve_reynolds(h, dx, U, MU, method="fe")
        fv = solve_reynolds(h, dx, U, MU, method="fvm")
        diffs.append(abs(fe.load / fv.load - 1))
    assert diffs[0] > 0 and 3.5 < diffs[0] / diffs[1] < 4.5


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="positive"):
        solve_reynolds(np.zeros((5, 5)), (1e-4, 1e-4), 1.0, 0.05)
    with pytest.raises(ValueError, match="method"):
        solve_reynolds(np.ones((5, 5)) * 1e-5, (1e-4, 1e-4), 1.0, 0.05, method="fdm")
    with pytest.raises(ValueError, match="viscosity"):
        solve_reynolds(np.ones((5, 5)) * 1e-5, (1e-4, 1e-4), 1.0, -1)
    x = np.linspace(-1, 1, 41)
    with pytest.raises(ReynoldsNotConverged):
        solve_reynolds(np.tile(1e-5 * (1 + 4 * x ** 2), (9, 1)), (1e-4, 1e-3), 1.0, 0.05,
                       max_iter=1)


def test_fbns_solves_the_same_problems_as_the_switch():
    """The paper's Fischer-Burmeister-Newton-Schur solver (FVM twin) on the Swift-Stieber
    cylinder, the pocketed slider and a 2D cavitating bump: the same pressure and cavity
    fraction as the p-theta switch (both to their 1e-10 residual tolerances; fields agree
    to 1e-6 of p_max, theta to 1e-6)."""
    R, h0, x_in = 10e-3, 5e-6, 6.0
    b = np.sqrt(2 * R * h0)
    x = np.linspace(-x_in * b, x_in * b, 401)
    cases = [strip(h0 * (1 + (x / b) ** 2), x[1] - x[0], ny=21)[:2]]
    xp = np.linspace(0, 20e-3, 201)
    cases.append(strip(np.where((xp > 6e-3) & (xp < 10e-3), 20e-6, 10e-6), xp[1])[:2])
    g = np.linspace(-1, 1, 49)
    X, Y = np.meshgrid(g, g)
    cases.append((1e-6 * (1.2 + 0.5 * np.cos(np.pi * X) * np.cos(np.pi * Y / 2)),
                  2e-3 / 48))
    for h, dx in cases:
        kw = dict(method="fvm", ambient_pressure=1e5, cavitation_pressure=8e4)
        a = solve_reynolds(h, dx, U, MU, **kw)
        f = solve_reynolds(h, dx, U, MU, complementarity="fb", **kw)
        scale = max(a.pressure.max() - 8e4, 1.0)
        assert np.abs(a.pressure - f.pressure).max() < 1e-6 * scale
        assert np.abs(a.cavity_fraction - f.cavity_fraction).max() < 1e-6
        assert f.iterations >= a.iterations
    with pytest.raises(ValueError, match="complementarity"):
        solve_reynolds(h, dx, U, MU, complementarity="lcp")


@pytest.mark.parametrize("block", [1 << 16, 22, 1])
def test_poiseuille_reassembly_equals_the_scikit_fem_form(block, monkeypatch):
    """Element-tensor re-assembly is the skfem assembly of the same form (round-off), with
    a full non-symmetric A and without A, whether the elements come in one block or in
    blocks of two rows or one."""
    import skfem

    from fem_twin.macro.film import reynolds
    monkeypatch.setattr(reynolds, "BLOCK", block)

    from skfem.helpers import dot, grad

    from fem_twin.io.mesh import grid_mesh
    from fem_twin.macro.film.reynolds import fe_poiseuille, homogenised_poiseuille_form

    @skfem.BilinearForm
    def poiseuille_form(u, v, w):
        """Pressure flow of eq 17 with a scalar coefficient ``g``, without A."""
        return w.g * dot(grad(u), grad(v))

    rng = np.random.default_rng(0)
    shape, dx = (9, 12), (1.3e-5, 1.1e-5)
    g, A = rng.random(shape), rng.random(shape + (2, 2))
    gm = grid_mesh(shape, dx)
    basis = skfem.Basis(gm.mesh, skfem.ElementQuad1(), intorder=2)

    def at(f):
        return basis.interpolate(gm.to_nodes(f))

    ref = homogenised_poiseuille_form.assemble(
        basis, g=at(g), a11=at(A[..., 0, 0]), a12=at(A[..., 0, 1]), a21=at(A[..., 1, 0]),
        a22=at(A[..., 1, 1]))
    assert abs(fe_poiseuille(g, dx, A) - ref).max() < 1e-14 * abs(ref).max()
    ref = poiseuille_form.assemble(basis, g=at(g))
    assert abs(fe_poiseuille(g, dx) - ref).max() < 1e-14 * abs(ref).max()
    with pytest.raises(ValueError, match="shape"):
        fe_poiseuille(g, dx, A[:-1])


@pytest.mark.parametrize("scale", [1e5, 1e8])
def test_a_newton_step_reuses_the_factors_of_its_inner_solve(monkeypatch, scale):
    """fem_twin.macro.film.stencil_solver: within one inner solve (K and B fixed) a Newton step
    whose switch differs from the factorised one in a few nodes is solved with the kept
    factors updated for the switched columns (Woodbury) to STEP_RTOL, without a new
    factorisation, each switched column solved once however many steps it stays switched;
    one with more switched nodes than half a factorisation's cost allows factorises anew;
    release() frees the factors.  ``scale`` 1e8 makes a cavity node's column 1e-8 of a film
    node's, as on the 2048^2 pin where GMRES with the kept factors failed such steps."""
    import scipy.sparse as sp

    from fem_twin.macro.film import stencil_solver as ss
    from fem_twin.macro.film.couette import couette_matrix
    from fem_twin.macro.film.reynolds import fe_poiseuille
    from fem_twin.numerics.linalg import SPDSolver, default_backend
    if default_backend() != "pardiso":
        pytest.skip("the stencil solver needs MKL PARDISO")
    rng = np.random.default_rng(4)
    n, dx = 48, (1e-4, 1e-4)
    h = 1e-6 * (1 + rng.uniform(0, 4, (n, n)))
    K = fe_poiseuille(h ** 3 / (12 * MU), dx)
    B = couette_matrix(h * U / 2, 0 * h, dx)
    dirichlet = np.zeros((n, n), bool)
    dirichlet[[0, -1]] = dirichlet[:, [0, -1]] = True
    interior = np.flatnonzero(~dirichlet)
    factorisations, solves = [], []
    monkeypatch.setattr(SPDSolver, "factor", lambda self, v, f=SPDSolver.factor:
                        factorisations.append(1) or f(self, v))
    monkeypatch.setattr(SPDSolver, "solve", lambda self, r, f=SPDSolver.solve:
                        solves.append(1) or f(self, r))
    step = ss.newton_solver(dirichlet.shape, dirichlet.ravel(), interior, K, B)
    pos = rng.uniform(size=interior.size) < 0.7
    rhs = rng.normal(size=interior.size)

    def solved(pos):
        solves.clear()
        x = step(pos, np.where(pos, 0.0, 1 / scale), rhs)
        J = (K @ sp.diags(np.isin(np.arange(n * n), interior[pos]) * 1.0)
             + B @ sp.diags(np.where(np.isin(np.arange(n * n), interior[pos]), 0, 1 / scale))
             )[interior][:, interior]
        return np.linalg.norm(J @ x - rhs) / np.linalg.norm(rhs)

    assert solved(pos) < ss.STEP_RTOL and len(factorisations) == 1
    few = pos.copy()                          # 2116 unknowns: a budget of 3 solves
    for node in rng.choice(pos.size, 3, replace=False):    # one more switched per step
        few[node] ^= True
        assert solved(few) < ss.STEP_RTOL and len(factorisations) == 1
        assert len(solves) <= 1 + 1 + ss.REFINEMENTS      # the new column, refinements
    assert solved(pos) < ss.STEP_RTOL and len(factorisations) == 1   # all switched back
    many = pos.copy()
    many[rng.choice(pos.size, 40, replace=False)] ^= True
    assert solved(many) < ss.STEP_RTOL and len(factorisations) == 2
    step.release()
    assert ss._grid(dirichlet.shape, dirichlet.ravel(), interior).budget() == 0


def test_a_settled_solve_stops_once_its_active_set_has_settled():
    """fem_twin.macro.film.switch: ``settle`` truncates the semismooth Newton path (the same
    steps, fewer of them) at the first step that switches at most that fraction of the
    nodes the first step switched, not earlier; ``settle=0`` solves to convergence (the
    2D cavitating bump from an ambient start: 4501, 2190, 1463, 767, 114, 42 nodes switch)."""
    from fem_twin.macro.film.couette import couette_matrix
    from fem_twin.macro.film.reynolds import fe_poiseuille
    from fem_twin.macro.film.switch import solve_complementarity
    n, settle = 97, 0.1
    g = np.linspace(-1, 1, n)
    X, Y = np.meshgrid(g, g)
    h = 1e-6 * (1.2 + 0.5 * np.cos(np.pi * X) * np.cos(np.pi * Y / 2))
    dx = (2e-3 / (n - 1),) * 2
    K, B = fe_poiseuille(h ** 3 / (12 * MU), dx), couette_matrix(h * U / 2, 0 * h, dx)
    dirichlet = np.zeros((n, n), bool)
    dirichlet[[0, -1]] = dirichlet[:, [0, -1]] = True
    args = (K, B, dirichlet, 0.0, 1e5)
    _, exact_its, exact_history = solve_complementarity(*args)
    phi, its, history = solve_complementarity(*args, settle=settle)
    assert its < exact_its and history == exact_history[:len(history)]

    def after(steps):
        return (solve_complementarity(*args, max_iter=steps, inexact=True)[0] >= 0
                if steps else np.ones(n * n, bool))
    first = np.count_nonzero(after(1) != after(0))
    last, before = (np.count_nonzero(after(k) != after(k - 1)) for k in (its - 1, its - 2))
    assert last <= settle * first < before
    assert np.array_equal(phi >= 0, after(its - 1))
