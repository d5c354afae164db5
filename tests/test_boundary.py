"""The boundary shear law (fem_twin.macro.laws.boundary_laws and .boundary_friction,
docs/model.md "Boundary friction"): its constant limit bit for bit, a single Hertzian
asperity, one decade of speed, and the case file's [boundary] section."""

import numpy as np
import pytest
from sample_cases import macro_case

from fem_twin import Topography
from fem_twin.case import CaseError
from fem_twin.errors import InputError
from fem_twin.macro import (
    BOUNDARY_FRICTION,
    BoundaryLaw,
    Lubricant,
    MacroSettings,
    OperatingPoint,
    solve_mixed,
)
from fem_twin.macro.laws.boundary_friction import boundary_area, boundary_traction
from fem_twin.micro import homogenise

SHEAR = BoundaryLaw(law="shear", shear_strength=50e6, pressure_coefficient=0.1,
                    speed_coefficient=0.05, reference_speed=0.1)


def test_the_shear_law_with_the_constant_coefficient_is_the_constant_law(factors):
    """tau_0 = 0, alpha = C_f,b and no speed or temperature term: the same operating point,
    friction and shear field bit for bit as eq 32's constant law."""
    gap, dx, face = macro_case(32)
    run = lambda law: solve_mixed(gap, dx, factors, load=150.0, speed=0.02,  # noqa: E731
                                  face=face, lubricant=Lubricant(0.066),
                                  settings=MacroSettings(boundary=law))
    constant = run(BoundaryLaw())
    shear = run(BoundaryLaw(law="shear", shear_strength=0.0,
                            pressure_coefficient=BOUNDARY_FRICTION))
    assert shear.boundary_force == constant.boundary_force > 0
    assert shear.friction_coefficient == constant.friction_coefficient
    assert np.array_equal(shear.shear_stress, constant.shear_stress)


def test_a_new_law_is_one_class_and_one_registry_line(factors, monkeypatch):
    """A toy law registered here (half of eq 32's shear, its own fitted factor) is a choice
    of the [boundary] section, the macro scale's boundary force follows it (half the
    constant law's on the same fields, which the boundary shear does not move) and the
    fit lists its parameter, with its start and bounds."""
    from fem_twin.macro.laws.boundary_laws import LAWS, ConstantLaw, Fitted, fitted_law
    from fem_twin.stribeck.fit import FitModel, _unknowns, parameters

    class Half(ConstantLaw):
        name = "half"
        fitted = {"half_factor": Fitted(0.0, 1.0, "friction")}
        limits = ()

        def traction(self, law, load, dry_fraction, speed, boundary_friction):
            return 0.5 * boundary_friction * np.asarray(load, float)

        def unknowns(self, law, boundary_friction):
            return [("half_factor", 0.5, 0.0, 1.0)]

    with pytest.raises(InputError, match="law: one of"):
        BoundaryLaw(law="half")
    monkeypatch.setitem(LAWS, "half", Half())
    gap, dx, face = macro_case(32)
    run = lambda law: solve_mixed(gap, dx, factors, load=150.0, speed=0.02,  # noqa: E731
                                  face=face, lubricant=Lubricant(0.066),
                                  settings=MacroSettings(boundary=law))
    constant, half = run(BoundaryLaw()), run(BoundaryLaw(law="half"))
    assert half.boundary_force == pytest.approx(0.5 * constant.boundary_force, rel=1e-12)
    assert half.hydrodynamic_friction == constant.hydrodynamic_friction
    assert "half_factor" in parameters() and fitted_law(["half_factor"]) is LAWS["half"]
    names, x0, lower, upper = _unknowns(FitModel((), BOUNDARY_FRICTION, 150.0, None),
                                        ["half_factor"], 1, None)
    assert (names, list(x0), lower, upper) == (["half_factor"], [0.5], [0.0], [1.0])


def test_one_decade_of_speed_multiplies_the_shear_by_one_plus_the_coefficient():
    """s(10 u) / s(u) = 1 + c_u at u = u_ref, and the constant law has no speed term."""
    p, a = np.array([1e8, 2e8]), np.array([0.1, 0.3])
    at = lambda law, u: boundary_traction(p, 1e6, a, u, law, 0.15)  # noqa: E731
    assert at(SHEAR, 1.0) / at(SHEAR, 0.1) == pytest.approx(1.05, rel=1e-14)
    assert np.array_equal(at(BoundaryLaw(), 1.0), at(BoundaryLaw(), 0.01))


def test_a_single_hertzian_asperity_carries_tau0_times_its_area_plus_alpha_times_its_load():
    """A paraboloid asperity (R = 20 um) in a 40 um periodic cell of 256^2 pixels against a
    flat at interferences of 0.1 and 0.2 um: the cell's real contact area lies within 5 % of Hertz's
    pi a^2 for its load (a = (3 W R / (2 E'))^(1/3); measured +2.1 % and +3.4 %: the area
    is counted in whole pixels), and the law's force over the cell is tau_0 A + alpha W
    exactly, so within 2 % of tau_0 pi a^2 + alpha W."""
    n, size, radius, e_red = 256, 40e-6, 20e-6, 231e9
    x = (np.arange(n) - n / 2 + 0.5) * size / n
    z = -(x[None, :] ** 2 + x[:, None] ** 2) / (2 * radius)
    z -= z.mean()
    flat = Topography(np.zeros_like(z), size / n)
    ff = homogenise(Topography(z, size / n), flat, z.max() - np.array([0.2e-6, 0.1e-6]),
                    steps=1, e_reduced=e_red, hardness=1e11, error_estimate=False)
    load, area = ff.p_con * size ** 2, ff.contact_fraction * size ** 2
    hertz = np.pi * (3 * load * radius / (2 * e_red)) ** (2 / 3)
    assert np.all(np.abs(area / hertz - 1) < 0.05), area / hertz
    at_ref = BoundaryLaw(**{**SHEAR.__dict__, "speed_coefficient": 0.0})
    force = boundary_traction(ff.p_con, 0.0, ff.contact_fraction, 1.0, at_ref, 0.0) * size ** 2
    assert force == pytest.approx(50e6 * area + 0.1 * load, rel=1e-12)
    assert force == pytest.approx(50e6 * hertz + 0.1 * load, rel=0.02)


def test_the_boundary_section_is_checked_before_any_work(tmp_path):
    """The shear law's keys need law = "shear"; its speed factor stays positive over the
    sweep; its temperature term needs the thermal model; a slip is refused with its key."""
    from conftest import ROOT

    from fem_twin.case import load_case
    text = (ROOT / "examples" / "pin_on_disk.toml").read_text().replace(
        "../meshes/", str(ROOT / "meshes") + "/")
    text = text[:text.index("[boundary]")] + text[text.index("[sweep]"):]  # its own below
    cases = {'[boundary]\nshear_strength = 1e7\n': "unused by law",
             '[boundary]\nlaw = "shear"\nspeed_coefficient = 0.5\n': "speed factor falls",
             '[boundary]\nlaw = "shear"\nshear_strength = 1e7\npressure_coefficient = 12\n':
                 "pressure_coefficient = 12: implausible",
             '[boundary]\nlaw = "stick"\n': "law: one of",
             '[boundary]\nlaw = "shear"\nshear_strength = 10.0\n':     # 10 MPa typed as Pa
                 "shear_strength = 10: implausible",
             '[boundary]\nlaw = "shear"\npressure_coefficient = 0\n': "no shear at all"}
    for section, words in cases.items():
        (tmp_path / "case.toml").write_text(text + "\n" + section)
        with pytest.raises(CaseError, match=words):
            load_case(tmp_path / "case.toml")
    cold = "\n".join(line for line in text.replace('model = "flash"', 'model = "none"')
                      .splitlines() if not line.startswith(("bulk_resistance", "spot_radius")))
    (tmp_path / "case.toml").write_text(
        cold + '\n[boundary]\nlaw = "shear"\ntemperature_coefficient = 0.02\n')
    with pytest.raises(CaseError, match="the shear would fall by 52%"):
        load_case(tmp_path / "case.toml")               # 26 K above T_ref at the 50 C oil
    (tmp_path / "case.toml").write_text(
        cold + '\n[boundary]\nlaw = "shear"\ntemperature_coefficient = 0.002\n')
    assert load_case(tmp_path / "case.toml").boundary.reference_temperature == 24.0
    (tmp_path / "case.toml").write_text(text + '\n[boundary]\nlaw = "shear"\n'
                                        'shear_strength = 2e7\npressure_coefficient = 0.1\n')
    case = load_case(tmp_path / "case.toml")
    assert case.boundary.shear_strength == 2e7
    (tmp_path / "case.toml").write_text(text.replace("boundary_friction = ", "boundary_friction"
                                                     " = 0.12 #") + '\n[boundary]\nlaw = "shear"\n')
    assert load_case(tmp_path / "case.toml").boundary.pressure_coefficient == 0.12  # the case's
    from fem_twin.stages.requests import macro_settings
    assert macro_settings(case).boundary == case.boundary
    with pytest.raises(InputError, match="speed_coefficient"):
        BoundaryLaw(speed_coefficient=5.0)


def test_the_temperature_term_reads_the_flash_of_the_tempered_shear(factors):
    """With the thermal model, the shear law's temperature factor t and the asperities'
    temperature T_c (the film's plus the spots' flash of the tempered shear) satisfy
    t = 1 - c_T (T_c - T_ref) to rounding (the flash is linear in the flux, so the closed
    form t = (1 - c_T (T - T_ref)) / (1 + c_T G tau) is exact, no iteration), and the
    point's boundary friction is t times the untempered one's at the same film."""
    from fem_twin.macro.laws.thermal import ContactThermal, ThermalSettings, thermal_point
    from fem_twin.macro.laws.viscosity import WaltherLaw
    gap, dx, face = macro_case(32)
    law = BoundaryLaw(law="shear", shear_strength=20e6, pressure_coefficient=0.1,
                      temperature_coefficient=0.01)

    def solve(lubricant, previous):
        return (solve_mixed(gap, dx, factors, load=150.0, speed=0.05, face=face,
                            lubricant=lubricant, settings=MacroSettings(boundary=law)),)
    thermal = ContactThermal(ThermalSettings(), WaltherLaw.through((24.0, 50.0),
                                                                   (0.066, 0.024), 875.0))
    point = OperatingPoint(gap, dx, factors, load=150.0, speed=0.05, face=face,
                           lubricant=Lubricant(0.066), settings=MacroSettings(boundary=law))
    (res,), film, record = thermal_point(solve, point, thermal)
    t = res.meta["boundary_temperature_factor"]
    assert 0.5 < t < 0.999
    assert t == pytest.approx(1 - 0.01 * (record["asperity_C"] - law.reference_temperature),
                              rel=1e-9)
    (cold,) = solve(film, None)
    assert res.boundary_force == pytest.approx(t * cold.boundary_force, rel=1e-9)


def test_a_constant_coefficient_fit_is_refused_on_a_shear_law_case(tmp_path):
    """``fit --params boundary_friction`` and ``run --from-fit`` with a fitted C_f,b on a
    case whose [boundary] law is "shear" (which does not read C_f,b) are refused before any
    work rather than silently ignored."""
    import json
    from dataclasses import replace

    from conftest import ROOT

    from fem_twin.case import load_case
    from fem_twin.studies.fitting import apply_fit, fit_case
    case = load_case(ROOT / "examples" / "pin_on_disk.toml")
    case = replace(case, boundary=SHEAR)
    fit = {"fit": {"parameters": ["boundary_friction"]}, "case": {"temperatures": [24.0]},
           "boundary_friction": {"value": 0.12}}
    with pytest.raises(InputError, match="does not read it"):
        apply_fit(case, json.loads(json.dumps(fit)))
    measured = tmp_path / "m.csv"
    measured.write_text("speed,friction_coefficient\n" + "".join(
        f"{u},{0.05}\n" for u in (0.01, 0.1, 1.0)))

    def run(*args, **kwargs):
        raise AssertionError("the run started")
    with pytest.raises(InputError, match="does not read it"):
        fit_case(case, [measured], tmp_path / "o", ["boundary_friction"], progress=False,
                 run=run)


def test_a_fit_recovers_the_shear_laws_pressure_and_speed_coefficients(factors):
    """Synthetic truth: the twin run with the shear law (alpha = 0.12, c_u = 0.03 about
    0.1 m/s) at 9 speeds is fitted by the constant-law twin's curve (its real contact area
    and asperity load, 20 speeds, PCHIP in log speed): noiseless, alpha and c_u within
    1 % and 0.003; with 1 % noise inside their 95 % intervals.  tau_0 with alpha from one
    load, and C_f,b beside the shear law, are refused as unidentifiable."""
    from fem_twin.stribeck import SweepRequest, stribeck_sweep
    from fem_twin.stribeck.curve import MeasuredCurve
    from fem_twin.stribeck.fit import FitModel, fit_curves
    gap, dx, face = macro_case(32)
    truth = BoundaryLaw(law="shear", pressure_coefficient=0.12, speed_coefficient=0.03,
                        reference_speed=0.1)
    common = dict(load=150.0, face=face, lubricant=Lubricant(0.066))
    sim = stribeck_sweep(SweepRequest(gap, dx, factors, np.geomspace(2.0, 0.004, 20),
                                      **common))
    speeds = np.geomspace(1.0, 0.01, 9)
    measured = stribeck_sweep(SweepRequest(gap, dx, factors, speeds, **common,
                                           settings=MacroSettings(boundary=truth)))
    model = FitModel((sim,), BOUNDARY_FRICTION, 150.0, None,
                     boundary=BoundaryLaw(law="shear", pressure_coefficient=0.15,
                                          reference_speed=0.1))
    params = ["pressure_coefficient", "speed_coefficient"]
    exact = fit_curves(model, [MeasuredCurve(speeds, measured.friction_coefficient)], params,
                       start_temperatures=None)
    assert exact["pressure_coefficient"]["value"] == pytest.approx(0.12, rel=0.01)
    assert exact["speed_coefficient"]["value"] == pytest.approx(0.03, abs=0.003)
    noisy = measured.friction_coefficient * (
        1 + 0.01 * np.random.default_rng(5).standard_normal(speeds.size))
    out = fit_curves(model, [MeasuredCurve(speeds, noisy)], params, start_temperatures=None)
    for name, value in (("pressure_coefficient", 0.12), ("speed_coefficient", 0.03)):
        assert out[name]["low"] < value < out[name]["high"], (name, out[name])
    for bad, words in ((["shear_strength", "pressure_coefficient"], "two or more loads"),
                       (["boundary_friction", "speed_coefficient"], "fit one law"),
                       (["temperature_coefficient"], "spot_rise")):
        with pytest.raises(InputError, match=words):
            fit_curves(model, [MeasuredCurve(speeds, noisy)], bad, start_temperatures=None)


@pytest.mark.integration
def test_two_loads_separate_the_shear_strength_from_the_pressure_coefficient(factors):
    """Synthetic truth at 150 and 300 N with both oils (0.066 and 0.024 Pa s): the twin
    with tau_0 = 30 MPa and alpha = 0.08, fitted by the constant-law twin's four curves (20
    speeds each): noiseless within 2 % and 1 % (measured 30.28 MPa, 0.0798; the two 0.999
    correlated); with 1 % noise the intervals hold the truth in at least 16 of 20 seeds
    (measured over 40: 95 % for both).  From 150 N alone a law cannot separate them: a
    constant C_f,b fitted there misses the 300 N curve by 2.2 % C_f,b (1 to 4 %)."""
    from fem_twin.stribeck import SweepRequest, stribeck_sweep
    from fem_twin.stribeck.curve import MeasuredCurve
    from fem_twin.stribeck.fit import FitModel, fit_curves
    from fem_twin.stribeck.prediction import predict
    gap, dx, face = macro_case(32)
    truth = BoundaryLaw(law="shear", shear_strength=30e6, pressure_coefficient=0.08)
    speeds, sim, measured = np.geomspace(1.0, 0.01, 9), {}, {}
    tests = [(load, mu) for load in (150.0, 300.0) for mu in (0.066, 0.024)]
    for load, mu in tests:
        common = dict(load=load, face=face, lubricant=Lubricant(mu))
        sim[load, mu] = stribeck_sweep(SweepRequest(gap, dx, factors,
                                                    np.geomspace(2.0, 0.004, 20), **common))
        measured[load, mu] = stribeck_sweep(SweepRequest(
            gap, dx, factors, speeds, **common,
            settings=MacroSettings(boundary=truth))).friction_coefficient
    model = FitModel(tuple(sim[t] for t in tests), BOUNDARY_FRICTION, 150.0, None,
                     loads=tuple(load for load, _ in tests))
    params = ["shear_strength", "pressure_coefficient"]
    exact = fit_curves(model, [MeasuredCurve(speeds, measured[t]) for t in tests], params,
                       start_temperatures=None)
    assert exact["shear_strength"]["value"] == pytest.approx(30e6, rel=0.02)
    assert exact["pressure_coefficient"]["value"] == pytest.approx(0.08, rel=0.01)
    hits = np.zeros(2)
    for seed in range(20):
        rng = np.random.default_rng(seed)
        noisy = [MeasuredCurve(speeds, measured[t] * (1 + 0.01 * rng.standard_normal(9)))
                 for t in tests]
        out = fit_curves(model, noisy, params, start_temperatures=None)
        hits += [out[n]["low"] < getattr(truth, n) < out[n]["high"] for n in params]
    assert np.all(hits >= 16), hits
    light, heavy = (150.0, 0.066), (300.0, 0.066)
    one = fit_curves(FitModel((sim[light],), BOUNDARY_FRICTION, 150.0, None),
                     [MeasuredCurve(speeds, measured[light])], ["boundary_friction"],
                     start_temperatures=None)
    at_300 = predict(FitModel((sim[heavy],), BOUNDARY_FRICTION, 300.0, None), one, speeds,
                     None, curve=0)
    miss = np.abs(at_300["cf"] - measured[heavy]).max() / BOUNDARY_FRICTION
    assert 0.01 < miss < 0.04


def test_the_error_estimate_carries_the_real_contact_fractions_error(factors):
    """Each variant of the flow factors (time steps, cell grid, h0 spacing) carries its own
    contact fraction, and the law reads it: under a law that rests on the real area
    (tau_0 = 100 MPa, alpha = 0.02) the point's grid part differs from the constant law's
    (measured at 0.02 m/s: 0.0093 against 0.0041), while the film part, which no contact
    fraction enters when the films below the cut carry no shear, is the same."""
    from fem_twin.stribeck import SweepRequest, stribeck_sweep
    gap, dx, face = macro_case(32)
    parts = {}
    for law in (BoundaryLaw(thin_films=False),
                BoundaryLaw(law="shear", shear_strength=100e6, pressure_coefficient=0.02,
                            thin_films=False)):
        curve = stribeck_sweep(SweepRequest(gap, dx, factors, [0.02], load=150.0, face=face,
                                            lubricant=Lubricant(0.066), error_estimate=True,
                                            settings=MacroSettings(boundary=law)))
        parts[law.law] = {k: float(v[0]) for k, v in curve.friction_error_parts.items()}
        parts[law.law]["film"] = float(curve.film_sensitivity[0])
    assert abs(parts["shear"]["grid"] / parts["constant"]["grid"] - 1) > 0.1
    assert parts["shear"]["film"] == pytest.approx(parts["constant"]["film"], rel=1e-9)


def test_films_below_the_boundary_film_join_the_boundary_area():
    """a_r is the contact spots' fraction and, with ``thin_films`` (the default), the films
    thinner than the boundary film (1 - film_fraction): they carry the boundary shear, not
    none.  Off, the spots alone; factors without a spread (film_fraction 1) read the spots
    either way.  A cell in contact has films below the cut beside its spots (counted at
    the quadrature points, so a lone contact pixel's neighbourhood can read as film: the
    larger of the two areas is taken)."""
    from types import SimpleNamespace
    shear = SimpleNamespace(contact_fraction=np.array([0.1, 0.3, 0.2]),
                            film_fraction=np.array([0.8, 0.75, 1.0]))
    assert np.allclose(boundary_area(shear, BoundaryLaw()), [0.2, 0.3, 0.2])
    assert np.allclose(boundary_area(shear, BoundaryLaw(thin_films=False)), [0.1, 0.3, 0.2])
    n, dx = 32, 85e-6 / 32
    pin = Topography(self_affine_patch(n, dx, 1), (dx, dx))
    disk = Topography(self_affine_patch(n, dx, 2), (dx, dx))
    ff = homogenise(pin, disk, [0.08e-6, 0.15e-6, 0.3e-6], steps=4, error_estimate=False)
    assert np.all(ff.contact_fraction > 0) and np.all(ff.film_fraction < 1)
    assert ff.film_fraction[0] < 1 - ff.contact_fraction[0]     # heavy contact: thin films


def self_affine_patch(n, dx, seed):
    from fem_twin.topography.synthetic import self_affine
    return self_affine((n, n), (dx, dx), 0.8, 100e-9, rng=seed).heights


@pytest.mark.parametrize("model", ["flash", "none"])
def test_the_two_oils_boundary_forces_differ_by_their_temperatures(factors, model):
    """Issue 84 item 1: the temperature term acts on the asperities' absolute temperature,
    so the slow-end boundary force of the bundled case's two oils (24 and 50 C) differs by
    the closed form's ratio ``t(50) / t(24)``, ``t = 1 - c_T (T_c - T_ref)``; with the
    thermal model T_c is the point's asperity temperature (oil, bulk rise, face and spot
    flash), isothermal the oil's.  With tau_0 = 0 the force is alpha t times the
    asperities' load exactly.  The spot's flash alone (0.2-3 K) gave a ratio near 1."""
    from fem_twin.macro.laws.thermal import ContactThermal, ThermalSettings
    from fem_twin.macro.laws.viscosity import WaltherLaw
    from fem_twin.stribeck.request import SweepRequest
    from fem_twin.stribeck.sweep import _solve_point
    gap, dx, face = macro_case(32)
    law = BoundaryLaw(law="shear", pressure_coefficient=0.1, temperature_coefficient=0.005)
    walther = WaltherLaw.through((24.0, 50.0), (0.066, 0.024), 875.0)
    thermal = (ContactThermal(ThermalSettings(), walther) if model == "flash" else None)
    forces = {}
    for oil, mu in ((24.0, 0.066), (50.0, 0.024)):
        request = SweepRequest(gap, dx, factors, [0.005], load=150.0, face=face,
                               lubricant=Lubricant(mu), settings=MacroSettings(boundary=law),
                               thermal=thermal, oil_temperature=None if thermal else oil)
        res = _solve_point(request, 0.005, ())[0]
        hot = res.meta["thermal"]["asperity_C"] if thermal else oil
        t = 1 - 0.005 * (hot - 24.0)
        assert res.boundary_force == pytest.approx(0.1 * t * res.asperity_load, rel=1e-9)
        forces[oil] = (res.boundary_force / res.asperity_load, t)
    ratio = forces[50.0][0] / forces[24.0][0]
    assert ratio == pytest.approx(forces[50.0][1] / forces[24.0][1], rel=1e-9)
    assert ratio < 1 - 0.005 * 25                       # the 26 K between the oils shows
