"""A checkpoint is read back only for what it was made for: a valid file copied over
another's (another speed, another h0) is set aside as damaged and recomputed."""

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from fem_twin import Topography
from fem_twin.errors import InputError
from fem_twin.macro import Lubricant, MacroSettings
from fem_twin.micro import homogenise
from fem_twin.stribeck import SweepRequest, stribeck_sweep
from fem_twin.stribeck.sweep import point_files
from fem_twin.topography.synthetic import self_affine

sys.path.insert(0, str(Path(__file__).parent))
from sample_cases import macro_case, smooth_factors  # noqa: E402


def test_a_stribeck_point_copied_over_another_is_recomputed(tmp_path):
    """Sample pin 1 at 32^2, smooth factors, two speeds: the 0.5 m/s point's file copied
    over the 1 m/s one's is moved to ``.corrupt`` on the rerun and the 1 m/s point solved
    again, to the first run's C_f (it was read back as the other point, whose C_f differs
    by more than 10 %)."""
    gap, dx, face = macro_case(32)
    request = SweepRequest(gap, dx, smooth_factors(), [1.0, 0.5], load=150.0,
                           lubricant=Lubricant(0.066), face=face, checkpoint=tmp_path,
                           settings=MacroSettings(tol=1e-6))
    first = stribeck_sweep(request)
    fast, slow = sorted(point_files(tmp_path), key=lambda p: -float(p.stem.rsplit("_", 1)[1]))
    fast.write_bytes(slow.read_bytes())
    again = stribeck_sweep(request)
    assert fast.with_name(fast.name + ".corrupt").is_file()
    assert np.array_equal(again.friction_coefficient, first.friction_coefficient)
    assert abs(first.friction_coefficient[1] / first.friction_coefficient[0] - 1) > 0.1


def test_an_h0_checkpoint_copied_over_another_is_recomputed(tmp_path):
    """A random cell at two separations: the 0.4 um moments copied over the 0.2 um file are
    set aside and recomputed, the factors equal to the first run's."""
    dx = 40e-6 / 16
    pin = self_affine((16, 16), (dx, dx), 0.8, 0.1e-6, rng=4)
    disk = Topography(np.zeros((16, 16)), (dx, dx))
    kw = dict(steps=2, error_estimate=False, checkpoint=tmp_path)
    first = homogenise(pin, disk, [0.2e-6, 0.4e-6], **kw)
    low, high = sorted(tmp_path.glob("*_h0_*.json"))
    low.write_text(high.read_text())
    again = homogenise(pin, disk, [0.2e-6, 0.4e-6], **kw)
    assert low.with_name(low.name + ".corrupt").is_file()
    assert np.array_equal(again.A, first.A) and np.array_equal(again.h_m, first.h_m)


def _changed(value):
    """``value`` changed a little, whatever its kind (a number, an array, a dataclass's first
    number, a string, None)."""
    from dataclasses import fields, replace
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return value + 1
    if isinstance(value, float):
        return value * 1.01 + 1e-9
    if isinstance(value, np.ndarray):
        out = value.copy()
        out.flat[0] = (not out.flat[0]) if out.dtype == bool else out.flat[0] * 1.01 + 1e-12
        return out
    if isinstance(value, tuple):
        return (_changed(value[0]), *value[1:])
    if isinstance(value, str):
        return value + "x"
    for f in fields(value):                  # the first number whose change is plausible
        if isinstance(getattr(value, f.name), (int, float)) and not isinstance(
                getattr(value, f.name), bool):
            try:
                return replace(value, **{f.name: _changed(getattr(value, f.name))})
            except InputError:               # 0 -> 1e-9 Pa of a tau_0: below its range
                continue
    raise AssertionError(f"no field to change in {value!r}")


def test_the_sweep_key_changes_with_every_field_that_sets_the_points():
    """A sweep's checkpoint key is derived from its request: changing any field outside the
    declared exclusions (where points are written, the speeds, the Hersey length, the
    starts), or any field of its settings, lubricant, thermal model or factors, changes the
    key; changing an excluded one does not (nor the settings' order of the error
    estimate's macro part, which the estimate records).  A new physics field can therefore not reuse
    stale checkpoints."""
    from dataclasses import fields, replace

    from fem_twin.macro.laws.thermal import ContactThermal, ThermalSettings
    from fem_twin.macro.laws.viscosity import WaltherLaw
    from fem_twin.stribeck import request as rq
    gap, dx, face = macro_case(16)
    law = WaltherLaw.through([24.0, 50.0], [0.066, 0.024], 850.0)
    base = SweepRequest(gap, dx, smooth_factors(), [1.0], load=150.0,
                        lubricant=Lubricant(0.066), face=face,
                        thermal=ContactThermal(ThermalSettings(), law))
    key = base.key
    nested = {"settings": base.settings, "lubricant": base.lubricant,
              "thermal": base.thermal, "factors": base.factors}
    for f in fields(base):
        value = getattr(base, f.name)
        if f.name in rq.NOT_KEYED or f.name in nested or f.name == "motion":
            continue
        changed = ({"load_share": 0.9}.get(f.name) or _changed(value) if value is not None
                   else "factors of a run")
        assert replace(base, **{f.name: changed}).key != key, f.name
    for name, value in nested.items():
        for g in fields(value):
            if g.name == "meta" or isinstance(getattr(value, g.name), str):
                continue
            inner = getattr(value, g.name)
            if inner is None:
                continue
            moved = replace(value, **{g.name: _changed(inner)})
            assert replace(base, **{name: moved}).key != key, (name, g.name)
    from fem_twin.stribeck.request import RollingSliding
    assert replace(base, motion=RollingSliding(1.0)).key != key
    for name, value in (("speeds", [2.0]), ("hersey_length", 9e-3), ("origin", (1.0, 0.0)),
                        ("error_estimate", True), ("keep_level", 1), ("guide", "abc"),
                        ("settings", replace(base.settings, grid_order=2.0))):
        assert replace(base, **{name: value}).key == key, name


def test_a_point_whose_estimate_was_made_another_way_is_estimated_again(tmp_path):
    """A Stribeck point checkpointed with a C_f error estimate of another method (an
    earlier fem_twin's: no ``"method"``, the film's sensitivity in its total) keeps its
    solution on a resumed run but gets its estimate made again, equal to the first run's;
    a current estimate is read back as it is."""
    from fem_twin.io.checkpoint import load_or_none
    from fem_twin.macro import MixedResult
    from fem_twin.macro.estimate import METHOD

    gap, dx, face = macro_case(32)
    request = SweepRequest(gap, dx, smooth_factors(), [0.5], load=150.0,
                           lubricant=Lubricant(0.066), face=face, checkpoint=tmp_path,
                           settings=MacroSettings(tol=1e-6), error_estimate=True)
    first = stribeck_sweep(request)
    (path,) = point_files(tmp_path)
    res = load_or_none(path, MixedResult.load)
    assert res.meta["error_estimate"]["method"] == METHOD
    old = {k: v for k, v in res.meta["error_estimate"].items() if k != "method"}
    old["total"] = 1.0                                     # an older total: not this one
    replace(res, meta={**res.meta, "error_estimate": old}).save(path)
    again = stribeck_sweep(request)
    assert again.friction_error[0] == first.friction_error[0] != 1.0
    assert load_or_none(path, MixedResult.load).meta["error_estimate"]["method"] == METHOD
    # another macro order: the same points (the same key), the estimate made again
    second = replace(request, settings=replace(request.settings, grid_order=2.0))
    assert second.key == request.key
    assert stribeck_sweep(second).friction_error[0] != first.friction_error[0]
    assert load_or_none(path, MixedResult.load).meta["error_estimate"]["macro_order"] == 2.0
