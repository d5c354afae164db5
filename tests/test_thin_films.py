"""What the boundary law acts on (docs/model.md, "Boundary friction"): tau_0 on the dry
contact alone, the confined films below the boundary film as boundary films, viscous
films or nothing (``[boundary] thin_films``), in the twin and node by node in the
deterministic reference."""

import numpy as np
import pytest
from sample_cases import macro_case
from test_deterministic import OIL, rough_pad

from fem_twin import Topography
from fem_twin.macro import BoundaryLaw, Lubricant, MacroSettings, solve_mixed
from fem_twin.macro.film.reynolds import trapezoid_weights
from fem_twin.macro.reference.deterministic import DeterministicSettings, solve_deterministic
from fem_twin.micro import homogenise

SHEAR = BoundaryLaw(law="shear", shear_strength=50e6, pressure_coefficient=0.1)


def test_the_confined_films_shear_is_their_mean_inverse_gap_on_a_cosine_cell():
    """A cosine ridge (a = 0.2 um) over a flat, 3 nm apart at its crest, 256 px a period:
    ``thin_friction / h_m`` is ``<1/h>`` over the films between the 1 nm floor and the
    10 nm boundary film, whose closed form is ``(1/pi) int_theta*^pi dtheta / (H + a cos
    theta)`` with ``cos theta* = (h_b - H) / a``, and their share ``thin_area`` is ``1 -
    theta* / pi``; within 0.5 % (the cell integrates the linear interpolant of the gap
    exactly, second order in the pixel; measured -0.27 % for the mean)."""
    n, period, a, crest = 256, 100e-6, 0.2e-6, 3e-9
    x = np.arange(n) * period / n
    ridge = np.tile(a * np.cos(2 * np.pi * x / period), (4, 1))
    h0 = a + crest                                   # the mean gap H: no contact
    ff = homogenise(Topography(np.zeros_like(ridge), period / n), Topography(ridge, period / n),
                    [h0], steps=1, error_estimate=False)
    assert ff.p_con[0] == 0 and ff.h_m[0] == pytest.approx(h0, rel=1e-12)
    start = np.arccos((10e-9 - h0) / a)
    root = np.sqrt(h0 ** 2 - a ** 2)
    closed = 2 / root * (np.pi / 2 - np.arctan(np.sqrt((h0 - a) / (h0 + a))
                                               * np.tan(start / 2))) / np.pi
    assert ff.thin_friction[0] / ff.h_m[0] == pytest.approx(closed, rel=5e-3)
    assert ff.thin_area[0] == pytest.approx(1 - start / np.pi, rel=5e-3)   # their share
    assert ff.thin_friction[0] > 0.1 * ff.friction_factor[0]        # it matters here


def test_tau0_acts_on_the_dry_contact_and_viscous_films_on_the_film(factors):
    """At a slow point of the bundled pair (0.005 m/s, 150 N): the real contact area is
    the dry contact fraction's integral; tau_0 multiplies it alone, so the shear law's
    force is ``tau_0 A_r + alpha W`` to rounding whatever the thin films carry; the thin
    films as viscous films leave the solution (pressure) bit for bit, add exactly their
    Couette integral ``mu u thin_friction / h_m (1 - theta)`` (mu the film's), limited by
    the law's ``alpha p`` over their area ``thin_area`` (both bind somewhere on this face),
    to the film friction, and take their film pressure off the asperities' load."""
    gap, dx, face = macro_case(32)
    run = {t: solve_mixed(gap, dx, factors, load=150.0, speed=0.005, face=face,
                          lubricant=Lubricant(0.066),
                          settings=MacroSettings(boundary=BoundaryLaw(**{
                              **SHEAR.__dict__, "thin_films": t})))
           for t in ("boundary", "viscous", "none")}
    weights = trapezoid_weights(face.shape, dx) * face
    local = factors.at(run["none"].h0)
    dry = float(np.sum(weights * local.contact_fraction))
    for res in run.values():
        assert res.real_contact_area == pytest.approx(dry, rel=1e-12)
        assert res.boundary_force == pytest.approx(
            50e6 * res.real_contact_area + 0.1 * res.asperity_load, rel=1e-12)
    assert run["boundary"].asperity_load >= run["viscous"].asperity_load
    assert run["viscous"].asperity_load == run["none"].asperity_load
    v, n = run["viscous"], run["none"]
    assert np.array_equal(v.pressure, n.pressure)
    confined = v.viscosity * 0.005 * local.thin_friction / v.mean_gap * (1 - v.cavity_fraction)
    gauge = np.maximum(v.pressure - MacroSettings().ambient_pressure, 0.0)
    limit = 0.1 * gauge * local.thin_area                 # alpha p over the films' area
    assert v.hydrodynamic_friction - n.hydrodynamic_friction == pytest.approx(
        float(np.sum(weights * np.minimum(confined, limit))), rel=1e-9)
    assert v.hydrodynamic_friction > n.hydrodynamic_friction
    assert np.any(confined[face] > limit[face]) and np.any(confined[face] < limit[face])


@pytest.mark.parametrize("thin_films", ["boundary", "viscous", "none"])
def test_the_deterministic_pad_takes_the_twins_boundary_law(thin_films):
    """The resolved pad (2 x 2 cells of 16 px, flat, 10 MPa at 1 cm/s) under the shear law:
    its boundary force is, node by node, tau_0 on the spots (p_con > 0) plus alpha on the
    contact pressure and the film's where the gap is at most the boundary film (thin films
    as boundary films) or on the spots alone; the constant law's is C_f,b times that load
    (eq 32); viscous thin films raise the film friction and no other field."""
    _, shape, dx = rough_pad(tiles=2, cell=16)
    load = 10e6 * (32e-6) ** 2

    def solve(law):
        s = DeterministicSettings(e_reduced=2.3e11, hardness=1e9, boundary=law)
        return solve_deterministic(shape, dx, load=load, speed=0.01, lubricant=OIL, settings=s)

    shear = solve(BoundaryLaw(**{**SHEAR.__dict__, "thin_films": thin_films}))
    area = trapezoid_weights(shape.shape, dx)
    spots = shear.contact_pressure > 0
    wet = shear.gap <= 10e-9 if thin_films == "boundary" else spots
    asperity = np.sum(area * (shear.contact_pressure + np.maximum(shear.pressure, 0) * wet))
    assert spots.any() and shear.load_share > 0.3
    assert shear.boundary_force == pytest.approx(
        50e6 * np.sum(area * spots) + 0.1 * asperity, rel=1e-12)
    constant = solve(BoundaryLaw(thin_films=thin_films))
    assert constant.boundary_force == pytest.approx(0.1924500897 * asperity, rel=1e-9)
    if thin_films == "viscous":
        plain = solve(BoundaryLaw(**{**SHEAR.__dict__, "thin_films": "none"}))
        assert np.array_equal(plain.pressure, shear.pressure)
        assert shear.film_friction > plain.film_friction


@pytest.mark.integration
def test_the_boundary_share_is_cf_s_sensitivity_to_the_boundary_level(factors, tmp_path):
    """``boundary_share`` = F_b / F_T (stribeck.csv, results.nc) is the relative change of
    C_f per relative change of C_f,b (the boundary force does not feed back into an
    isothermal film): C_f,b raised 10 % raises C_f by 10 % times the share, to 1e-9."""
    from fem_twin.stribeck import SweepRequest, stribeck_sweep
    from fem_twin.stribeck.curve import write_stribeck_csv
    gap, dx, face = macro_case(32)
    curves = [stribeck_sweep(SweepRequest(gap, dx, factors, [0.3, 0.02], load=150.0,
                                          face=face, lubricant=Lubricant(0.066),
                                          settings=MacroSettings(boundary_friction=cfb)))
              for cfb in (0.15, 0.165)]
    share = curves[0].boundary_share
    assert share[0] == 0 and 0.5 < share[1] < 1          # full film, then mixed
    rise = curves[1].friction_coefficient / curves[0].friction_coefficient - 1
    assert np.allclose(rise, 0.1 * share, rtol=1e-9, atol=0)
    import csv
    with open(write_stribeck_csv(tmp_path / "s.csv", curves[:1]), newline="") as f:
        written = [float(r["boundary_share"]) for r in csv.DictReader(f)]
    assert np.allclose(written, share, rtol=1e-12)


def test_factors_of_an_earlier_version_are_recomputed_where_the_films_shear(factors,
                                                                          tmp_path):
    """A patch's factors file written before the confined films' moments reads them as none
    (zero), which is right where nothing reads them and wrong under ``thin_films =
    "viscous"``: the micro stage keeps such a file only where the case does not shear
    those films."""
    from fem_twin.micro.flow_factors import ARRAYS
    from fem_twin.stages.factors import _knows_thin
    new = factors.save(tmp_path / "new.npz")
    old = tmp_path / "old.npz"
    np.savez(old, **{k: getattr(factors, k) for k in ARRAYS if not k.startswith("thin_")},
             meta=np.array("{}"))
    assert _knows_thin(new) and not _knows_thin(old)
    assert np.all(type(factors).load(old).thin_area == 0)


@pytest.mark.integration
def test_each_shear_law_parameter_s_share_is_cf_s_sensitivity_to_it(factors):
    """``share_shear_strength`` and ``share_pressure_coefficient`` (stribeck.csv) split the
    boundary share between tau_0 and alpha: each is d ln C_f / d ln q, so raising tau_0 or
    alpha by 10 % raises C_f by 10 % times its share, to 1e-9; they add up to the
    boundary share; the constant law's one share is the boundary share."""
    from fem_twin.stribeck import SweepRequest, stribeck_sweep
    from fem_twin.stribeck.curve import parameter_shares
    gap, dx, face = macro_case(32)

    def sweep(law):
        return stribeck_sweep(SweepRequest(gap, dx, factors, [0.05, 0.01], load=150.0,
                                           face=face, lubricant=Lubricant(0.066),
                                           settings=MacroSettings(boundary=law)))
    base = sweep(SHEAR)
    shares = parameter_shares(base, SHEAR)
    assert np.allclose(shares["share_shear_strength"] + shares["share_pressure_coefficient"],
                       base.boundary_share, rtol=1e-12)
    assert np.all(shares["share_shear_strength"] > 0.05)
    for name in ("shear_strength", "pressure_coefficient"):
        up = sweep(BoundaryLaw(**{**SHEAR.__dict__, name: 1.1 * getattr(SHEAR, name)}))
        rise = up.friction_coefficient / base.friction_coefficient - 1
        assert np.allclose(rise, 0.1 * shares[f"share_{name}"], rtol=1e-9, atol=0)
    constant = sweep(BoundaryLaw())
    assert np.array_equal(parameter_shares(constant, BoundaryLaw())["share_boundary_friction"],
                          constant.boundary_share)
