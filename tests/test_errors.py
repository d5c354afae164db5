"""Failures surface cleanly in the API (issue 30): every error fem_twin raises on purpose is
a FemTwinError of the builtin kind a caller expects, bad input is refused before work
starts with the argument named, and errors survive pickling to and from workers."""

import pickle

import numpy as np
import pytest
from conftest import ROOT

from fem_twin import Topography, contact, errors
from fem_twin.errors import FemTwinError, InputError
from fem_twin.micro import homogenise
from fem_twin.topography import fill_defects
from fem_twin.topography.prepare import prepare_pin
from fem_twin.topography.synthetic import self_affine


@pytest.mark.parametrize("args,words", [
    ((0.0, 0.3, 210e9, 0.3), "e1"), ((210e9, 0.7, 210e9, 0.3), "nu1"),
    ((210e9, 0.3, 210e3, 0.3), "e2"), ((210e9, 0.3, np.nan, 0.3), "finite")])
def test_reduced_modulus_refuses_impossible_materials(args, words):
    with pytest.raises(InputError, match=words):
        contact.reduced_modulus(*args)


def test_contact_refuses_a_zero_pitch_and_wrong_units():
    shape = np.zeros((8, 8))
    e = contact.reduced_modulus(210e9, 0.3, 210e9, 0.3)
    with pytest.raises(InputError, match="spacing"):
        contact.solve(shape, (0.0, 0.0), e, load=1.0)
    with pytest.raises(InputError, match="e_reduced"):
        contact.solve(shape, 1e-6, e / 1e9, load=1.0)           # GPa typed as Pa
    with pytest.raises(InputError, match="hardness"):
        contact.solve(shape, 1e-6, e, load=1.0, hardness=6.99)


def test_fill_defects_refuses_a_map_with_almost_no_data():
    z = np.full((32, 32), np.nan)
    z[3, 4] = 1e-6
    with pytest.raises(InputError, match="1 of 1024 pixels"):
        fill_defects(Topography(z, 1e-6))


def test_a_constant_map_is_not_a_pin():
    with pytest.raises(InputError, match="no pin face"):
        prepare_pin(Topography(np.full((64, 64), 1e-6), 1e-4))


def test_homogenise_refuses_a_patch_in_micrometres():
    """A patch with heights in um typed as m (1e3 too high) ran to p_con = 1.75 GPa."""
    pin = self_affine((16, 16), 1e-6, 0.8, 100e-9, rng=1)
    disk = self_affine((16, 16), 1e-6, 0.8, 100e-9, rng=2)
    slip = Topography(pin.heights * 1e3, pin.spacing)
    with pytest.raises(InputError, match="Sq"):
        homogenise(slip, disk, [1e-7, 2e-7], steps=2)


def test_every_error_class_is_a_fem_twin_error_and_pickles():
    classes = [c for c in vars(errors).values()
               if isinstance(c, type) and issubclass(c, Exception)]
    assert len(classes) >= 12
    for cls in classes:
        assert issubclass(cls, FemTwinError)
        err = (cls("message", [1.0, 0.5]) if issubclass(cls, errors.NotConverged)
               else cls("message"))
        back = pickle.loads(pickle.dumps(err))
        assert type(back) is cls and "message" in str(back)
    assert issubclass(errors.MissingFile, FileNotFoundError)
    assert issubclass(errors.InputError, ValueError)


def test_a_cropped_pin_says_why_it_cannot_be_levelled():
    """A pin map cut through the face made the torque balance fail with 'Singular matrix'."""
    from pathlib import Path

    from fem_twin.contact import level_pin
    from fem_twin.errors import NotConverged
    from fem_twin.io.files import read_topography
    from fem_twin.topography.prepare import MacroOptions
    raw = read_topography(Path(__file__).parents[1] / "meshes" / "sample" / "pin_1.npz")
    crop = Topography(raw.heights[:, :300], raw.spacing,
                      mask=None if raw.mask is None else raw.mask[:, :300])
    pin = prepare_pin(crop, MacroOptions(resolution=(48, 48)))
    with pytest.raises(NotConverged, match="cropped"):
        level_pin(pin, load=150.0)


# -- issue 64 item 4: only FemTwinError escapes the API, whatever the input -----------------
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from fem_twin.macro import Lubricant, solve_mixed, solve_reynolds  # noqa: E402
from fem_twin.micro import FlowFactors  # noqa: E402

#: inputs of the wrong type, shape, unit or value, each where an array or a number goes
BAD = st.sampled_from([
    None, "1e-6", [], np.zeros(0), np.zeros((0, 0)), np.zeros(3), np.zeros((2, 2, 2)),
    np.full((8, 8), np.nan), np.full((8, 8), np.inf), np.ones((8, 8), dtype=int),
    np.ones((8, 8)), -np.ones((8, 8)), 1e3 * np.ones((8, 8)), (1e-6, 1e-6, 1e-6), 0.0, -1.0,
    np.nan, 1e9, object()])
GOOD_GAP = 1e-6 * (1 + np.add.outer(np.linspace(-1, 1, 8) ** 2, np.linspace(-1, 1, 8) ** 2))


def _calls(bad):
    """Each entry point with one argument replaced by ``bad``."""
    z = 1e-7 * np.cos(np.arange(64) / 3).reshape(8, 8)
    e = contact.reduced_modulus(210e9, 0.3, 210e9, 0.3)
    yield lambda: Topography(bad, 1e-6)
    yield lambda: Topography(z, bad)
    yield lambda: contact.solve(bad, 1e-6, e, load=1.0)
    yield lambda: contact.solve(z, bad, e, load=1.0)
    yield lambda: contact.solve(z, 1e-6, bad, load=1.0)
    yield lambda: homogenise(Topography(z, 1e-6), Topography(z, 1e-6), bad, steps=2,
                             error_estimate=False)
    yield lambda: solve_reynolds(bad, (1e-4, 1e-4), 1.0, 0.066)
    yield lambda: solve_reynolds(GOOD_GAP, bad, 1.0, 0.066)
    yield lambda: solve_mixed(bad, (1e-4, 1e-4), FlowFactors.smooth(), load=1.0, speed=1.0,
                              lubricant=Lubricant(0.066))
    yield lambda: solve_mixed(GOOD_GAP, (1e-4, 1e-4), bad, load=1.0, speed=1.0,
                              lubricant=Lubricant(0.066))
    yield lambda: solve_mixed(GOOD_GAP, (1e-4, 1e-4), FlowFactors.smooth(), load=bad,
                              speed=1.0, lubricant=Lubricant(0.066))
    yield lambda: solve_mixed(GOOD_GAP, (1e-4, 1e-4), FlowFactors.smooth(), load=1.0,
                              speed=bad, lubricant=Lubricant(0.066))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(BAD)
def test_only_fem_twin_errors_escape_the_api(bad):
    """Wrong types, shapes, units, empty and non-finite arrays at each entry point: the
    call either works (a plausible value among them) or raises a FemTwinError naming what
    is wrong, never a numpy, scipy or Python error from inside."""
    for call in _calls(bad):
        try:
            call()
        except FemTwinError:
            pass


#: the public API: every callable these modules export
PUBLIC = ["fem_twin", "fem_twin.topography", "fem_twin.contact", "fem_twin.micro",
          "fem_twin.macro", "fem_twin.stribeck", "fem_twin.io", "fem_twin.fvm", "fem_twin.peers",
          "fem_twin.case"]
#: modules without an ``__all__`` whose own public functions are walked too (issue 87
#: item 7: the new round's functions)
MODULES = ["fem_twin.results", "fem_twin.studies.verification", "fem_twin.stribeck.analysis",
           "fem_twin.macro.laws.boundary_friction", "fem_twin.macro.laws.boundary_laws",
           "fem_twin.macro.laws.thermal",
           "fem_twin.macro.reference.deterministic", "fem_twin.macro.reference.film_friction",
           "fem_twin.macro.point", "fem_twin.runtime.machine", "fem_twin.topography.statistics",
           "fem_twin.peers.patir_cheng", "fem_twin.peers.greenwood_tripp",
           "fem_twin.peers.average_flow"]
#: wrong types, empty, non-finite and integer arrays, each given to every required argument
WRONG = [None, "x", object(), np.zeros(0), np.zeros((0, 0)), np.full((6, 6), np.nan),
         np.ones((6, 6), dtype=int)]


def _extra_callables() -> dict:
    """Public callables outside the packages' ``__all__``: the thermal, kinematics,
    viscosity-law, case-reading and fit-application functions (issue 72 item 5)."""
    from fem_twin.case import load_case
    from fem_twin.macro.laws import kinematics, thermal
    from fem_twin.macro.laws.viscosity import WaltherLaw
    from fem_twin.studies import fitting
    return {"ThermalSettings": thermal.ThermalSettings,
            "surface_temperature": thermal.surface_temperature,
            "face_flash": thermal.face_flash, "disk_velocity": kinematics.disk_velocity,
            "WaltherLaw.through": WaltherLaw.through, "load_case": load_case,
            "apply_fit": fitting.apply_fit, "check_fit": fitting.check_fit}


def public_callables():
    import importlib
    import inspect
    seen = {id(obj): (name, obj) for name, obj in _extra_callables().items()}
    for name in PUBLIC + MODULES:
        module = importlib.import_module(name)
        own = [a for a in vars(module) if not a.startswith("_")
               and getattr(getattr(module, a), "__module__", None) == name]
        for attr in getattr(module, "__all__", own):
            obj = getattr(module, attr)
            if callable(obj) and not (inspect.isclass(obj) and issubclass(obj, BaseException)):
                seen.setdefault(id(obj), (f"{name}.{attr}", obj))
    return list(seen.values())


def test_every_public_function_refuses_wrong_arguments_with_a_fem_twin_error():
    """Every callable of the public API (the subpackages' ``__all__``),
    its required arguments all wrong (types, empty and non-finite arrays, integers where
    metres go), raises a FemTwinError naming what is wrong, never a numpy, scipy or
    Python error from inside."""
    import inspect
    calls = public_callables()
    assert len(calls) >= 140
    escaped = []
    for name, obj in calls:
        try:
            params = inspect.signature(obj).parameters.values()
        except (TypeError, ValueError):
            continue
        required = [p for p in params if p.default is inspect.Parameter.empty
                    and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
        for bad in WRONG:
            args = [bad for p in required if p.kind != p.KEYWORD_ONLY]
            kwargs = {p.name: bad for p in required if p.kind == p.KEYWORD_ONLY}
            try:
                obj(*args, **kwargs)
            except FemTwinError:
                pass
            except Exception as err:                     # noqa: BLE001 (what escapes)
                escaped.append(f"{name}({type(bad).__name__}): {type(err).__name__}: {err}")
    assert not escaped, "\n".join(escaped)


#: settings that carry no number of their own: file paths, switches, text, addresses and a
#: section filled in whole (its own keys are walked as that section's)
UNRANGED_UNITS = {"file path", "file paths", "file path pairs", "true or false", "address",
                  "a registered model", "a section"}


def _declared_settings():
    from dataclasses import fields

    from fem_twin.case.sections import SECTIONS
    from fem_twin.macro import MacroSettings
    from fem_twin.macro.laws.thermal import ThermalSettings
    from fem_twin.micro.sliding import CellSettings
    for cls in {CellSettings, MacroSettings, ThermalSettings, *SECTIONS.values()}:
        for f in fields(cls):
            yield cls, f


def test_every_numeric_setting_declares_a_plausible_range():
    """Every setting of the case file and of the stages' settings objects
    either names a quantity of ``checks.QUANTITIES`` (its plausible range and unit, shown
    in the generated case-file reference) or is text, a switch or a file; its default lies
    inside that range, and an API object built with a value a thousand times outside it
    (a unit slip) is refused with the field named."""
    from dataclasses import MISSING

    from fem_twin.checks import OFF_AT_ZERO, QUANTITIES
    missing = [f"{cls.__name__}.{f.name}" for cls, f in _declared_settings()
               if not f.metadata.get("quantity") and not f.metadata.get("choices")
               and f.metadata.get("unit") not in UNRANGED_UNITS]
    assert not missing, f"settings without a declared range: {missing}"
    for cls, f in _declared_settings():
        quantity = f.metadata.get("quantity")
        if not quantity or f.default is MISSING or f.default is None:
            continue
        lo, hi, _ = QUANTITIES[quantity]
        value = f.default if f.name != "pin" else 1
        off = quantity in OFF_AT_ZERO and np.all(np.asarray(value, float) == 0)
        assert off or np.all((lo <= np.asarray(value, float)) & (np.asarray(value, float) <= hi)), (
            cls.__name__, f.name)
        if not f.metadata.get("section") and quantity not in ("pin_number",):
            slip = hi * 1000 if hi > 0 else lo * 1000
            bad = (slip,) * len(value) if isinstance(value, tuple) else slip
            with pytest.raises(InputError, match=f.name):
                cls(**{f.name: type(value)(bad) if not isinstance(value, tuple) else bad})
    from fem_twin.macro import MacroSettings
    with pytest.raises(InputError, match="max_iter: expected whole numbers"):
        MacroSettings(max_iter=10.5)


def test_settings_refuse_text_none_and_truthy_flags_where_a_number_or_flag_goes():
    """``check_ranges`` refused numbers out of range but let text and None through, which
    failed later with a bare error, and took ``"no"`` for a flag (truthy)."""
    from fem_twin.macro import BoundaryLaw, MacroSettings
    from fem_twin.macro.laws.thermal import ThermalSettings
    from fem_twin.macro.reference.deterministic import DeterministicSettings
    from fem_twin.micro.sliding import CellSettings
    for make, words in ((lambda: DeterministicSettings(film_deforms="no"), "true or false"),
                        (lambda: BoundaryLaw(film_on_contacts="yes"), "true or false"),
                        (lambda: BoundaryLaw(thin_films="yes"), "one of 'boundary'"),
                        (lambda: BoundaryLaw(shear_strength="10 MPa"), "10 MPa is 1e7"),
                        (lambda: BoundaryLaw(pressure_coefficient=None), "alpha|got None"),
                        (lambda: MacroSettings(tol="1e-6"), "tol"),
                        (lambda: BoundaryLaw(shear_strength=10.0), "shear_strength = 10"),
                        (lambda: ThermalSettings(bulk_resistance=None), "bulk_resistance"),
                        (lambda: DeterministicSettings(max_iter=2.5), "whole numbers"),
                        (lambda: DeterministicSettings(boundary_film=5e-7), "boundary_film")):
        with pytest.raises(InputError, match=words):
            make()
    assert CellSettings(time_tol=0).time_tol is None                  # 0 and None: off
    assert BoundaryLaw(law="shear", shear_strength=0.0).shear_strength == 0.0  # 0: none


def test_the_new_public_functions_check_their_arguments():
    """Issue 87 item 7: each raised a bare error or returned NaN."""
    from fem_twin.macro import BoundaryLaw, Lubricant, boundary_traction
    from fem_twin.macro.laws.thermal import ThermalSettings, face_flash
    from fem_twin.macro.laws.viscosity import WaltherLaw
    from fem_twin.macro.point import OperatingPoint
    from fem_twin.micro import FlowFactors
    from fem_twin.runtime.machine import probe_seconds
    gap = np.full((9, 9), 1e-6)
    point = dict(load=10.0, speed=1.0, lubricant=Lubricant(0.066))
    law = WaltherLaw.through([24.0, 50.0], [0.066, 0.024], 850.0)
    ones = np.ones((4, 4))
    for make, words in (
            (lambda: law.viscosity(-500.0), "absolute zero"),
            (lambda: probe_seconds("bogus"), "kind is one of"),
            (lambda: probe_seconds("micro", repeats=0), "repeats"),
            (lambda: face_flash(ones, ones > 0, (1e-5, 1e-5), 1.0, ThermalSettings()),
             "pair"),
            (lambda: boundary_traction(ones, ones, np.ones(3), 1.0, BoundaryLaw(), 0.1),
             "one grid"),
            (lambda: boundary_traction(ones, ones, 5 * ones, 1.0, BoundaryLaw(), 0.1),
             r"\[0, 1\]"),
            (lambda: boundary_traction(-ones, ones, ones / 2, 1.0, BoundaryLaw(), 0.1),
             "not negative"),
            (lambda: OperatingPoint(gap, (1e-5, 1e-5), FlowFactors.smooth(), **{
                **point, "lubricant": None}), "Lubricant"),
            (lambda: OperatingPoint(gap, (1e-5, 1e-5), FlowFactors.smooth(), **point,
                                    settings=None), "MacroSettings"),
            (lambda: OperatingPoint(gap, (1e-5, 1e-5), FlowFactors.smooth(), **point,
                                    face=np.zeros((9, 9), bool)), "all False"),
            (lambda: OperatingPoint(gap + 0j, (1e-5, 1e-5), FlowFactors.smooth(), **point),
             "real numbers")):
        with pytest.raises(InputError, match=words):
            make()


def test_unit_slips_and_impossible_values_of_the_round_six_functions():
    """Issue 87's probe table: each call returned a result (NaN, or on a wrong scale)."""
    from fem_twin import contact
    from fem_twin.macro import BoundaryLaw, Lubricant
    from fem_twin.peers import average_flow_factors
    from fem_twin.stribeck import StribeckCurve
    from fem_twin.stribeck.analysis import knee_speed
    from fem_twin.studies.verification import RoughPad
    from fem_twin.topography import Topography
    rng = np.random.default_rng(1)
    pin = Topography(1e-7 * rng.standard_normal((32, 32)), 1e-6)
    flat = Topography(np.zeros((32, 32)), 1e-6)
    two = np.ones(2)
    curve = StribeckCurve(speed=np.array([0.01, 0.1]), hersey=two,
                          friction_coefficient=np.array([0.1, 0.05]), viscosity=0.066,
                          hydrodynamic_friction=two, boundary_force=two,
                          contact_load_fraction=np.array([0.9, 0.1]), h_d=two, iterations=two)
    for make, words in (
            (lambda: average_flow_factors(pin, flat, 231.0), "e_reduced"),
            (lambda: average_flow_factors(pin, flat, 231e9, h0=[0.5]), "h0"),
            (lambda: average_flow_factors(pin, flat, 231e9, slide_to_roll=5.0), "slide_to_roll"),
            (lambda: knee_speed(curve, share=1.5), "share"),
            (lambda: RoughPad(None, 1e-6, Lubricant(0.066)), "roughness"),
            (lambda: BoundaryLaw(pressure_coefficient=np.array([0.1, 0.2])), "one number"),
            (lambda: contact.solve(1e6 * pin.heights, 1e-6, 231e9, load=1.0), "metres")):
        with pytest.raises(InputError, match=words):
            make()
    assert knee_speed(curve) == pytest.approx(np.sqrt(0.01 * 0.1))


def _round_five_api_probes():
    """``(probe id, call, words)`` of issue 87's API probes that returned a result, raised a
    bare error or named neither the argument nor its unit."""
    from fem_twin.macro.laws.boundary_friction import (
        BoundaryLaw,
        asperity_load,
        boundary_area,
        boundary_traction,
        temperature_factor,
    )
    from fem_twin.macro.laws.friction import FilmFields
    from fem_twin.macro.laws.lubricant import Lubricant
    from fem_twin.macro.laws.thermal import ThermalSettings, face_flash, spot_flash
    from fem_twin.macro.laws.viscosity import WaltherLaw
    from fem_twin.macro.reference.deterministic import DeterministicSettings
    from fem_twin.macro.reference.film_friction import pad_friction
    from fem_twin.macro.reference.time_resolved import disk_at, solve_time_resolved
    from fem_twin.peers import Summits, average_flow_factors, contact_pressure, mean_gap
    from fem_twin.peers import patir_cheng as pc
    from fem_twin.runtime import machine
    from fem_twin.studies import verification as V
    from fem_twin.topography.statistics import RoughnessStatistics, roughness_statistics
    rng = np.random.default_rng(0)
    pin = Topography(1e-7 * rng.standard_normal((32, 32)), 1e-6)
    disk = Topography(1e-7 * rng.standard_normal((32, 32)), 1e-6)
    summits = Summits.from_moments(1e-13, 1e-2, 1e9)
    law = BoundaryLaw(law="shear", shear_strength=1e7, pressure_coefficient=0.1,
                      temperature_coefficient=0.002)
    zeros, micron = np.zeros((5, 5)), np.full((5, 5), 1e-6)
    x = np.linspace(-1, 1, 17)
    gap = 1e-6 * (x[None, :] ** 2 + x[:, None] ** 2)
    face, flux = np.ones((8, 8), bool), np.full((8, 8), 1e6)
    pad = V.RoughPad(roughness=0.2e-6 * rng.standard_normal((8, 8)), pitch=2e-6,
                     lubricant=Lubricant(0.066))
    pair = V.Pair(2, 0.1, 0.5, 0.5, 1e-6, 1e-6, 0.1, 0.1, 0.1, 0.1)
    sample = ROOT / "meshes" / "sample"
    return [
        ("A031", lambda: average_flow_factors(pin, disk, 231e9, h0=[[1e-7, 2e-7]] * 2), "h0"),
        ("A040", lambda: Summits(-1.0, 1e-5, 1e-7, 0.0), "Summits.density"),
        ("A041", lambda: Summits("a", 1e-5, 1e-7, 0.0), "Summits.density"),
        ("A042", lambda: Summits(1e10, 1e-5, float("nan"), 0.0), "Summits.spread"),
        ("A058", lambda: Summits(1e10, 0.0, 1e-7, 0.0), "Summits.radius"),
        ("A043", lambda: contact_pressure([1e-7], summits, 231.0), r"e_reduced \[Pa\]"),
        ("A044", lambda: contact_pressure([1e-7], summits, -231e9), r"e_reduced \[Pa\]"),
        ("A004", lambda: mean_gap([1e-6], 1.0), r"sigma.*\[m\]"),
        ("A009", lambda: mean_gap([1.0], 1e-7), r"h \[m\]"),
        ("A069", lambda: pc.pressure_flow([1.0], 1.0, hold="yes"), "hold: expected bool"),
        ("A085", lambda: RoughnessStatistics(1e-6, (1e-5, 0.0), (1.0, 1.0), (1.0, 1.0)),
         "lengths"),
        ("A088", lambda: RoughnessStatistics(-1.0, (1e-5, 1e-5), (1.0, 1.0), (1.0, 1.0)),
         "sigma"),
        ("A080", lambda: roughness_statistics(Topography(np.zeros((32, 32)), (1e-6, 1e-6))),
         "flat cell"),
        ("A113", lambda: boundary_traction(1e6, 0.0, 0.5, 1.0, BoundaryLaw(), 12.0),
         "boundary_friction = 12: implausible"),
        ("A114", lambda: boundary_traction(1e6, 0.0, 0.5, 1.0, BoundaryLaw(), -0.12),
         "boundary_friction"),
        ("A119", lambda: temperature_factor(law, 297.15), "not kelvin"),
        ("A121", lambda: temperature_factor(law, 50.0, rise_per_shear=-5.0),
         r"rise_per_shear = -5 K"),
        ("A124", lambda: boundary_area(None, BoundaryLaw()), "boundary_area: shear"),
        ("A126", lambda: asperity_load("1e6", 1e5, 0.5, law=BoundaryLaw()),
         "contact_pressure"),
        ("A146", lambda: face_flash(flux, ~face, (1e-5, 1e-5), (0.0, 1.0), ThermalSettings()),
         "face has no node"),
        ("A151", lambda: face_flash(-flux, face, (1e-5, 1e-5), (0.0, 1.0), ThermalSettings()),
         r"flux \[W/m\^2\]"),
        ("A154", lambda: spot_flash(1e6, (0.0, 1.0), ThermalSettings(), n=0), "spot_flash: n"),
        ("A162", lambda: WaltherLaw.through([24.0, 50.0], [0.066, 0.024], 850.0).viscosity(1e6),
         r"temperature \[C\]"),
        ("A166", lambda: WaltherLaw(float("nan"), 1.0, 850.0), "WaltherLaw.a"),
        ("A195", lambda: pad_friction(FilmFields(zeros, np.ones((6, 6)), zeros, 0.066),
                                      (1e-5, 1e-5), 0.1, 1e-8), "one grid"),
        ("A196", lambda: pad_friction(FilmFields(zeros, micron, zeros, 0.066), (1e-5, 1e-5),
                                      0.1, -1e-8), r"boundary_film \[m\]"),
        ("A197", lambda: pad_friction(FilmFields(zeros, micron, zeros, -0.066), (1e-5, 1e-5),
                                      0.1, 1e-8), r"viscosity \[Pa s\]"),
        ("A198", lambda: pad_friction(FilmFields(zeros, micron, zeros + 3, 0.066),
                                      (1e-5, 1e-5), 0.1, 1e-8), "cavity_fraction"),
        ("A199", lambda: pad_friction(FilmFields(zeros, micron, zeros, 0.066), (0.0, 1e-5),
                                      0.1, 1e-8), r"spacing \[m\]"),
        ("A215", lambda: disk_at(np.zeros((9, 9)), float("nan"), 9), "shift"),
        ("A216", lambda: disk_at(np.zeros((9, 9)), 0.5, 0), "nodes"),
        ("A217", lambda: disk_at(None, 0.5, 9), "disk"),
        ("A221", lambda: solve_time_resolved(
            (gap, np.full((17, 17), 1.0)), (1e-5, 1e-5), load=1.0, speed=0.1,
            lubricant=Lubricant(0.066), settings=DeterministicSettings()), "disk"),
        ("A250", lambda: V.summary([pair], 0.0), "boundary_friction"),
        ("A252", lambda: V.compared([1, 2], [3, 4], 2), "compared: det"),
        ("A253", lambda: V.compared([], [], 2.5), "tiles"),
        ("A254", lambda: V.with_settings(pad, bogus=1), "bogus: not a setting"),
        ("A257", lambda: V.sample_pad(sample, pixels=32.5), "pixels"),
        ("A264", lambda: V.sample_pad(sample, pixels=0), "pixels"),
        ("A306", lambda: machine.probe_together("micro", 0), "processes"),
    ]


@pytest.mark.parametrize("probe", range(len(_round_five_api_probes())))
def test_the_round_five_api_probes_raise_input_errors_naming_the_argument(probe):
    """Issue 87's bad API probes: each is an InputError naming the argument (and its unit
    where it has one), with no numpy warning on the way."""
    import warnings
    ident, make, words = _round_five_api_probes()[probe]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match=words):
            make()


def test_curves_read_back_from_a_csv_make_a_dataset():
    """Probes A290, A291: curves of stribeck.csv carry the total C_f error without its
    parts, and stribeck_dataset raised TypeError on them."""
    from fem_twin.results import stribeck_dataset
    from fem_twin.stribeck import StribeckCurve
    two = np.ones(2)
    curve = StribeckCurve(speed=np.array([0.01, 0.1]), hersey=two,
                          friction_coefficient=np.array([0.1, 0.05]), viscosity=0.066,
                          hydrodynamic_friction=two, boundary_force=two,
                          contact_load_fraction=np.array([0.9, 0.1]), h_d=two,
                          iterations=two, friction_error=np.array([1e-4, 2e-4]))
    ds = stribeck_dataset([curve])
    assert ds["cf_err"].values.tolist() == [[1e-4, 2e-4]]
    assert stribeck_dataset([curve], patch_curves=[[curve]])["cf_max"].shape == (1, 2)
    with pytest.raises(InputError, match="patch_curves"):         # a patch without curves
        stribeck_dataset([curve], patch_curves=[[]])


def test_a_kelvin_reference_temperature_is_refused_where_it_meets_a_temperature():
    """Probe A108: BoundaryLaw(reference_temperature=297.15) alone cannot tell kelvin from
    Celsius (it lies in -40 to 300 C); at a film temperature of 50 C its factor was 1.49,
    the shear raised 49 %.  temperature_factor refuses a temperature more than 100 K from
    T_ref, as the case parser does at every oil."""
    from fem_twin.macro.laws.boundary_friction import BoundaryLaw, temperature_factor
    law = BoundaryLaw(law="shear", shear_strength=1e7, pressure_coefficient=0.1,
                      temperature_coefficient=0.002, reference_temperature=297.15)
    with pytest.raises(InputError, match="not kelvin"):
        temperature_factor(law, 50.0)
    assert temperature_factor(BoundaryLaw(**{**law.__dict__, "reference_temperature": 24.0}),
                              50.0) == pytest.approx(1 - 0.002 * 26)
