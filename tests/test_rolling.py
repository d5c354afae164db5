"""Rolling-sliding kinematics (fem_twin.micro.rolling): the cell with both surfaces moving,
its identities, the frame change the macro scale uses, and the mean-speed frame."""

import numpy as np
import pytest

from fem_twin.errors import InputError
from fem_twin.macro import MacroSettings, solve_mixed
from fem_twin.macro.laws.lubricant import Lubricant
from fem_twin.micro import FlowFactors, at_slide_to_roll, average, homogenise
from fem_twin.topography.synthetic import self_affine

H0 = [0.2e-6, 1e-6]                        # 4-6 % of the pixels in contact, and none


def pair(n=32, seed=1):
    """A random pair whose spectrum stops at 8 px of the 64 px cell (a filtered measurement)."""
    dx = 85e-6 / n
    return tuple(self_affine((n, n), (dx, dx), 0.8, 100e-9, rng=s, short_cutoff=85e-6 / 8)
                 for s in (seed, seed + 1))


def cell(pin, disk, method="fe", **kw):
    return homogenise(pin, disk, H0, steps=16, method=method, error_estimate=False, **kw)


def flipped(t):
    return t.with_heights(-t.heights)


ARRAYS = ("h_m", "p_con", "A", "b", "C", "d")


@pytest.mark.parametrize("method", ["fe", "fvm"])
def test_the_cell_with_both_surfaces_moving_is_linear_in_their_speeds(method):
    """Eq 8's right-hand side is linear in the two speeds at each instant (the contact and
    eqs 9-10 see only the relative position), so the laboratory cell at SRR is
    ``(1 - SRR/2)`` times the pure rolling cell plus ``SRR/2`` times the sliding one, to
    the tolerance of the contact rate (``rate_tol`` 1e-6; measured 7e-9); A, C, h_m and
    p_con do not depend on the speeds at all."""
    pin, disk = pair()
    sliding = cell(pin, disk, method, moving="upper")
    rolling = cell(pin, disk, method, moving="upper", slide_to_roll=0.0)
    mixed = cell(pin, disk, method, moving="upper", slide_to_roll=0.5)
    assert sliding.contact_fraction[0] > 0.02
    for name in ("b", "d"):
        expect = 0.75 * getattr(rolling, name) + 0.25 * getattr(sliding, name)
        assert np.abs(getattr(mixed, name) - expect).max() < 1e-7
    for name in ("h_m", "p_con", "A", "C"):
        assert np.allclose(getattr(mixed, name), getattr(sliding, name), rtol=1e-12, atol=0)


@pytest.mark.parametrize("method", ["fe", "fvm"])
def test_swapping_the_surfaces_and_their_speeds_gives_the_same_factors(method):
    """The disk's roughness below at the pin's speed and the pin's above at the disk's:
    the same gap with the wall speeds exchanged, SRR -> -SRR.  Eq 8 does not know which wall
    is which, and the relative positions are the same set (in reverse order), so every
    factor is the same, to the contact solver's tolerance; with the pin at rest (SRR 2)
    its mirror is the disk at rest and the pin moving (SRR -2).  So is the friction factor
    (the force on the lower body per mu u_r: both change sign), while the Poiseuille
    friction is the other body's, ``2 e1 - (2 e1 - b)``."""
    pin, disk = pair()
    for srr in (0.5, 2.0):
        a = cell(pin, disk, method, moving="upper", slide_to_roll=srr)
        b = cell(flipped(disk), flipped(pin), method, moving="upper", slide_to_roll=-srr)
        for name in ARRAYS + ("friction_factor",):
            ref = np.abs(getattr(a, name)).max()
            assert np.abs(getattr(a, name) - getattr(b, name)).max() < 1e-7 * ref, name
        # the other body's Poiseuille friction: the two take -h_m grad p together
        assert np.abs(a.pressure_friction + b.pressure_friction - [2, 0]).max() < 1e-7


def test_a_common_translation_changes_only_the_couette_factor():
    """Both surfaces moved at an extra speed c: in eq 17's form ``u_m b`` grows by ``c e1``
    (the frame change), ``u_m d`` and everything else stays.  At the same sliding speed
    u_r = 1, SRR 0.5 (u_m = 2) against SRR 1 (u_m = 1).  Without contact to round-off for
    the FVM (its Couette difference is the central difference of the squeeze term) and the
    FE's second-order spatial error (measured 3e-5 at 64^2); with contact (5 % of the
    pixels) to the discretisation of the contact edges (FE measured 2.2e-3 in u_m b1)."""
    pin, disk = pair(64)
    for method, tol_free, tol_contact in (("fvm", 1e-12, 0.02), ("fe", 1e-4, 0.005)):
        fast = cell(pin, disk, method, moving="upper", slide_to_roll=0.5)    # u_m = 2
        slow = cell(pin, disk, method, moving="upper", slide_to_roll=1.0)    # u_m = 1
        couette = 2 * fast.b - slow.b - [1.0, 0.0]                           # 0 exactly
        shear = 2 * fast.d - slow.d
        assert np.abs(couette[1]).max() < tol_free and np.abs(shear[1]).max() < tol_free
        assert np.abs(couette[0]).max() < tol_contact
        assert np.allclose(fast.A, slow.A, rtol=1e-12) and np.allclose(fast.C, slow.C,
                                                                       rtol=1e-12)


def test_pure_rolling_over_a_smooth_surface_has_only_the_kinematic_squeeze():
    """A rough pin rolling with a smooth disk (SRR 0): the roughness is carried through the
    contact unchanged, so chi_1 = 0, b = e1, d = 0.  Without contact the FVM gives it to
    round-off and the FE to its second-order spatial error, which falls 4x per halving of
    the pixel on a cosine ridge refined exactly."""
    def ridge(n):
        dx = 85e-6 / n
        z = 0.5e-6 * np.cos(2 * np.pi * np.arange(n) / n) + 0.1e-6 * np.sin(
            4 * np.pi * np.arange(n) / n)[:, None]
        from fem_twin import Topography
        rough = Topography(z, (dx, dx))
        return rough, rough.with_heights(np.zeros((n, n)))

    errors = []
    for n in (32, 64, 128):
        rough, flat = ridge(n)
        fv = homogenise(rough, flat, [1e-6], steps=8, method="fvm", moving="upper",
                        slide_to_roll=0.0, error_estimate=False)
        assert np.abs(fv.b - [1, 0]).max() < 1e-12 and np.abs(fv.d).max() < 1e-12
        fe = homogenise(rough, flat, [1e-6], steps=8, moving="upper", slide_to_roll=0.0,
                        error_estimate=False)
        errors.append(np.abs(fe.b - [1, 0]).max())
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all((orders > 1.8) & (orders < 2.2)), (errors, orders)


@pytest.mark.parametrize("method", ["fe", "fvm"])
def test_the_mean_speed_frame_is_the_pin_frame_without_its_rolling_error(method):
    """The default cell (``moving="both"``: disk at +U/2, pin at -U/2, no Couette term) is
    by linearity the pin's frame minus its pure rolling cell: ``b - b_0 + e1`` and
    ``d - d_0``, to the contact rate's tolerance (measured 4e-9); and the rough disk
    moving over the pin and the pin's roughness moving under the disk are mirror images
    (b' = 2 e1 - b, d' = -d) to the same, with contact too."""
    pin, disk = pair()
    mean = cell(pin, disk, method)
    upper = cell(pin, disk, method, moving="upper")
    rolling = cell(pin, disk, method, moving="upper", slide_to_roll=0.0)
    assert np.abs(mean.b - (upper.b - rolling.b + [1, 0])).max() < 1e-7
    assert np.abs(mean.d - (upper.d - rolling.d)).max() < 1e-7
    flip = cell(flipped(disk), flipped(pin), method)           # the pin's roughness moving
    assert np.abs(mean.b + flip.b - [2, 0]).max() < 1e-7
    assert np.abs(mean.d + flip.d).max() < 1e-7


def small_factors(srr=None):
    h0 = np.geomspace(1e-7, 1e-6, 4)
    n = h0.size
    meta = {} if srr is None else {"slide_to_roll": srr}
    b = np.column_stack([np.linspace(0.7, 0.95, n), np.zeros(n)])
    d = np.column_stack([np.linspace(0.3, 0.05, n), np.zeros(n)])
    variant = {"h0": h0.tolist(), "h_m": h0.tolist(), "p_con": [0.0] * n,
               "A": np.tile(np.eye(2), (n, 1, 1)).tolist(), "b": (b + 0.01).tolist(),
               "C": np.tile(np.eye(2), (n, 1, 1)).tolist(), "d": d.tolist(),
               "friction_factor": (1 - 3 * d[:, 0]).tolist(),
               "pressure_friction": np.tile([1.0, 0.0], (n, 1)).tolist(),
               "contact_fraction": [0.0] * n}
    return FlowFactors(h0=h0, h_m=h0 * 1.1, p_con=np.zeros(n), A=np.tile(np.eye(2), (n, 1, 1)),
                       b=b, C=np.tile(np.eye(2), (n, 1, 1)), d=d, friction_factor=1 - 3 * d[:, 0],
                       pressure_friction=np.tile([1.0, 0.0], (n, 1)), contact_fraction=np.zeros(n),
                       meta={**meta, "variants": {"time": variant}})


def test_factors_carried_to_another_srr():
    """b -> e1 + k (b - e1), d -> k d with k = SRR_new / SRR_own, the variants too; a round
    trip returns the factors; smooth factors do not change; pure rolling factors refuse."""
    f = small_factors()
    half = at_slide_to_roll(f, 0.5)
    assert half.meta["slide_to_roll"] == 0.5
    assert np.allclose(half.b[:, 0], 1 + 0.25 * (f.b[:, 0] - 1), rtol=1e-14)
    assert np.allclose(half.d, 0.25 * f.d, rtol=1e-14)
    assert np.allclose(half.variants()["time"].b[:, 0], 1 + 0.25 * (f.b[:, 0] + 0.01 - 1))
    assert half.variants()["time"].meta["slide_to_roll"] == 0.5
    back = at_slide_to_roll(at_slide_to_roll(half, 1.5), 2.0)
    assert np.allclose(back.b, f.b, rtol=1e-14) and np.allclose(back.d, f.d, rtol=1e-14)
    smooth = FlowFactors.smooth()
    assert np.array_equal(at_slide_to_roll(smooth, 0.3).b, smooth.b)
    assert at_slide_to_roll(f, 2.0) is f
    with pytest.raises(InputError, match="pure rolling"):
        at_slide_to_roll(at_slide_to_roll(f, 0.0), 1.0)
    with pytest.raises(InputError, match="slide_to_roll"):
        at_slide_to_roll(f, 2.5)
    with pytest.raises(InputError, match="differ in slide_to_roll"):
        average([f, half])


def test_a_ball_at_srr_2_is_the_pin_and_a_rolling_ball_has_no_couette_shear():
    """solve_mixed at speed u_r with entrainment u_r/2 is the pin-on-disk point, bit for bit;
    at SRR 0 (speed 0) the Couette shear of eq 31 vanishes, and C_f is smooth in SRR: the
    parabola through SRR 0.4, 0.2 and 0.1 reaches the SRR 0 point within 1e-3 of C_f at
    SRR 2 (measured 1e-4; the film changes with SRR through b - e1, so C_f is not linear)."""
    n, a = 25, 100e-6
    x = np.linspace(-2 * a, 2 * a, n)
    X, Y = np.meshgrid(x, x)
    gap = (X ** 2 + Y ** 2) / (2 * 10e-3)
    f = small_factors()
    lub = Lubricant(viscosity=0.05)
    kw = dict(load=2.0, lubricant=lub, settings=MacroSettings(coupling="newton"))
    spacing = (x[1] - x[0],) * 2
    pin = solve_mixed(gap, spacing, f, speed=0.2, **kw)
    ball = solve_mixed(gap, spacing, f, speed=0.2, entrainment=0.1, **kw)
    assert ball.friction_coefficient == pin.friction_coefficient
    cf = [solve_mixed(gap, spacing, f, speed=s * 0.1, entrainment=0.1, **kw).friction_coefficient
          for s in (0.4, 0.2, 0.1)]
    rolling = solve_mixed(gap, spacing, f, speed=0.0, entrainment=0.1, **kw)
    extrapolated = 8 / 3 * cf[2] - 2 * cf[1] + cf[0] / 3
    assert abs(rolling.friction_coefficient - extrapolated) < 1e-3 * pin.friction_coefficient
    assert cf[0] > cf[1] > cf[2] > rolling.friction_coefficient
