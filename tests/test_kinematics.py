"""The rotating disk under the face (fem_twin.macro.laws.kinematics), against references that do
not share the twin's Cartesian grid: a sector thrust pad solved in polar coordinates, a
face with the disk's rotational symmetry, mass balance through a cavity, and the limit of
an infinite track radius.

The sector pad's Cartesian grid cuts its curved and slanted edges in steps, a first-order
error of the domain (-3.3 % of the load at 0.1 mm, -1.65 % at 0.05 mm); one Richardson
step removes it, which leaves the kinematics' own error (0.02 % at 0.2 / 0.1 mm).
"""

import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fem_twin.macro import BOUNDARY_FRICTION, Lubricant, MacroSettings, solve_mixed, solve_reynolds
from fem_twin.macro.film.couette import couette_matrix
from fem_twin.macro.film.reynolds import fe_poiseuille, trapezoid_weights
from fem_twin.macro.laws.friction import face_slope
from fem_twin.macro.laws.kinematics import disk_velocity, in_grid_frame, rotations
from fem_twin.micro.flow_factors import LocalFactors

sys.path.insert(0, str(Path(__file__).parent))
from sample_cases import macro_case  # noqa: E402

MU, OMEGA = 0.05, 100.0
#: a sector pad: radii, angle, films (thick at the inlet, large polar angle)
R1, R2, BETA, H_MIN, H_MAX = 20e-3, 40e-3, np.radians(40), 10e-6, 20e-6
T_LO = np.pi / 2 - BETA / 2


def sector_film(t):
    return H_MIN + (H_MAX - H_MIN) * (t - T_LO) / BETA


def polar_sector(n):
    """Load [N], the pad's friction force along x1 [N] and centre of pressure (x1, x2) [m]
    of the sector pad in polar coordinates (r, t), the runner turning at -OMEGA about the
    origin: ``d/dr(r h^3 dp/dr) + (1/r) d/dt(h^3 dp/dt) = -6 mu omega r dh/dt``, five-point
    conservative differences on an (n+1)^2 grid, p = 0 on the pad's edges."""
    r, t = np.linspace(R1, R2, n + 1), np.linspace(T_LO, T_LO + BETA, n + 1)
    dr, dt = r[1] - r[0], t[1] - t[0]
    R, T = np.meshgrid(r, t, indexing="ij")
    idx = np.arange(R.size).reshape(R.shape)
    i, c = idx[1:-1, 1:-1].ravel(), (slice(1, -1), slice(1, -1))
    Rc, Tc, h3 = R[c], T[c], sector_film(T[c]) ** 3
    links = (((Rc + dr / 2) * h3 / dr ** 2, idx[2:, 1:-1]),
             ((Rc - dr / 2) * h3 / dr ** 2, idx[:-2, 1:-1]),
             (sector_film(Tc + dt / 2) ** 3 / (Rc * dt ** 2), idx[1:-1, 2:]),
             (sector_film(Tc - dt / 2) ** 3 / (Rc * dt ** 2), idx[1:-1, :-2]))
    edge = np.setdiff1d(idx.ravel(), i)
    rows = np.concatenate([np.r_[i, i] for _ in links] + [edge])
    cols = np.concatenate([np.r_[nb.ravel(), i] for _, nb in links] + [edge])
    vals = np.concatenate([np.r_[k.ravel(), -k.ravel()] for k, _ in links] + [np.ones(edge.size)])
    rhs = np.zeros(R.size)
    rhs[i] = (-6 * MU * OMEGA * Rc * (H_MAX - H_MIN) / BETA).ravel()
    A = sp.csc_matrix((vals, (rows, cols)), shape=(R.size, R.size))
    p = spla.spsolve(A, rhs).reshape(R.shape)
    trap = np.r_[0.5, np.ones(n - 1), 0.5]
    w = np.outer(trap * dr, trap * dt) * R                        # r dr dt
    load = (p * w).sum()
    slope = -np.sin(T) / R * (H_MAX - H_MIN) / BETA              # dh/dx1
    # shear mu u . e1 / h minus (h/2) dp/dx1, the latter by parts (p = 0 on the edge)
    # -(p dh/dx1) / 2 + ... together with the slope force -p dh/dx1: -(1/2) p dh/dx1
    friction = ((MU * OMEGA * R * np.sin(T) / sector_film(T) - p * slope / 2) * w).sum()
    return load, friction, ((p * w * R * np.cos(T)).sum() / load,
                            (p * w * R * np.sin(T)).sum() / load)


def twin_sector(dx, method, rotating=True):
    """The same pad on the twin's Cartesian grid (the axis at the origin, the grid's x2
    radial), the disk's velocity of :func:`disk_velocity` about the pad's centroid."""
    x1, x2 = np.arange(-14e-3, 14e-3 + dx / 2, dx), np.arange(18e-3, 41e-3 + dx / 2, dx)
    X1, X2 = np.meshgrid(x1, x2)
    r, t = np.hypot(X1, X2), np.arctan2(X2, X1)
    pad = (r >= R1) & (r <= R2) & (t >= T_LO) & (t <= T_LO + BETA)
    gap = np.where(pad, sector_film(t), 1e-3)
    radius = float(X2[pad].mean())                      # the centroid's distance to the axis
    v = disk_velocity(pad, (dx, dx), radius) if rotating else None
    res = solve_reynolds(gap, (dx, dx), OMEGA * radius, MU, method=method, velocity=v)
    p = res.pressure
    c, _, speed = rotations(v) if rotating else (1.0, 0.0, 1.0)
    tau = (MU * OMEGA * radius * speed * c / gap - gap / 2 * np.gradient(p, dx, axis=1)
           - p * face_slope(gap, pad, dx))
    w = trapezoid_weights(p.shape, (dx, dx))
    return res.load, float(tau[pad].sum() * dx * dx), ((p * w * X1).sum() / res.load,
                                                       (p * w * X2).sum() / res.load)


@pytest.fixture(scope="module")
def polar_reference():
    """The polar solution at 400^2, second order: 200^2 differs by 8e-5 in the load."""
    return polar_sector(400)


@pytest.mark.parametrize("method", ["fe", "fvm"])
def test_a_sector_pad_on_the_rotating_disk_matches_the_polar_solution(polar_reference, method):
    """Load, friction along x1 and centre of pressure of a 20-40 mm, 40 degree sector pad:
    the Cartesian twin converges at first order (its stepped edges) to the polar solution,
    and its Richardson extrapolation from 0.2 and 0.1 mm is within 0.1 % of it (load,
    friction); at 0.1 mm its centre of pressure is within 25 um (0.12 % of the pad's
    20 mm; measured 22 and 4 um).  The uniform model puts it 0.35 mm too close to the
    axis."""
    load, friction, (c1, c2) = polar_reference
    coarse, fine = twin_sector(0.2e-3, method), twin_sector(0.1e-3, method)
    assert 1.6 < (coarse[0] - load) / (fine[0] - load) < 2.4        # first order
    assert abs(2 * fine[0] - coarse[0] - load) < 1e-3 * load
    assert abs(2 * fine[1] - coarse[1] - friction) < 1e-3 * friction
    assert abs(fine[2][0] - c1) < 25e-6 and abs(fine[2][1] - c2) < 25e-6
    assert twin_sector(0.1e-3, method, rotating=False)[2][1] < c2 - 3e-4


@pytest.mark.parametrize("method", ["fe", "fvm"])
def test_a_face_with_the_disks_symmetry_carries_no_load(method):
    """Waves concentric with the disk's axis: the film is steady in the disk's motion, so
    the exact pressure is zero; the twin's load falls at second order (1.4e-3, 3.6e-4 of
    the same face's load under uniform sliding, at 65 and 129 nodes)."""
    ratios = []
    for n in (65, 129):
        x = np.linspace(-4e-3, 4e-3, n)
        dx, (X1, X2) = x[1] - x[0], np.meshgrid(x, x)
        h = 10e-6 + 2e-6 * np.cos(2 * np.pi * (np.hypot(X1, X2 + 30e-3) - 30e-3) / 8e-3)
        v = disk_velocity(np.ones(h.shape, bool), (dx, dx), 30e-3)
        rotating = solve_reynolds(h, (dx, dx), 1.0, MU, method=method, velocity=v)
        ratios.append(rotating.load / solve_reynolds(h, (dx, dx), 1.0, MU, method=method).load)
    assert abs(ratios[0]) < 3e-3 and 3.2 < ratios[0] / ratios[1] < 4.8


def test_mass_is_conserved_through_a_cavity_on_the_rotating_disk():
    """A pocket between two radial lines (twice the film): its exact solution is p = 0 and
    theta = 1/2, the liquid filling half the pocket.  The discrete balance of every dual
    cell holds to the solver's tolerance, the boundary's fluxes sum to zero (round-off),
    and theta inside the pocket is 1/2 within 1.2 % (the stepped radial walls)."""
    n, R = 129, 30e-3
    x = np.linspace(-4e-3, 4e-3, n)
    dx, (X1, X2) = x[1] - x[0], np.meshgrid(x, x)
    angle = np.arctan2(X1, X2 + R)
    h = np.where(np.abs(angle) < 0.04, 20e-6, 10e-6)
    v = disk_velocity(np.ones(h.shape, bool), (dx, dx), R)
    res = solve_reynolds(h, (dx, dx), 1.0, MU, velocity=v, ambient_pressure=1e5,
                         cavitation_pressure=1e5)
    q = h * 1.0 / 2
    flux = (fe_poiseuille(h ** 3 / (12 * MU), (dx, dx)) @ (res.pressure - 1e5).ravel()
            + couette_matrix(q * v[..., 0], q * v[..., 1], (dx, dx))
            @ (1 - res.cavity_fraction).ravel()).reshape(h.shape)
    scale = dx * q.max()
    interior = np.zeros(h.shape, bool)
    interior[1:-1, 1:-1] = True
    assert np.abs(flux[interior]).max() < 1e-8 * scale
    assert abs(flux.sum()) < 1e-12 * np.abs(flux[~interior]).sum()
    inside = (np.abs(angle) < 0.04 - 3 * dx / R) & (np.abs(X2) < 3e-3)
    assert np.abs(res.cavity_fraction[inside] - 0.5).max() < 0.012 * 0.5


def test_the_cell_frame_turns_into_the_grid():
    """Rotations: isotropic tensors stay, ``b = e1`` turns into the sliding direction, and
    turning by phi then -phi gives the factors back."""
    rng = np.random.default_rng(1)
    v = np.stack([1 + 0.1 * rng.random((3, 4)), 0.2 * rng.standard_normal((3, 4))], -1)
    A = rng.random((3, 4, 2, 2))
    loc = LocalFactors(h0=np.ones((3, 4)), h_m=np.ones((3, 4)), p_con=None,
                       A=np.broadcast_to(2 * np.eye(2), (3, 4, 2, 2)),
                       b=np.tile([1.0, 0.0], (3, 4, 1)), C=A, d=None, friction_factor=None,
                       pressure_friction=None, contact_fraction=None)
    moved = in_grid_frame(loc, rotations(v))
    c, s, _ = rotations(v)
    assert np.allclose(moved.A, 2 * np.eye(2)) and np.allclose(moved.b, np.stack([c, s], -1))
    back = in_grid_frame(moved, rotations(v * [1, -1]))
    assert np.allclose(back.C, A, atol=1e-14)
    assert in_grid_frame(loc, None) is loc


def test_a_far_axis_is_uniform_sliding(factors):
    """The sample pin in mixed lubrication (contact, cavitation, deformation): C_f on a
    rotating disk tends to the uniform model's as the track radius grows, at first order
    in 1 / R."""
    gap, dx, face = macro_case(32)
    cf = [solve_mixed(gap, dx, factors, load=150.0, speed=0.03, face=face,
                      lubricant=Lubricant(0.066),
                      settings=MacroSettings(track_radius=R, tol=1e-8)).friction_coefficient
          for R in (None, 0.3, 3.0)]
    assert 5 < (cf[1] - cf[0]) / (cf[2] - cf[0]) < 20
    assert abs(cf[2] / cf[0] - 1) < 1e-3


def test_the_boundary_shear_acts_along_the_local_sliding(factors):
    """On the turning disk the contacts' shear C_f,b (p_con + p a_r) (eq 32 on the
    asperities' load, :mod:`fem_twin.macro.laws.boundary_friction`) acts along the local
    sliding, and the load cell reads its x1 part: that times cos(phi) over the face, less
    than C_f,b times the asperity load by at most 1 - cos 7.6 degrees (0.9 %)."""
    gap, dx, face = macro_case(32)
    res = solve_mixed(gap, dx, factors, load=150.0, speed=0.01, face=face,
                      lubricant=Lubricant(0.066), settings=MacroSettings(track_radius=30e-3))
    c = rotations(disk_velocity(face, dx, 30e-3))[0]
    film = np.maximum(res.pressure - MacroSettings().ambient_pressure, 0.0)
    load = res.contact_pressure + film * factors.at(res.h0).contact_fraction
    along = BOUNDARY_FRICTION * (load * c)[face].sum() * dx[0] * dx[1]
    whole = BOUNDARY_FRICTION * load[face].sum() * dx[0] * dx[1]
    assert res.boundary_force == pytest.approx(along, rel=1e-12)
    assert along == pytest.approx(BOUNDARY_FRICTION * res.asperity_load, rel=1e-12)
    assert 0.991 * whole < along < whole


def test_the_case_turns_the_disk_at_its_track_radius(tmp_path):
    """``[tribometer] kinematics``: the pin turns at ``sliding_radius`` (default), a ball at
    ``track_radius``; ``"uniform"`` is the paper's sliding; anything else is refused."""
    from fem_twin.case import CaseError, load_case
    from fem_twin.stages.requests import macro_settings
    root = Path(__file__).resolve().parents[1] / "examples"
    assert macro_settings(load_case(root / "pin_on_disk.toml")).track_radius == 30e-3
    assert macro_settings(load_case(root / "ball_on_disk.toml")).track_radius == 20e-3
    text = (root / "pin_on_disk.toml").read_text().replace("../meshes/",
                                                           str(root.parent / "meshes") + "/")
    for value, expect in (('"uniform"', None), ('"spinning"', "kinematics")):
        (tmp_path / "case.toml").write_text(text.replace('kinematics = "rotating"',
                                                         f"kinematics = {value}"))
        if expect is None:
            assert macro_settings(load_case(tmp_path / "case.toml")).track_radius is None
        else:
            with pytest.raises(CaseError, match=expect):
                load_case(tmp_path / "case.toml")
    (tmp_path / "radius.toml").write_text(text.replace("[macro]", "[macro]\ntrack_radius = 0.03",
                                                       1))
    with pytest.raises(CaseError, match="set by"):
        load_case(tmp_path / "radius.toml")


def test_a_disk_axis_under_the_ball_is_refused_when_the_case_is_read():
    """A track radius inside the ball's grid (three Hertz radii, 322 um for
    the bundled ball: a = 107 um) is refused when the case is read, naming the key, rather
    than at the Stribeck stage after the micro stage."""
    import tomllib
    from pathlib import Path

    from fem_twin.case import parse_case
    from fem_twin.errors import InputError
    path = Path(__file__).parents[1] / "examples" / "ball_on_disk.toml"
    data = tomllib.loads(path.read_text())
    data["tribometer"]["track_radius"] = 2e-4
    with pytest.raises(InputError, match=r"track_radius = 0.0002 m: .*0.00032\d* m"):
        parse_case(data, base=path.parent, source=path)
    data["tribometer"]["track_radius"] = 4e-4
    assert parse_case(data, base=path.parent, source=path).tribometer.track_radius == 4e-4


def test_the_torque_reading_is_the_force_reading_on_a_sliding_disk(factors):
    """``reading = "torque"``: the disk's drag times its lever ``|v| = r / R`` over the face.
    Under uniform sliding it equals the load cell's force on the pin (the force on the pin
    is the force on the disk): within 1e-5 of C_f at 32^2 (measured 9.9e-6 at 1 m/s, 6e-6
    at 64^2: the face-edge term).  On the disk turning at R = 30 mm the reading differs: in
    full film it is 0.68 % (32^2) and 0.62 % (64^2) above the force, the film's shear
    growing with the speed and the lever on the outer side; in mixed lubrication the
    contacts sit a little inside the track and it reads 0.16 % and 0.09 % less."""
    gap, dx, face = macro_case(32)
    point = lambda radius, reading, speed: solve_mixed(  # noqa: E731
        gap, dx, factors, load=150.0, speed=speed, face=face, lubricant=Lubricant(0.066),
        settings=MacroSettings(track_radius=radius, reading=reading, tol=1e-8))
    for speed in (1.0, 0.05):
        ratio = point(None, "torque", speed).friction_coefficient / point(
            None, "force", speed).friction_coefficient
        assert abs(ratio - 1) < 1e-5
    full = point(30e-3, "torque", 1.0).friction_coefficient / point(
        30e-3, "force", 1.0).friction_coefficient
    assert 0.003 < full - 1 < 0.01
    from fem_twin.errors import InputError
    with pytest.raises(InputError, match="friction"):
        MacroSettings(reading="torque", friction="paper")
