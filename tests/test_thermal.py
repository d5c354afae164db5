"""The contact's temperature (fem_twin.macro.laws.thermal) against the moving heat source's
closed forms, the heat balance, and the isothermal limit.

Closed forms (a uniform flux q over a source of half-width l on a half-space of
conductivity k, Peclet number Pe = U l / (2 kappa)): the square source at rest has the
mean rise 0.946393 q l / k (the mean of 1/r over a square); the band source (infinitely
long across the motion) has the mean rise
``(q / (pi k 2l)) int_{-2l}^{2l} (2l - |u|) exp(U u / 2 kappa) K0(U |u| / 2 kappa) du``
(Jaeger 1942), whose limits are ``(2 q l / (pi k)) (3/2 - gamma - ln Pe)`` at low Pe and
``(4 / 3) q l / (k sqrt(pi Pe))`` at high Pe (1D conduction along each streamline).
"""

import pickle
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import k0e

from fem_twin.errors import NotConverged
from fem_twin.macro import Lubricant, MacroSettings, OperatingPoint, solve_mixed
from fem_twin.macro.laws.thermal import (
    ContactThermal,
    ThermalNotConverged,
    ThermalSettings,
    face_flash,
    surface_temperature,
    thermal_point,
)
from fem_twin.macro.laws.viscosity import WaltherLaw

sys.path.insert(0, str(Path(__file__).parent))
from sample_cases import macro_case  # noqa: E402

L, KAPPA = 4e-3, 1.2e-5                       # half-width [m], steel's diffusivity [m^2/s]
SQUARE_AT_REST = 2 * (4 * np.log(1 + np.sqrt(2)) + 4 / 3 * (1 - np.sqrt(2))) / (2 * np.pi)


def band_mean(pe):
    """Jaeger's band source, its mean rise over q l / k, by quadrature (the reference; u
    in half-widths)."""
    f = lambda u: (2 - abs(u)) * np.exp(pe * (u - abs(u))) * k0e(pe * abs(u))  # noqa: E731
    return (quad(f, -2, 0, limit=200)[0] + quad(f, 0, 2, limit=200)[0]) / (2 * np.pi)


def test_the_band_reference_has_jaegers_limits():
    """The quadrature against the two closed forms: within 1e-4 at Pe 0.01 and 1000."""
    assert band_mean(0.01) == pytest.approx(2 / np.pi * (1.5 - np.euler_gamma - np.log(0.01)),
                                            rel=1e-4)
    assert band_mean(1000) == pytest.approx(4 / (3 * np.sqrt(np.pi * 1000)), rel=3e-4)


def test_a_square_source_at_rest_converges_to_its_closed_form():
    """0.946393 q l / k: 5.6e-4, 1.7e-4, 5e-5 off at 32, 64, 128 px (second order)."""
    errors = []
    for n in (32, 64):
        dx = 2 * L / n
        theta = surface_temperature(np.ones((n, n)), (dx, dx), 0.0, 1.0, KAPPA).mean() / L
        errors.append(theta / SQUARE_AT_REST - 1)
    assert 0 < errors[1] < 3e-4 and 2.5 < errors[0] / errors[1] < 4.5


@pytest.mark.parametrize("pe", [1.0, 10.0, 100.0])
def test_a_moving_band_source_matches_jaegers_solution(pe):
    """The middle third of a strip 24 half-widths long against the band's mean rise:
    within 0.1 % at 32 px across (measured 3e-4, 6e-4, 9e-4 at Pe 1, 10, 100)."""
    n, long = 32, 24
    dx = 2 * L / n
    theta = surface_temperature(np.ones((long * n, n)), (dx, dx), pe * 2 * KAPPA / L, 1.0, KAPPA)
    middle = theta[long * n // 3: 2 * long * n // 3].mean() / L
    assert middle == pytest.approx(band_mean(pe), rel=1e-3)


def test_blok_partition_gives_both_bodies_one_temperature_and_all_the_heat():
    """The pin's share heats the pin at rest exactly as the rest heats the moving disk, and
    the two shares add up to the heat."""
    n = 32
    x = (np.arange(n) - (n - 1) / 2) / (n / 2)
    face = np.hypot(x[None, :], x[:, None]) <= 1
    flux = np.where(face, 1e5 * (1 + x[None, :]), 0.0)
    dx = (2 * L / n, 2 * L / n)
    s = ThermalSettings()
    theta, share = face_flash(flux, face, dx, (0.0, 0.5), s)
    pin = surface_temperature(share * flux, dx, 0.0, s.conductivity, s.diffusivity)[face].mean()
    disk = surface_temperature((1 - share) * flux, dx, 0.5, s.conductivity,
                               s.diffusivity)[face].mean()
    assert pin == pytest.approx(theta, rel=1e-12) and disk == pytest.approx(theta, rel=1e-12)
    assert 0 < share < 0.5                        # the moving disk takes most of the heat


@pytest.fixture(scope="module")
def point(factors):
    gap, dx, face = macro_case(32)
    common = dict(load=150.0, speed=1.0, face=face, settings=MacroSettings(tol=1e-8))

    def solve(lub, previous):
        initial = None if previous is None else previous[0]
        return (solve_mixed(gap, dx, factors, lubricant=lub, initial=initial, **common),)
    return solve


@pytest.fixture(scope="module")
def operating(factors):
    """The operating point :func:`point` solves, with the oil at 24 C."""
    gap, dx, face = macro_case(32)
    return OperatingPoint(gap, dx, factors, load=150.0, speed=1.0, face=face,
                          settings=MacroSettings(tol=1e-8), lubricant=Lubricant(0.066))


LAW = WaltherLaw.through((24.0, 50.0), (0.066, 0.024), 875.0)


def test_the_film_temperature_settles_and_its_heat_is_the_frictional_power(point, operating):
    """At 1 m/s on the sample pin: the converged film temperature is the oil's plus R_b Q
    plus the face's flash (to the tolerance), Q = F_T U, and the film's viscosity is the
    Walther law's at that temperature."""
    thermal = ContactThermal(ThermalSettings(bulk_resistance=2.0), LAW)
    (res,), film, record = thermal_point(point, operating, thermal)
    assert record["power_W"] == pytest.approx(res.friction_force * 1.0, rel=1e-12)
    assert abs(record["oil_C"] + 2.0 * record["power_W"] + record["face_flash_K"]
               - record["film_C"]) < 0.01
    assert film.viscosity == pytest.approx(float(LAW.viscosity(record["film_C"])), rel=1e-12)
    assert 24.5 < record["film_C"] < 40 and record["iterations"] <= 6
    assert res.friction_coefficient < point(Lubricant(0.066), None)[0].friction_coefficient


def test_ideal_heat_sinks_recover_the_isothermal_twin(point, operating):
    """No bulk resistance, a conductivity 1e9 times steel's, no spots: one iteration, and
    C_f equals the isothermal point's to 1e-9.  (The ideal heat sink lies outside the
    plausible conductivities ThermalSettings accepts, so it is set past the check.)"""
    s = ThermalSettings(bulk_resistance=0.0, spot_radius=0.0)
    object.__setattr__(s, "conductivity", 46e9)
    (res,), film, record = thermal_point(point, operating, ContactThermal(s, LAW))
    iso = point(Lubricant(0.066), None)[0]
    assert record["iterations"] == 1
    assert res.friction_coefficient == pytest.approx(iso.friction_coefficient, rel=1e-9)


def test_a_temperature_that_does_not_settle_raises_with_its_history(point, operating):
    """max_iter 1 with a large resistance: ThermalNotConverged carries |dT| per iteration,
    survives pickling to and from a worker process, and is a NotConverged (the CLI's
    documented exit 3, not an internal error)."""
    s = ThermalSettings(bulk_resistance=20.0, max_iter=1)
    with pytest.raises(ThermalNotConverged) as err:
        thermal_point(point, operating, ContactThermal(s, LAW))
    assert len(err.value.history) == 1 and err.value.history[0] > 10
    again = pickle.loads(pickle.dumps(err.value))
    assert again.history == err.value.history and str(again) == str(err.value)
    assert isinstance(err.value, NotConverged)


def test_thermal_settings_refuse_nonsense():
    for bad in (dict(model="hot"), dict(conductivity=0.0), dict(tol=-1.0), dict(grid=4),
                dict(bulk_resistance=np.nan)):
        with pytest.raises(Exception, match="model|conductivity|tol|grid|bulk"):
            replace(ThermalSettings(), **bad)


def test_a_first_step_along_the_neighbours_slope_lands_within_the_tolerance():
    """A film temperature whose heat falls with it (g' = -0.2 here: the power 100 mu(T) W
    on R_b = 1 K/W, mu dropping 3 %/K) started 0.5 K off its root: the plain step leaves it
    0.1 K off, so the secant needs a third solve; along the slope of g - T that the converged
    point records (``residual_slope``, -1.2), the second solve lands within the tolerance."""
    from types import SimpleNamespace

    class Model:
        settings = ThermalSettings(bulk_resistance=1.0)
        law = SimpleNamespace(viscosity=lambda T: 0.066 * np.exp(-0.03 * (T - 24.0)),
                              temperature=lambda mu: 24.0 - np.log(mu / 0.066) / 0.03)

        def tempered(self, result, point, temperature):
            return result

        def heat(self, result, point):
            return {"power": result.power, "flash": 0.0, "pin_share": 0.5}

        def spot(self, result, point):
            return 0.0

    def solve(lubricant, previous):
        return (SimpleNamespace(speed=1.0, power=100 * lubricant.viscosity),)

    oil = SimpleNamespace(lubricant=Lubricant(0.066), surface_speeds=(0.0, 1.0))
    _, film, record = thermal_point(solve, oil, Model())
    assert record["residual_slope"] == pytest.approx(-1.0 - 3.0 * film.viscosity, rel=1e-2)
    off = {**record, "film_C": record["film_C"] + 0.5}
    plain = thermal_point(solve, oil, Model(), {**off, "residual_slope": None})[2]
    along = thermal_point(solve, oil, Model(), off)[2]
    assert plain["iterations"] == 3 and along["iterations"] == 2
    assert abs(along["film_C"] - record["film_C"]) < Model.settings.tol
