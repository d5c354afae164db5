"""The linear response of a point's friction coefficient to a change of its flow factors
(fem_twin.macro.coupling.linearised), against the point solved to convergence with the
changed factors: the bundled sample pin 1 at 32 x 32 nodes and sample patch 1's factors.

The changes are the factors' time variant scaled by ``eps``: the response is first order in
the change, so one step's error falls as ``eps^2`` where the Jacobian is exact (as ``eps``
where it is not); the chord step that follows leaves at most a fifth of it (0.10 and 0.02
here).  The references converge to 1e-9, far below the errors compared."""

from dataclasses import fields, replace

import pytest
from sample_cases import macro_case, sample_factors

from fem_twin.macro import BOUNDARY_FRICTION, Lubricant, MacroSettings, OperatingPoint
from fem_twin.macro.coupling import linearised
from fem_twin.macro.mixed import solve_point


def _scaled(factors, variant, eps):
    """``factors + eps (variant - factors)``, every array."""
    return type(factors)(**{f.name: getattr(factors, f.name) + eps * (
        getattr(variant, f.name) - getattr(factors, f.name))
        for f in fields(factors) if f.name != "meta"}, meta={})


@pytest.mark.parametrize("speed", [0.05, 0.02])
def test_the_response_is_the_converged_change_to_second_order(speed, monkeypatch):
    gap, dx, face = macro_case(32)
    factors = sample_factors()
    point = OperatingPoint(gap, dx, factors, speed=speed, face=face, load=150.0,
                           lubricant=Lubricant(0.066), settings=MacroSettings(tol=1e-9))
    base = solve_point(point)
    errors = {}
    for steps in (1, linearised.CHORD_STEPS):
        monkeypatch.setattr(linearised, "CHORD_STEPS", steps)
        for eps in (1.0, 0.5, 0.25):
            changed = _scaled(factors, factors.variants()["time"], eps)
            moved = solve_point(replace(point, factors=changed), initial=base)
            change = moved.friction_coefficient - base.friction_coefficient
            response = linearised.friction_responses(point, base, {"x": changed})["x"]
            errors[steps, eps] = (response - change, change)
    one = [abs(errors[1, eps][0]) for eps in (1.0, 0.5, 0.25)]
    assert one[1] / one[0] < 0.3 and one[2] / one[1] < 0.3, one       # eps^2: 0.25
    error, change = errors[linearised.CHORD_STEPS, 1.0]
    assert abs(change) > 5e-4 * BOUNDARY_FRICTION                 # a part that matters
    assert abs(error) < 0.01 * abs(change) and abs(error) < 0.2 * one[0]
