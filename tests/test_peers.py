"""The statistical peer (fem_twin.peers): Patir-Cheng's fits against their definitions and
limits, F_n against closed forms, Greenwood-Tripp against Greenwood-Williamson, McCool's
summits against a surface's counted summits, and the roughness statistics against a
surface of known spectrum."""

import numpy as np
import pytest
from scipy import special
from scipy.integrate import quad

from fem_twin.errors import InputError
from fem_twin.peers import (
    PairStatistics,
    Summits,
    average_flow_factors,
    contact_fraction,
    contact_pressure,
    mean_gap,
    tail_moment,
)
from fem_twin.peers import patir_cheng as pc
from fem_twin.topography import Topography
from fem_twin.topography.statistics import roughness_statistics

DX = 1e-7


def gaussian_surface(n, lengths, sigma=1e-7, seed=0):
    """A periodic surface whose circular autocorrelation is exactly that of the Gaussian
    ``exp(-(x1/l1)^2 - (x2/l2)^2)`` (``lengths`` in pixels): a white noise's phases under
    that spectrum's amplitudes."""
    n1 = 2 * np.pi * np.fft.fftfreq(n)
    k1, k2 = n1[None, :], n1[:, None]
    power = np.exp(-(k1 * lengths[0]) ** 2 / 4 - (k2 * lengths[1]) ** 2 / 4)
    noise = np.fft.fft2(np.random.default_rng(seed).standard_normal((n, n)))
    z = np.real(np.fft.ifft2(noise / np.abs(noise) * np.sqrt(power)))
    return z * sigma / z.std()


@pytest.mark.parametrize("lengths", [(5, 5), (20, 5), (6, 18)])
def test_statistics_of_a_known_spectrum(lengths):
    """lambda_0.5 = l sqrt(ln 2) within 1 % (linear reading between pixels), m2 = 2 s^2/l^2
    and m4 = 12 s^2/l^4 within 1 % (the sampled spectrum of a resolved Gaussian)."""
    st = roughness_statistics(Topography(gaussian_surface(256, lengths), DX))
    length = np.array(lengths) * DX
    assert np.allclose(st.lengths, length * np.sqrt(np.log(2)), rtol=0.01)
    assert st.gamma == pytest.approx(lengths[0] / lengths[1], rel=0.01)
    assert np.allclose(st.m2, 2e-14 / length ** 2, rtol=0.01)
    assert np.allclose(st.m4, 12e-14 / length ** 4, rtol=0.01)


def test_a_correlation_longer_than_the_cell_is_a_bound():
    """Ridges along the sliding (a correlation length of 48 px along x1 on a 64 px
    cell): the x1 length is the half cell and only a bound, gamma a lower bound; the peer
    takes the tables' edge, 9, and says both in its notes."""
    ridges = gaussian_surface(64, (48, 4))
    st = roughness_statistics(Topography(ridges, DX))
    assert st.bounded == (True, False) and st.gamma_bound == "lower"
    assert st.lengths[0] == pytest.approx(32 * DX)
    ff = average_flow_factors(Topography(ridges, DX), Topography(np.zeros_like(ridges), DX),
                              2.3e11)
    assert ff.meta["gamma"] == 9.0
    assert any("only a bound (lower" in n for n in ff.meta["notes"])
    assert any("tables' edge 9" in n for n in ff.meta["notes"])


def test_summits_match_the_counted_ones():
    """McCool's summit density, mean height and spread against the local maxima (8
    neighbours) of a resolved isotropic Gaussian surface (10 px correlation, 512^2, about
    480 summits: a 5 % statistical tolerance)."""
    z = gaussian_surface(512, (10, 10))
    s = Summits.from_moments(*roughness_statistics(Topography(z, DX)).moments)
    around = [np.roll(z, (i, j), (0, 1)) for i in (-1, 0, 1) for j in (-1, 0, 1) if i or j]
    peaks = np.all([z > b for b in around], axis=0)
    assert s.density * (512 * DX) ** 2 == pytest.approx(peaks.sum(), rel=0.05)
    assert s.mean == pytest.approx(z[peaks].mean(), rel=0.05)
    assert s.spread == pytest.approx(z[peaks].std(), rel=0.05)


def test_tail_moments_against_closed_forms():
    """F_0, F_1, F_2 of the normal density in erfc form (to 1e-10), F_3/2 and F_5/2 against
    quadrature, and the exponential density's Gamma(n+1) exp(-H) above 0."""
    H = np.linspace(-3, 6, 19)
    f0 = special.erfc(H / np.sqrt(2)) / 2
    phi = np.exp(-H ** 2 / 2) / np.sqrt(2 * np.pi)
    assert np.allclose(tail_moment(H, 0), f0, rtol=1e-10, atol=1e-300)
    assert np.allclose(tail_moment(H, 1), phi - H * f0, rtol=1e-10)
    assert np.allclose(tail_moment(H, 2), (1 + H ** 2) * f0 - H * phi, rtol=1e-9)
    for n in (1.5, 2.5):
        exact = [quad(lambda x: (x - h) ** n * np.exp(-x ** 2 / 2) / np.sqrt(2 * np.pi), h,
                      np.inf, epsrel=1e-12)[0] for h in H]
        assert np.allclose(tail_moment(H, n), exact, rtol=1e-9)
    Hp = np.linspace(0, 5, 11)
    assert np.allclose(tail_moment(Hp, 2.5, "exponential"), special.gamma(3.5) * np.exp(-Hp))
    below = quad(lambda x: (x + 1) ** 2.5 * np.exp(-x), 0, np.inf)[0]
    assert tail_moment(-1.0, 2.5, "exponential") == pytest.approx(below, rel=1e-10)


def test_tail_moments_deep_in_contact():
    """Far below the mean summit (H < -10), where the parabolic cylinder function overflows
    (F_5/2 was NaN, so a pad's contact fraction at a deep separation was NaN): the expansion
    in 1/H^2 against quadrature to 1e-6, and the contact fraction capped at 1."""
    for n in (1.5, 2.0, 2.5):
        for h in (-10.5, -14.0, -40.0):
            exact = quad(lambda x: max(x - h, 0.0) ** n * np.exp(-x ** 2 / 2) / np.sqrt(2 * np.pi),
                         -40.0, 40.0, points=[0.0], epsrel=1e-13, limit=200)[0]
            assert tail_moment(h, n) == pytest.approx(exact, rel=1e-6)
    summits = Summits.from_moments(1e-14, 1e-3, 1e8)
    assert contact_fraction(-1e-5, summits) == 1.0
    assert np.isfinite(contact_pressure(-1e-5, summits, 231e9))


def test_greenwood_tripp_against_greenwood_williamson():
    """With exponential summit heights, a summit pair's mean real pressure P/A is
    Greenwood and Williamson's closed form for summits of the pair's radius beta/2,
    ``E* sqrt(2 s / beta) / sqrt(pi)`` (E* = E'/2) at every separation: the constants
    8 sqrt(2) pi / 15 and pi^2 and the powers 5/2 and 2 together."""
    s = Summits(density=5e10, radius=5e-6, spread=1e-7, mean=0.0)
    h = np.linspace(0, 4e-7, 9)
    p = contact_pressure(h, s, 2.3e11, "exponential")
    a = contact_fraction(h, s, "exponential")
    gw = 2.3e11 / 2 * np.sqrt(2 * s.spread / s.radius) / np.sqrt(np.pi)
    assert np.allclose(p / a, gw, rtol=1e-12)


def test_couette_stress_against_its_definition():
    """phi_f = h <1/h_T> for the polynomial heights: to 1e-9 above H = 3; below, with
    films cut at 3 sigma epsilon*, within 0.5 % (the closed form drops O(epsilon*)
    terms); 1 + 1/H^2 at large H."""
    c = 3.0

    def exact(H):
        lo = max(-c, -H + c * pc.FILM_CUTOFF)
        return H * quad(lambda d: 35 / (32 * c) * (1 - d * d / c / c) ** 3 / (H + d), lo, c,
                        epsabs=1e-13, epsrel=1e-12, limit=200)[0]
    for H, tol in ((0.5, 5e-3), (1.0, 5e-3), (2.0, 5e-3), (3.5, 1e-9), (10.0, 1e-9),
                   (29.0, 1e-9), (40.0, 1e-8)):
        assert pc.couette_stress(np.array(H)) == pytest.approx(exact(H), rel=tol)


def test_fits_limits_and_symmetry():
    """phi_x, phi_y, phi_fp -> 1 and Phi_s, Phi_fs -> 0 as H -> infinity; phi_y(gamma) =
    phi_x(1/gamma), equal at gamma = 1; phi_x below 1 at the tabulated gamma < 1, above
    at those > 1, and rising with gamma at every H, between the tables too (longitudinal
    ridges pass the flow)."""
    big = np.array([1e4])
    for g in pc.GAMMAS:
        assert pc.pressure_flow(big, g) == pytest.approx(1, abs=1e-5)
        assert pc.pressure_stress(big, g) == pytest.approx(1, abs=1e-9)
        assert pc.shear_flow(big, g) == pytest.approx(0, abs=1e-9)
        assert pc.shear_stress(big, g) == 0
    H = np.linspace(1.0, 6.0, 11)
    assert np.allclose(pc.pressure_flow_across(H, 1 / 3), pc.pressure_flow(H, 3.0))
    assert np.allclose(pc.pressure_flow(H, 1.0), pc.pressure_flow_across(H, 1.0))
    gammas = np.geomspace(1 / 9, 9, 41)
    phi = np.array([pc.pressure_flow(H, g) for g in gammas])
    assert np.all(np.diff(phi, axis=0) > 0)
    table = np.array([pc.pressure_flow(H, g) for g in pc.GAMMAS])
    assert np.all(table[pc.GAMMAS < 1] < 1) and np.all(table[pc.GAMMAS > 1] > 1)


def test_fits_refuse_to_extrapolate():
    """Below a fit's H range or outside gamma in [1/9, 9]: a clear error; hold=True holds
    the end value."""
    with pytest.raises(InputError, match="below the fit's range"):
        pc.pressure_flow(np.array([0.8]), 1 / 9)
    with pytest.raises(InputError, match="outside Patir and Cheng's tables"):
        pc.shear_flow(np.array([1.0]), 12.0)
    with pytest.raises(InputError, match="outside Patir and Cheng's tables"):
        pc.pressure_flow_across(np.array([1.0]), 0.0)
    held = pc.pressure_flow(np.array([0.2]), 1.0, hold=True)
    assert held == pytest.approx(pc.pressure_flow(np.array([0.5]), 1.0))


def test_mean_gap_against_quadrature():
    """h_T = E[max(h + delta, 0)] for Gaussian delta, and h_T -> h far apart."""
    for h in (-1e-7, 0.0, 5e-8, 3e-7):
        exact = quad(lambda d: max(h + d, 0) * np.exp(-d * d / 2e-14) / np.sqrt(2e-14 * np.pi),
                     -1e-6, 1e-6, points=[-h], epsabs=1e-20)[0]
        assert mean_gap(h, 1e-7) == pytest.approx(exact, rel=1e-8)
    assert mean_gap(1e-6, 1e-7) == pytest.approx(1e-6, rel=1e-12)
    with pytest.raises(InputError, match="sigma"):
        mean_gap(1e-7, 0.0)


def test_average_flow_factors_of_a_pair():
    """The peer's FlowFactors: smooth limit far apart (A = I, b = e1, s_C = 1 within the
    fits' tails), the shear flow term's sign (a rough moving disk over a smooth pin
    carries extra flow, b1 > 1; the rough pin alone, b1 < 1), the contact from
    Greenwood-Tripp, the hold recorded."""
    rough = gaussian_surface(128, (6, 6))
    flat = np.zeros_like(rough)
    e = 2.3e11
    disk_rough = average_flow_factors(Topography(flat, DX), Topography(rough, DX), e)
    pin_rough = average_flow_factors(Topography(rough, DX), Topography(flat, DX), e)
    far = disk_rough.at(np.array([5e-6]))
    assert far.A[0] == pytest.approx(np.eye(2), abs=1e-4)
    assert far.b[0] == pytest.approx([1, 0], abs=1e-4)
    assert far.friction_factor[0] == pytest.approx(1, abs=1e-3)
    near = np.array([2e-7])
    assert disk_rough.at(near).b[0, 0] > 1 > pin_rough.at(near).b[0, 0]
    assert np.all(pin_rough.friction_factor > 0)     # the held phi_fs stays below phi_f
    stats = PairStatistics.from_cells(Topography(flat, DX), Topography(rough, DX))
    assert stats.shares == (0.0, 1.0) and stats.gammas[0] is None
    p = contact_pressure(disk_rough.h0, stats.summits, e)
    assert np.allclose(disk_rough.p_con, np.where(p < 1e-12 * p.max(), 0.0, p))
    held = disk_rough.meta["held_below_m"]
    assert held >= 0.5 * stats.sigma
    h = disk_rough.h0[disk_rough.h0 < held]
    phi_x = disk_rough.A[: h.size, 0, 0] * (mean_gap(h, stats.sigma) / h) ** 3
    assert np.allclose(phi_x, phi_x[-1], rtol=1e-12)


def test_knee_speed_reads_the_half_load_crossing():
    """knee_speed: where contact_load_fraction crosses 0.5, linear in log speed (a share
    falling as log speed rises crosses at the exact speed); NaN without a crossing (a share
    outside (0, 1) is refused: tests/test_errors.py)."""
    from fem_twin.stribeck.analysis import knee_speed
    from fem_twin.stribeck.curve import StribeckCurve
    speed = np.geomspace(2.0, 0.01, 12)
    share = np.clip(0.5 - 0.3 * np.log(speed / 0.2), 0, 1)
    n = speed.size
    curve = StribeckCurve(speed=speed, hersey=speed, friction_coefficient=np.ones(n),
                          viscosity=0.066, hydrodynamic_friction=np.ones(n),
                          boundary_force=np.ones(n), contact_load_fraction=share,
                          h_d=np.ones(n), iterations=np.ones(n))
    assert knee_speed(curve) == pytest.approx(0.2, rel=1e-12)
    flat = StribeckCurve(**{**curve.__dict__, "contact_load_fraction": np.full(n, 0.2)})
    assert np.isnan(knee_speed(flat))


def test_a_screening_point_has_no_error_bar(factors):
    """The peer's factors are flagged (FlowFactors.screening, kept by average), and a
    point solved with them carries no discretisation estimate: NaN with the reason, no
    extra solves."""
    from sample_cases import macro_case

    from fem_twin.macro import Lubricant, MacroSettings
    from fem_twin.macro.estimate import SCREENING, friction_error
    from fem_twin.macro.point import OperatingPoint
    from fem_twin.micro import average
    rough = gaussian_surface(64, (5, 5))
    peer = average_flow_factors(Topography(rough, DX), Topography(np.zeros_like(rough), DX),
                                2.3e11)
    assert peer.screening and average([peer, peer]).screening and not factors.screening
    gap, dx, face = macro_case(32)
    point = OperatingPoint(gap=gap, spacing=dx, factors=peer, load=150.0, speed=1.0,
                           lubricant=Lubricant(0.066), settings=MacroSettings(), face=face)
    err = friction_error(None, point)
    assert np.isnan(err["total"]) and err["failed"] == [SCREENING]


def screening_case(tmp_path):
    """The small case with ``[micro] model = "average-flow"`` and none of the cell
    problems' keys (its [micro] holds the model and the resolution only)."""
    import re

    from sample_cases import small_case
    path = small_case(tmp_path)
    text = path.read_text()
    start = text.index("[micro]")
    end = text.index("\n[", start)
    micro = "\n".join(line for line in text[start:end].splitlines()
                      if re.match(r"(\[micro\]|resolution)", line))
    path.write_text(text[:start] + micro + '\nmodel = "average-flow"\n' + text[end:])
    return path


def test_the_case_key_and_its_choices(tmp_path):
    """[micro] model: "cells" by default, "average-flow" read, anything else refused with
    the choices named; the cell problems' keys, unused by the statistical model, are
    refused with it (probe S-AVGFLOW-steps)."""
    from sample_cases import small_case

    from fem_twin.case import CaseError, load_case
    assert load_case(small_case(tmp_path)).micro.model == "cells"
    path = screening_case(tmp_path)
    text = path.read_text()
    assert load_case(path).micro.model == "average-flow"
    path.write_text(text.replace('"average-flow"', '"patir-cheng"'))
    with pytest.raises(CaseError, match="average-flow"):
        load_case(path)
    for key in ("steps = 64", "h0_tol = 0.02", "boundary_film = 1e-8"):
        path.write_text(text.replace("[micro]", f"[micro]\n{key}"))
        with pytest.raises(CaseError, match=f"{key.split()[0]}: the cell problems"):
            load_case(path)


@pytest.mark.integration
def test_a_screening_run(tmp_path):
    """fem-twin run with [micro] model = "average-flow": no cell problems, the summary and
    the banner name the model, every C_f has no error bar (cf_err NaN), and the curves
    rise from full film to the boundary level."""
    import csv
    import json

    from fem_twin.cli import main
    path = screening_case(tmp_path)
    out = tmp_path / "out"
    assert main(["run", str(path), "-o", str(out), "--no-progress"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stages"]["micro"]["model"] == "average-flow"
    assert not any((out / "micro").rglob("checkpoints"))
    rows = list(csv.DictReader(open(out / "stribeck.csv")))
    assert all(np.isnan(float(r["cf_err"])) for r in rows)
    cf = [float(r["friction_coefficient"]) for r in rows if float(r["viscosity_Pa_s"]) == 0.066]
    assert cf[-1] > 5 * min(cf)
