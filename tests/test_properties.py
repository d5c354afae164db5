"""Property-based tests (hypothesis) of the inputs a user gives (issue 30 item 5): the case
parser on random values of every key, topographies of random shapes, NaN patterns and
pitches, and the CLI's exit codes on damaged files.  Whatever the input, the only failure
is fem_twin's own InputError (one line on the CLI, a documented exit code), never another
exception type or a traceback.  ``pytest -m slow`` runs 10x the examples."""

import math
import os
import tomllib

import numpy as np
import pytest
from conftest import ROOT
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from fem_twin import Topography
from fem_twin.case import parse_case
from fem_twin.cli import main
from fem_twin.errors import InputError
from fem_twin.topography import fill_defects, level

EXAMPLES = 400 if os.environ.get("FEM_TWIN_SLOW_PROPERTIES") else 40
CASE = tomllib.loads((ROOT / "examples" / "pin_on_disk.toml").read_text())
KEYS = [(section, key) for section, table in CASE.items() if isinstance(table, dict)
        for key in table if section != "geometry"]

values = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**6, 10**6),
                   st.booleans(), st.text(max_size=8),
                   st.lists(st.floats(-1e3, 1e3) | st.integers(-5, 300), max_size=3),
                   st.just([]), st.dictionaries(st.text(max_size=3), st.integers(), max_size=2))


def _parse(data):
    try:
        return parse_case(data, base=ROOT / "examples")
    except InputError as err:                  # the one accepted failure, with a message
        assert str(err)
        return None


@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.sampled_from(KEYS), values), min_size=1, max_size=3))
@example([(("micro", "time_tol"), "0")])    # found by CI: a setting whose 0 means off
def test_case_parser_accepts_or_refuses_cleanly(changes):
    data = {s: dict(t) if isinstance(t, dict) else t for s, t in CASE.items()}
    for (section, key), value in changes:
        data[section][key] = value
    case = _parse(data)
    if case is not None:                       # what is accepted is usable later
        assert all(isinstance(n, int) for n in (case.micro.h0_count, case.micro.steps,
                                                case.sweep.count, case.run.workers))
        assert case.run.workers >= 0 and min(case.micro.resolution) >= 8
        assert all(math.isfinite(v) and v > 0 for v in case.lubricant.viscosities)


@settings(max_examples=EXAMPLES, deadline=None)
@given(st.integers(0, 7), st.integers(0, 7), st.floats(allow_nan=True, allow_infinity=True),
       st.floats(0, 1), st.integers(0, 2**32 - 1),
       st.sampled_from([1e-9, 1e-6, 1.0, 1e3]))
def test_topographies_of_any_shape_fill_and_level_or_refuse(ny, nx, pitch, holes, seed, unit):
    rng = np.random.default_rng(seed)
    z = rng.normal(size=(ny, nx)) * unit
    z[rng.random((ny, nx)) < holes] = np.nan
    try:
        t = level(fill_defects(Topography(z, pitch)))
    except InputError as err:
        assert str(err)
        return
    assert np.all(np.isfinite(t.heights)) and t.shape == (ny, nx)


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory):
    """An output folder with a simulated curve, as ``fem-twin validate`` reads it."""
    from fem_twin.stribeck.curve import StribeckCurve, write_stribeck_csv
    out = tmp_path_factory.mktemp("run")
    u = np.geomspace(1.0, 0.01, 6)
    ones = np.ones_like(u)
    write_stribeck_csv(out / "stribeck.csv", [StribeckCurve(
        speed=u, hersey=0.066 * u * 8e-3 / 150, friction_coefficient=0.01 / u ** 0.5,
        viscosity=0.066, hydrodynamic_friction=ones, boundary_force=ones,
        contact_load_fraction=0 * u, h_d=1e-6 * ones, iterations=ones)])
    return out


csv_like = st.text(alphabet="speed,friction_coefficient_maxin0123456789.e-+\n ", max_size=120)


@settings(max_examples=max(EXAMPLES // 2, 10), deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.one_of(st.binary(max_size=200), csv_like.map(str.encode)),
       st.sampled_from(["run", "validate", "validate --rpm"]))
def test_cli_exits_with_a_documented_code_on_damaged_files(tmp_path, capsys, finished_run,
                                                          content, command):
    path = tmp_path / ("case.toml" if command == "run" else "m.csv")
    path.write_bytes(content)
    args = (["run", str(path), "-o", str(tmp_path / "o"), "--no-progress"] if command == "run"
            else command.split() + [str(finished_run), str(path)])
    code = main(args)
    err = capsys.readouterr().err
    assert code in (0, 2) and "Traceback" not in err and "internal error" not in err, err


@pytest.mark.slow
def test_properties_with_ten_times_the_examples():
    """The three properties above with 10x the examples (a few minutes)."""
    import subprocess
    import sys
    env = dict(os.environ, FEM_TWIN_SLOW_PROPERTIES="1")
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-m", "not slow", __file__],
                          env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-2000:]


@settings(max_examples=max(EXAMPLES // 2, 10), deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.integers(min_value=0, max_value=10_000))
def test_a_cut_stribeck_csv_is_refused_naming_the_file(tmp_path, finished_run, cut):
    """A run's stribeck.csv cut at any byte reads back whole (the cut at its end) or is
    refused with an InputError naming the file, never a Python error from inside."""
    from fem_twin.errors import InputError
    from fem_twin.stribeck.curve import read_stribeck_csv
    text = (finished_run / "stribeck.csv").read_bytes()
    path = tmp_path / "stribeck.csv"
    path.write_bytes(text[:cut % (len(text) + 1)])
    try:
        read_stribeck_csv(path)
    except InputError as err:
        assert str(path) in str(err)
