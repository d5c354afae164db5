"""What measured curves identify (fem_twin.stribeck.identify): tau_0 and alpha refused
together where the real pressure hardly changes, with the identifiable alpha + tau_0 / p_r
named; separated where it does; honest intervals on the identifiable combination."""

import numpy as np
import pytest

from fem_twin.errors import InputError
from fem_twin.macro import BoundaryLaw
from fem_twin.stribeck.curve import MeasuredCurve, StribeckCurve
from fem_twin.stribeck.fit import FitModel, fit_curves

SPEEDS = np.geomspace(2.0, 0.005, 24)
TAU0, ALPHA, CFB = 20e6, 0.08, 0.1924500897


def curve(load: float, pressure) -> StribeckCurve:
    """A simulated curve at ``load`` [N]: a film friction falling with the speed, an
    asperity load rising below 0.05 m/s, and the real area at the mean real pressure
    ``pressure(u)`` [Pa] (the constant law's boundary force)."""
    u = SPEEDS
    asperity = load / (1 + (u / 0.05) ** 2)
    hd = 0.004 * load * np.sqrt(u) * (1 - asperity / load)
    n = u.size
    return StribeckCurve(speed=u, hersey=u * 1e-7, friction_coefficient=(hd + CFB * asperity)
                         / load, viscosity=0.066, hydrodynamic_friction=hd,
                         boundary_force=CFB * asperity, contact_load_fraction=asperity / load,
                         h_d=np.full(n, 1e-7), iterations=np.ones(n, int),
                         asperity_load=asperity, real_contact_area=asperity / pressure(u))


def truth(c: StribeckCurve, load: float) -> np.ndarray:
    return (c.hydrodynamic_friction + TAU0 * c.real_contact_area
            + ALPHA * c.asperity_load) / load


def resolved(u):
    """The bundled pairs' resolved real pressure: about 4.4 GPa, within 3 % over a curve."""
    return 4.4e9 * (1 + 0.03 * np.log10(u / 0.05) / 2.6)


def quantised(u, load):
    """A coarse cell's real pressure: 0.2 GPa at contact onset to 1.6 GPa deep in it."""
    return 0.2e9 + 1.4e9 * (load / 300.0) / (1 + (u / 0.05) ** 2)


def test_a_resolved_contact_refuses_tau0_with_alpha_and_names_what_it_identifies():
    """Two loads (150, 300 N) whose real pressure stays at 4.3-4.5 GPa, 5 % noise: the
    pair's 95 % interval reaches 0, so the fit is refused before its least squares, naming
    p_r's range and alpha + tau_0 / p_r (the truth 0.0845 within 5 %)."""
    loads = (150.0, 300.0)
    sim = [curve(load, resolved) for load in loads]
    rng = np.random.default_rng(1)
    measured = [MeasuredCurve(SPEEDS, truth(c, load) * (1 + 0.05 * rng.standard_normal(
        SPEEDS.size))) for c, load in zip(sim, loads)]
    model = FitModel(tuple(sim), CFB, 150.0, None, loads=loads)
    with pytest.raises(InputError, match=r"cannot be told apart.*alpha \+ tau_0 / p_r = "
                                         r"(0\.0[78]\d*)") as err:
        fit_curves(model, measured, ["shear_strength", "pressure_coefficient"],
                   start_temperatures=None)
    value = float(str(err.value).split("tau_0 / p_r = ")[1].split()[0])
    assert value == pytest.approx(ALPHA + TAU0 / 4.4e9, rel=0.05)


def test_a_real_pressure_that_changes_separates_them():
    """The coarse cells' real pressure (0.2 to 1.6 GPa along the curves), 1 % noise: the
    fit runs, records p_r's range, and its intervals hold tau_0 and alpha."""
    loads = (150.0, 300.0)
    sim = [curve(load, lambda u, load=load: quantised(u, load)) for load in loads]
    rng = np.random.default_rng(2)
    measured = [MeasuredCurve(SPEEDS, truth(c, load) * (1 + 0.01 * rng.standard_normal(
        SPEEDS.size))) for c, load in zip(sim, loads)]
    out = fit_curves(FitModel(tuple(sim), CFB, 150.0, None, loads=loads), measured,
                     ["shear_strength", "pressure_coefficient"], start_temperatures=None)
    low, _, high = out["fit"]["identifiability"]["real_pressure"]
    assert low < 0.3e9 and high > 1.2e9
    assert out["shear_strength"]["low"] < TAU0 < out["shear_strength"]["high"]
    assert out["pressure_coefficient"]["low"] < ALPHA < out["pressure_coefficient"]["high"]


def test_the_identifiable_combination_s_intervals_hold_it_under_5_percent_noise():
    """What a resolved contact identifies, alpha_eff = alpha + tau_0 / p_r, fitted as
    pressure_coefficient with tau_0 = 0 from one curve (150 N) with 5 % noise: its 95 %
    interval holds alpha + tau_0 / 4.4 GPa in at least 34 of 40 seeds (measured 37; binomial
    at 95 %: 38 expected, 33 or fewer has probability 0.3 %)."""
    sim = curve(150.0, resolved)
    model = FitModel((sim,), CFB, 150.0, None,
                     boundary=BoundaryLaw(law="shear", pressure_coefficient=0.1))
    target, hits = ALPHA + TAU0 / 4.4e9, 0
    for seed in range(40):
        rng = np.random.default_rng(seed)
        noisy = MeasuredCurve(SPEEDS, truth(sim, 150.0) * (1 + 0.05 * rng.standard_normal(
            SPEEDS.size)))
        out = fit_curves(model, [noisy], ["pressure_coefficient"], start_temperatures=None)
        hits += out["pressure_coefficient"]["low"] < target < out["pressure_coefficient"]["high"]
    assert hits >= 34, hits


def test_the_plateau_sets_the_boundary_level_and_the_rest_is_predicted():
    """``--plateau``: C_f,b from the points where the twin's asperities carry 90 % of the
    load (5 of 24 here), 2 % noise on a truth of 0.13: the interval holds 0.13, the 19
    predicted points lie within 2 % C_f,b rms, and the band (of the mean: the fit's
    interval and cf_err) holds the noiseless truth at every point; where the twin's film
    friction is half the measured one (noiseless; a wrong viscosity or film law), the
    predicted points' error shows it (rms C_f,dev above 0.5 % C_f,b and three times the
    fitted ones'); anything but the boundary law is refused."""
    from fem_twin.stribeck.plateau import fit_plateau
    sim = curve(150.0, resolved)
    model = FitModel((sim,), CFB, 150.0, None)
    rng = np.random.default_rng(3)
    noise = 1 + 0.02 * rng.standard_normal(SPEEDS.size)
    right = (sim.hydrodynamic_friction + 0.13 * sim.asperity_load) / 150.0 * noise
    out = fit_plateau(model, [MeasuredCurve(SPEEDS, right)], ["boundary_friction"])
    p = out["plateau"]
    assert (p["fitted"]["points"], p["predicted"]["points"]) == (5, 19)
    assert out["boundary_friction"]["low"] < 0.13 < out["boundary_friction"]["high"]
    assert p["predicted"]["rms_cf_dev"] < 0.02
    row = p["rows"][0]                 # the band is the mean's: it holds the noiseless truth
    truth = right / noise
    assert np.all((np.array(row["cf_low"]) <= truth) & (truth <= np.array(row["cf_high"])))
    off = (2 * sim.hydrodynamic_friction + 0.13 * sim.asperity_load) / 150.0
    wrong = fit_plateau(model, [MeasuredCurve(SPEEDS, off)], ["boundary_friction"])["plateau"]
    assert wrong["predicted"]["rms_cf_dev"] > max(3 * wrong["fitted"]["rms_cf_dev"], 0.005)
    with pytest.raises(InputError, match="boundary law alone"):
        fit_plateau(model, [MeasuredCurve(SPEEDS, right)], ["boundary_friction", "temperature"])
