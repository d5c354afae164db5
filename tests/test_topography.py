"""Pre-processing functions against exact expectations (paper 2.2.1)."""

import numpy as np
import pytest

import fem_twin
from fem_twin import topography as tp
from fem_twin.topography import Topography


def harmonic(x, y):
    """A cubic harmonic polynomial: the 5-point Laplacian of it is exactly zero."""
    return x ** 3 - 3 * x * y ** 2 + 2 * x * y + 0.5 * x - y


# -- the value -------------------------------------------------------------------------
def test_topography_entry_point_and_conventions():
    t = fem_twin.Topography(np.zeros((3, 5)), (2e-6, 1e-6))
    assert t.shape == (3, 5) and t.spacing == (2e-6, 1e-6)
    assert np.allclose(t.x1, [0, 2e-6, 4e-6, 6e-6, 8e-6]) and np.allclose(t.x2, [0, 1e-6, 2e-6])
    with pytest.raises(ValueError, match="read-only"):
        t.heights[0, 0] = 1.0


@pytest.mark.parametrize("spacing", [0.0, -1e-6, (1e-6, 0.0), np.nan])
def test_non_positive_spacing_raises(spacing):
    with pytest.raises(ValueError, match="spacing must be positive"):
        Topography(np.zeros((4, 4)), spacing)


def test_bad_shapes_and_values_raise():
    with pytest.raises(ValueError, match="2D"):
        Topography(np.zeros(5), 1e-6)
    with pytest.raises(ValueError, match="mask shape"):
        Topography(np.zeros((4, 4)), 1e-6, mask=np.ones((4, 5), bool))
    with pytest.raises(ValueError, match="no valid pixel"):
        Topography(np.full((4, 4), np.nan), 1e-6)
    with pytest.raises(ValueError, match="metres"):        # heights given in um
        Topography(np.array([[0.0, 150.0], [3.0, 1.0]]), 1e-6)
    with pytest.raises(ValueError, match="metres"):        # spacing given in um
        Topography(np.zeros((4, 4)), 16.0)


def test_nan_pixels_become_invalid():
    h = np.zeros((4, 4))
    h[1, 2] = np.nan
    t = Topography(h, 1e-6)
    assert t.mask is not None and not t.mask[1, 2] and t.mask.sum() == 15


# -- defect filling --------------------------------------------------------------------
def test_laplace_fill_reproduces_harmonic_function_in_holes():
    rng = np.random.default_rng(0)
    ny, nx, dx1, dx2 = 60, 80, 1.0e-6, 0.7e-6
    x1, x2 = np.meshgrid(np.arange(nx) * dx1, np.arange(ny) * dx2)
    z = 1e-6 * harmonic(x1 / 40e-6, x2 / 40e-6)
    holes = rng.random((ny, nx)) < 0.1
    holes[20:31, 30:45] = True                     # one large hole
    holes[[0, -1], :] = False                      # keep the frame valid: Dirichlet data
    holes[:, [0, -1]] = False
    filled = tp.fill_defects(Topography(np.where(holes, np.nan, z), (dx1, dx2)))
    assert filled.mask is None
    # the 5-point stencil is exact for cubic harmonics: error is round-off of the solve
    assert np.max(np.abs(filled.heights - z)) < 1e-12 * np.max(np.abs(z))


def test_laplace_fill_at_the_edge_gives_finite_bounded_values():
    z = np.random.default_rng(1).normal(size=(20, 20)) * 1e-7
    z[:3, :4] = np.nan                             # a hole in the corner (Neumann edge)
    filled = tp.fill_defects(Topography(z, 1e-6))
    valid = np.isfinite(z)
    assert np.all(np.isfinite(filled.heights))
    # maximum principle: harmonic values lie within the range of their boundary data
    assert z[valid].min() <= filled.heights.min() and filled.heights.max() <= z[valid].max()


# -- levelling -------------------------------------------------------------------------
def test_level_removes_exact_tilted_plane():
    rng = np.random.default_rng(2)
    t = Topography(np.zeros((40, 50)), (2e-6, 3e-6), origin=(-1e-5, 4e-5))
    x1, x2 = t.coordinates()
    plane = 3e-6 + 0.01 * x1 - 0.02 * x2
    out = tp.level(t.with_heights(plane))
    assert np.max(np.abs(out.heights)) < 1e-18
    # with a mask: garbage outside the mask (the pin holder) must not affect the fit
    mask = rng.random(t.shape) < 0.6
    z = np.where(mask, plane, -50e-6 + 1e-6 * rng.random(t.shape))
    out = tp.level(t.with_heights(z), mask=mask)
    assert np.max(np.abs(out.heights[mask])) < 1e-18
    assert np.allclose(out.heights[~mask], z[~mask] - plane[~mask], atol=1e-18)


def test_level_zeroes_mean_and_radial_mask():
    t = Topography(np.random.default_rng(3).normal(size=(101, 101)) * 1e-6, 1e-4,
                   origin=(-5e-3, -5e-3))
    mask = tp.radial_mask(t, 3e-3)
    # pixel count of a disk of radius 30 px: pi r^2 to within the perimeter
    assert abs(mask.sum() - np.pi * 30 ** 2) < 2 * np.pi * 30
    out = tp.level(t, mask)
    assert abs(out.heights[mask].mean()) < 1e-20


def test_level_rejects_degenerate_masks():
    t = Topography(np.zeros((5, 5)), 1e-6)
    mask = np.zeros((5, 5), bool)
    mask[2, :] = True                              # a single line: plane undefined
    with pytest.raises(ValueError, match="line"):
        tp.level(t, mask)
    with pytest.raises(ValueError, match="mask shape"):
        tp.level(t, np.ones((4, 4), bool))


# -- clipping and filtering ------------------------------------------------------------
def test_clip_limits_range():
    t = Topography(np.linspace(-40e-6, 40e-6, 100).reshape(10, 10), 1e-6)
    out = tp.clip_heights(t)
    assert out.heights.min() == -20e-6 and out.heights.max() == 20e-6


@pytest.mark.parametrize("fwhm", [3, 5, 7, 9, 11])
def test_gaussian_filter_fwhm_on_delta(fwhm):
    n = 101
    z = np.zeros((n, n))
    z[50, 50] = 1e-6
    out = tp.gaussian_filter(Topography(z, 1e-6), fwhm).heights
    profile = out[50] / out[50].max()
    x = np.arange(n) - 50.0
    # second moment of the response: sigma^2; FWHM = 2 sqrt(2 ln 2) sigma
    sigma = np.sqrt(np.sum(x ** 2 * profile) / np.sum(profile))
    assert abs(tp.FWHM_PER_SIGMA * sigma - fwhm) < 1e-6 * fwhm
    # half maximum found directly: log of the response is a parabola through the samples
    k = int(np.floor(fwhm / 2))
    c = np.polyfit(x[50 + k - 1:50 + k + 2], np.log(profile[50 + k - 1:50 + k + 2]), 2)
    half_width = (-c[1] - np.sqrt(c[1] ** 2 - 4 * c[0] * (c[2] - np.log(0.5)))) / (2 * c[0])
    assert abs(2 * abs(half_width) - fwhm) < 1e-6 * fwhm
    assert abs(out.sum() - 1e-6) < 1e-12          # mass conserved away from the edges


def test_gaussian_filter_zero_is_identity_and_masked_constant_stays_constant():
    mask = np.random.default_rng(4).random((30, 30)) > 0.2
    t = Topography(np.full((30, 30), 2e-6), 1e-6, mask=mask)
    assert tp.gaussian_filter(t, 0) is t
    out = tp.gaussian_filter(t, 7)
    assert np.array_equal(out.valid, t.valid)
    assert np.allclose(out.heights[out.valid], 2e-6, rtol=1e-12)
    with pytest.raises(ValueError):
        tp.gaussian_filter(t, -1)


# -- resampling ------------------------------------------------------------------------
@pytest.mark.parametrize("m,factor", [(999, 2), (1997, 4)])
def test_refinement_keeps_every_original_point(m, factor):
    z = np.random.default_rng(5).normal(size=(500, 500)) * 1e-6
    t = Topography(z, 16e-6)
    out = tp.resample(t, (m, m))
    assert out.shape == (m, m)
    assert np.array_equal(out.heights[::factor, ::factor], z)     # bit for bit
    assert np.isclose(out.spacing[0], 16e-6 / factor, rtol=1e-15)
    assert np.array_equal(tp.refine(t, factor).heights, out.heights)


def test_resample_linear_function_exact_and_cubic_keeps_nodes():
    t = Topography(np.zeros((50, 70)), (1e-5, 2e-5))
    x1, x2 = t.coordinates()
    lin = t.with_heights(1e-3 * x1 - 2e-3 * x2 + 1e-6)
    out = tp.resample(lin, (33, 41))
    X1, X2 = out.coordinates()
    assert np.allclose(out.heights, 1e-3 * X1 - 2e-3 * X2 + 1e-6, rtol=0, atol=1e-18)
    z = np.random.default_rng(6).normal(size=(50, 70)) * 1e-6
    cub = tp.resample(t.with_heights(z), (99, 139), "cubic")
    assert np.allclose(cub.heights[::2, ::2], z, rtol=0, atol=1e-12 * np.abs(z).max())
    with pytest.raises(ValueError, match="fill_defects"):
        tp.resample(Topography(np.where(z > 2e-6, np.nan, z), 1e-6), (10, 10))


def test_resample_cell_keeps_the_period_and_wraps_around():
    """Roughness cells are periodic: coarsening by 2 keeps every other pixel, refining by 2
    keeps every pixel and puts the mean of neighbours between them, including across the
    wrap from the last pixel to the first; the period n dx is unchanged.  A cosine of one
    period stays a cosine of one period (resample would stretch it by (n-1)/(m-1))."""
    z = np.random.default_rng(8).normal(size=(12, 20)) * 1e-7
    t = Topography(z, (1e-6, 2e-6))
    coarse = tp.resample_cell(t, (6, 10))
    assert np.array_equal(coarse.heights, z[::2, ::2])
    fine = tp.resample_cell(t, (24, 40))
    assert np.array_equal(fine.heights[::2, ::2], z)
    assert np.allclose(fine.heights[::2, 1::2], (z + np.roll(z, -1, axis=1)) / 2, rtol=1e-14)
    for out in (coarse, fine):
        assert np.allclose(np.array(out.shape[::-1]) * out.spacing, [20e-6, 24e-6], rtol=1e-14)
    cos = t.with_heights(1e-7 * np.cos(2 * np.pi * np.arange(20) / 20) * np.ones((12, 1)))
    c = tp.resample_cell(cos, (12, 10)).heights[0]
    assert np.allclose(c, 1e-7 * np.cos(2 * np.pi * np.arange(10) / 10), rtol=1e-12)


# -- placement ---------------------------------------------------------------------------
def test_extract_patch_takes_original_pixels():
    z = np.random.default_rng(7).normal(size=(576, 768)) * 1e-7
    t = Topography(z, 110.5e-9)
    p = tp.extract_patch(t, (256, 256), (100, 300))
    assert np.array_equal(p.heights, z[100:356, 300:556]) and p.spacing == t.spacing
    assert np.isclose(p.origin[0], 300 * 110.5e-9) and np.isclose(p.origin[1], 100 * 110.5e-9)
    with pytest.raises(ValueError, match="does not fit"):
        tp.extract_patch(t, (256, 256), (400, 0))


def test_flip_disk_is_rotation_about_x1():
    t = Topography(np.random.default_rng(8).normal(size=(6, 9)) * 1e-6, (1e-6, 2e-6),
                   origin=(-4e-6, -5e-6))
    f = tp.flip_disk(t)
    # the point (x1, x2, z) goes to (x1, -x2, -z)
    X1, X2 = t.coordinates()
    F1, F2 = f.coordinates()
    assert np.allclose(F1[::-1, :], X1) and np.allclose(F2[::-1, :], -X2)
    assert np.array_equal(f.heights[::-1, :], -t.heights)
    g = tp.flip_disk(f)                             # flipping twice is the identity
    assert np.array_equal(g.heights, t.heights) and np.allclose(g.origin, t.origin)


@pytest.mark.parametrize("direction", ["+x1", "+x2", "-x1", "-x2"])
def test_align_sliding_puts_direction_on_x1(direction):
    t = Topography(np.zeros((5, 7)), (1e-6, 2e-6))
    x1, x2 = t.coordinates()
    along = {"+x1": x1, "-x1": -x1, "+x2": x2, "-x2": -x2}[direction]
    out = tp.align_sliding(t.with_heights(1e-3 * along), direction)
    # heights increase by exactly one pitch-step along the new x1, are constant along x2
    d1 = np.diff(out.heights, axis=1)
    assert np.allclose(d1, 1e-3 * out.spacing[0]) and np.allclose(np.diff(out.heights, axis=0), 0)


def test_mount_pin_sets_holder():
    t = Topography(np.zeros((21, 21)), 1e-4, origin=(-1e-3, -1e-3))
    x1, x2 = t.coordinates()
    z = np.where(np.hypot(x1, x2) < 0.8e-3, 1e-6 * (1 - x1 ** 2 / 1e-6), -60e-6)
    out = tp.mount_pin(t.with_heights(z))
    face = np.hypot(x1, x2) < 0.8e-3
    assert np.array_equal(out.heights[face], z[face])
    assert np.all(out.heights[~face] == -1e-3)
    assert np.array_equal(tp.pin_face(out), face)


def synthetic_cap(n=301, size=1.2e-3, radius=9.525e-3, apex=(30e-6, -20e-6), astig=100e-9):
    """A 3/4" ball's top over 1.2 mm, its apex off the map's centre: its sphere and an
    astigmatic form error ``astig (x^2 - y^2) / (0.6 mm)^2`` about the map's centre (on the
    square map orthogonal to a sphere's and a plane's terms, so no fit absorbs it)."""
    x = np.linspace(-size / 2, size / 2, n)
    X, Y = np.meshgrid(x, x)
    r2 = (X - apex[0]) ** 2 + (Y - apex[1]) ** 2
    form = astig * (X ** 2 - Y ** 2) / (size / 2) ** 2
    sphere = np.sqrt(radius ** 2 - r2) - radius
    return Topography(sphere + form, (x[1] - x[0],) * 2, origin=(x[0], x[0])), form


def test_sphere_fit_of_a_ball_cap_recovers_radius_apex_and_form_error():
    """R within 1e-4 (a 3/4" ball: 1 um), the apex within 0.1 um, the form error within 2 %
    of its 100 nm amplitude; a flat or concave map is refused."""
    from fem_twin.errors import InputError
    from fem_twin.topography.sphere import cap_gap, fit_sphere
    cap, form = synthetic_cap()
    fit = fit_sphere(cap)
    assert fit.radius == pytest.approx(9.525e-3, rel=1e-4)
    assert np.allclose(fit.apex, (30e-6, -20e-6), atol=1e-7)
    err = fit.form_error.heights - fit.form_error.heights.mean() - (form - form.mean())
    assert np.sqrt(np.mean(err ** 2)) < 2e-9
    sphere, _ = synthetic_cap(astig=0.0)
    x = np.linspace(-200e-6, 200e-6, 41)
    gap = cap_gap(sphere, fit_sphere(sphere), x, x)
    X, Y = np.meshgrid(x, x)
    exact = 9.525e-3 - np.sqrt(9.525e-3 ** 2 - X ** 2 - Y ** 2)
    assert np.abs(gap - exact).max() < 1e-9            # bilinear: R'' dx^2 / 8 = 2.5e-11
    with pytest.raises(InputError, match="beyond the measured cap"):
        cap_gap(sphere, fit_sphere(sphere), 2 * x / x.max() * 1e-3, x)
    with pytest.raises(InputError, match="not convex"):
        fit_sphere(cap.with_heights(-cap.heights))
    # issue 64 item 5: a flat plate with a trace of curvature (R of 100 m) is named as such
    x1, x2 = np.meshgrid(cap.x1, cap.x2)
    plate = cap.with_heights(-(x1 ** 2 + x2 ** 2) / 200.0)
    with pytest.raises(InputError, match="nearly flat"):
        fit_sphere(plate)
