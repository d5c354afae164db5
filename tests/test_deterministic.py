"""The deterministic mixed-lubrication solver (fem_twin.macro.reference.deterministic) against the
references the twin passes: the plane slider (smooth limit), Hertz and rigid-plastic
contact (dry limit), the resolved ridged slider (full film); and the twin beside it on a
rough pad (fem_twin.studies.verification)."""

import pickle
import sys
from pathlib import Path

import numpy as np
import pytest

from fem_twin.contact import solve as contact_solve
from fem_twin.contact.elastic import elastic_operator
from fem_twin.errors import InputError
from fem_twin.macro import FilmFields, Lubricant, MacroSettings, solve_mixed, solve_reynolds
from fem_twin.macro.reference.deterministic import (
    DeterministicNotConverged,
    DeterministicSettings,
    solve_deterministic,
)
from fem_twin.macro.reference.film_friction import pad_friction
from fem_twin.micro import FlowFactors

sys.path.insert(0, str(Path(__file__).parent))
from test_friction import MU, RATIO, SLIDER, U, resolved_slider, strip

OIL = Lubricant(MU, roelands_alpha=0.0, dh_c2=1.0)
#: rigid: the film does not deform the surfaces, E' of the contact at its plausible maximum
RIGID = DeterministicSettings(e_reduced=4e12, film_deforms=False, tol=1e-9)


def slider(nodes, h_o=1e-6):
    """The plane slider strip (outlet ``h_o``, inlet ``RATIO h_o``) as a shape at zero
    separation, its spacing and the load of the smooth Reynolds solution at ``h_o``."""
    x = np.linspace(0, SLIDER, nodes)
    wedge, dx = strip(h_o * (RATIO - 1) * (1 - x / SLIDER))
    load = solve_reynolds(wedge + h_o, dx, U, MU, tol=1e-12).load
    return wedge, dx, load


def runner_per_width(res, dx):
    """The film's force on the pin per width along the strip's centre row [N/m]."""
    c = res.pressure.shape[0] // 2
    h, p, theta = res.gap[c], res.pressure[c], res.cavity_fraction[c]
    tau = MU * U / h * (1 - theta) + h / 2 * np.gradient(p, dx[0])
    return np.trapezoid(tau, dx=dx[0])


def test_the_smooth_pad_is_the_plane_slider():
    """Smooth limit: on the plane slider the deterministic solver finds the outlet film
    that carries the smooth Reynolds load (to 1e-6, the same discretisation), the runner's
    friction per width of the infinite slider (closed form: -8.4e-5, -2.1e-5, -5.3e-6 at 41,
    81, 161 nodes, second order), and the twin's friction on the
    same gap with smooth flow factors (within 0.1 %: the two friction forms are equal by
    parts)."""
    scale = MU * U * SLIDER / (1e-6 * (RATIO - 1))
    closed = scale * (4 * np.log(RATIO) - 6 * (RATIO - 1) / (RATIO + 1))
    errors = []
    for nodes in (41, 81, 161):
        shape, dx, load = slider(nodes)
        res = solve_deterministic(shape, dx, load=load, speed=U, lubricant=OIL,
                                  settings=RIGID)
        assert res.separation == pytest.approx(1e-6, rel=1e-6)
        assert res.contact_load == 0 and res.load_share == 0
        errors.append(runner_per_width(res, dx) / closed - 1)
    assert abs(errors[-1]) < 1e-5
    assert np.log2(errors[1] / errors[2]) > 1.9                  # measured 2.00
    twin = solve_mixed(shape + 1e-6, dx, FlowFactors.smooth(), load=load, speed=U,
                       lubricant=OIL, settings=MacroSettings(e_reduced=4e12, tol=1e-9,
                                                             ambient_pressure=0.0,
                                                             cavitation_pressure=0.0))
    assert res.film_friction == pytest.approx(twin.hydrodynamic_friction, rel=1e-3)


def test_the_dry_limit_is_hertz():
    """Dry limit: a sphere of R = 10 mm under 150 N on steel (E' 230.8 GPa) at 1 mm/s
    carries its load on the contact alone (film share below 1e-3), with Hertz's central
    pressure p0 = 1.569 GPa and approach delta = 4.564 um (docs/references.md) within 2 %
    on 81^2 nodes over 1 mm (a = 213.6 um is 17 nodes)."""
    x = np.linspace(-0.5e-3, 0.5e-3, 81)
    shape = (x[None, :] ** 2 + x[:, None] ** 2) / (2 * 10e-3)
    dx = (x[1] - x[0],) * 2
    steel = DeterministicSettings(e_reduced=2 * 115.38e9, hardness=1e11)
    res = solve_deterministic(shape, dx, load=150.0, speed=1e-3, lubricant=OIL,
                              settings=steel)
    assert res.load_share > 0.999
    assert res.contact_pressure.max() == pytest.approx(1.569e9, rel=0.02)
    assert -res.separation == pytest.approx(4.564e-6, rel=0.02)


def rough_pad(tiles=2, cell=16, crown=0.0, seed=3):
    """A pad of a random periodic roughness cell (Sq about 0.1 um) tiled ``tiles`` a side."""
    from fem_twin.topography.synthetic import self_affine
    dx = 1e-6
    r = self_affine((cell, cell), dx, 0.8, 0.1e-6, rng=seed).heights
    tiled = np.pad(np.tile(r, (tiles, tiles)), ((0, 1), (0, 1)), mode="wrap")
    xi = np.linspace(-1, 1, tiled.shape[0])
    return r, tiled + crown * (xi[None, :] ** 2 + xi[:, None] ** 2), (dx, dx)


def test_the_dry_limit_is_the_periodic_contact():
    """Dry limit on a flat rough pad of 4 x 4 cells on steel at a crawl (1 um/s): the
    asperities carry the load (film share below 1e-3), and a central cell carries what the
    periodic contact of one cell carries at imposed separation (the twin's cell problem),
    the separation being the pad's plus the cell's mean deformation under the whole pad's
    pressure (18.5 nm: the twin's macro h_el): within 0.5 % (measured 0.12 %)."""
    r, shape, dx = rough_pad(tiles=4, cell=32)
    steel = DeterministicSettings(e_reduced=2.3e11, hardness=1e9)
    res = solve_deterministic(shape, dx, load=15e6 * (128e-6) ** 2, speed=1e-6,
                              lubricant=OIL, settings=steel)
    w = elastic_operator(shape.shape, dx, 2.3e11)(res.contact_pressure + res.pressure)
    central = np.s_[64:96, 64:96]
    cell = contact_solve(r, dx, 2.3e11, separation=res.separation + w[central].mean(),
                         hardness=1e9, periodic=True)
    assert res.load_share > 0.999
    assert res.contact_pressure[central].sum() * dx[0] * dx[1] == pytest.approx(cell.load,
                                                                                rel=5e-3)


@pytest.mark.parametrize("h_o", [1e-6, 0.45e-6])
def test_the_full_film_is_the_resolved_ridged_slider(h_o):
    """Full film, no contact: the ridged slider of tests/test_friction.py (10 ridges of
    0.3 um on the pin) at its resolved load: the same separation (1e-6) and the same
    friction on the pin (1e-3: the pin's slope form against the form by parts)."""
    pin, _, load = resolved_slider(h_o, 10, 0.3e-6)
    x = np.linspace(0, SLIDER, 161)
    gap, dx = strip(h_o * (RATIO - 1) * (1 - x / SLIDER) - 0.3e-6 * np.cos(
        2 * np.pi * x * 10 / SLIDER))
    res = solve_deterministic(gap, dx, load=load, speed=U, lubricant=OIL, settings=RIGID)
    assert res.separation == pytest.approx(h_o, rel=1e-6)
    assert res.film_friction == pytest.approx(pin, rel=1e-3)


def test_pad_friction_cuts_the_boundary_films():
    """Films at or below the cut-off carry no wall shear: a uniform 5 nm film at rest
    pressure has none with a 10 nm cut-off and ``mu U / h`` per area with a 1 nm one."""
    h = np.full((5, 5), 5e-9)
    zero = np.zeros_like(h)
    film = FilmFields(zero, h, zero, MU)
    assert pad_friction(film, (1e-6, 1e-6), U, 10e-9) == 0
    assert pad_friction(film, (1e-6, 1e-6), U, 1e-9) == pytest.approx(
        MU * U / 5e-9 * 16e-12)


def test_bad_inputs_and_no_convergence_are_clear():
    """NaN shapes and wrong settings are refused before any work; a load balance that
    cannot finish in its evaluations raises with its residuals, intact across pickling."""
    _, shape, dx = rough_pad()
    bad = shape.copy()
    bad[3, 3] = np.nan
    with pytest.raises(InputError):
        solve_deterministic(bad, dx, load=1e-3, speed=1.0, lubricant=OIL, settings=RIGID)
    with pytest.raises(InputError):
        DeterministicSettings(boundary_film=1e-10)
    with pytest.raises(InputError, match="height range"):          # um typed as m
        solve_deterministic(shape * 1e6, dx, load=1e-3, speed=1.0, lubricant=OIL,
                            settings=RIGID)
    with pytest.raises(DeterministicNotConverged) as err:
        solve_deterministic(shape, dx, load=1e-3, speed=1.0, lubricant=OIL,
                            settings=DeterministicSettings(max_iter=2))
    again = pickle.loads(pickle.dumps(err.value))
    assert isinstance(again, DeterministicNotConverged) and again.history


def test_the_verification_pads_refuse_what_they_cannot_pose():
    """Issue 87 item 7: a pad in micrometres, fractional or zero tile counts, no oil, and
    a summary of no points are refused with the argument named, not as bare errors."""
    from fem_twin.studies import verification as V
    cell = np.random.default_rng(0).normal(0, 50e-9, (8, 8))
    pad = V.RoughPad(cell, 1e-6, OIL)
    for make, words in ((lambda: V.RoughPad(cell * 1e6, 1e-6, OIL), "roughness"),
                        (lambda: V.RoughPad(cell, 1e-6, None), "Lubricant"),
                        (lambda: V.RoughPad(cell, 1e-6, OIL, macro_nodes=64.5), "macro_nodes"),
                        (lambda: V.pad_speeds([1.0], 0), "tiles"),
                        (lambda: V.pad_speeds([1.0], 2.5), "tiles: expected a whole"),
                        (lambda: V.pad_speeds("fast", 2), "speeds"),
                        (lambda: pad.resolved(1.5), "tiles"),
                        (lambda: V.summary([], 0.19), "non-empty list of Pair"),
                        (lambda: V.to_zero([], []), "at least one")):
        with pytest.raises(InputError, match=words):
            make()
    assert V.to_zero([0.25], [0.01]) == (0.01, None)      # one point: itself, no order


@pytest.mark.integration
def test_the_twin_meets_the_deterministic_pad():
    """The mixed regime: sample patch pair 1 at 16 px tiled 8 x 8 on the crowned pad of
    fem_twin.studies.verification (1 MPa, 0.075 m/s, the bundled oil at 24 C): the deterministic
    solution carries 70 % of the load on asperities, and the twin with that cell's flow
    factors agrees within 0.02 in load share, 5 nm in separation and 2 % in film friction
    (measured 0.012, 3.0 nm, 0.45 %); at 2 cells a side (0.3 m/s), where the crown rises
    1 um across a cell, the twin misses the share by 0.06 and the separation by 49 nm:
    scale separation."""
    from fem_twin.studies import verification as V
    pad = V.sample_pad(Path(__file__).parents[1] / "meshes" / "sample", 16)
    factors = V.pad_factors(pad, np.geomspace(3e-8, 3e-6, 60))
    gaps = {}
    for tiles in (2, 8):
        p, = V.compared(V.deterministic_sweep(pad, tiles, [0.3]),
                        V.twin_sweep(pad, tiles, [0.3], factors), tiles)
        gaps[tiles] = (abs(p.share - p.share_det), abs(p.separation - p.separation_det),
                       abs(p.film / p.film_det - 1), p.share_det)
    share, separation, film, reached = gaps[8]
    assert reached > 0.6 and share < 0.02 and separation < 5e-9 and film < 0.02
    assert gaps[2][0] > 3 * share and gaps[2][1] > 3 * separation


@pytest.mark.parametrize("order", [1.0, 2.0])
def test_the_extrapolation_to_scale_separation_is_exact_on_a_power_law(order):
    """``to_zero`` recovers ``a`` and ``p`` of ``a + b eps^p`` from eps = 1/2 .. 1/16."""
    from fem_twin.studies.verification import to_zero
    eps = [1 / 2, 1 / 4, 1 / 8, 1 / 16]
    limit, p = to_zero(eps, [0.3 + 0.05 * e ** order for e in eps])
    assert limit == pytest.approx(0.3, abs=1e-12) and p == pytest.approx(order)


def test_no_order_is_assumed_where_the_gaps_do_not_shrink_monotonically():
    """A gap that changes sign between the pads (round 5's -3.50 -> +2.07 -> +1.04 % C_f,b
    at eps = 1/4, 1/8, 1/16) shows no order: ``to_zero`` returns the finest value and
    None, and the summary says so."""
    from fem_twin.studies.verification import order_text, to_zero
    limit, p = to_zero([1 / 4, 1 / 8, 1 / 16], [-3.50, 2.07, 1.04])
    assert limit == 1.04 and p is None
    assert to_zero([1 / 8, 1 / 16], [2.0, 1.0]) == (1.0, None)
    assert order_text(None) == "order none observed" and order_text(1.5) == "order 1.50"


def test_the_benchmarks_summary_line():
    """``benchmarks/run.py deterministic`` ends in exactly this line (issue 70's bar), from
    the worst point of the finest pad."""
    from fem_twin.studies.verification import Pair, summary
    pairs = [Pair(16, 0.1, 0.223, 0.234, 2e-7, 2e-7, 1e-3, 1e-3, 0.0556, 0.0577),
             Pair(16, 0.01, 0.899, 0.900, 2e-7, 2e-7, 1e-3, 1e-3, 0.1744, 0.1747)]
    assert summary(pairs, 0.19245) == ("mixed regime: worst |C_f - C_f,det| = 1.09 % C_f,b, "
                                       "worst |share - share,det| = 0.011, at 90 % asperity load")
    assert summary(pairs, 0.19245, "both rough, unsteady", None).endswith(
        "at 90 % asperity load, eps -> 0 order none observed")
    assert summary(pairs, 0.19245, "both rough, unsteady", 1.234).startswith(
        "both rough, unsteady: worst |C_f - C_f,det| = 1.09 % C_f,b")
