"""The bundled sample twin: Table 5 roughness, structure, and reproducible regeneration."""

import numpy as np
import pytest
from conftest import SAMPLE

from fem_twin import read_topography
from fem_twin import topography as tp
from fem_twin.io import samples
from fem_twin.topography.prepare import prepare_pin


@pytest.mark.parametrize("k", range(6))
def test_patches_match_table5_sq(k):
    low = read_topography(SAMPLE / f"patch_{k + 1}_pin.npz")
    up = read_topography(SAMPLE / f"patch_{k + 1}_disk.npz")
    assert low.shape == up.shape == (576, 768)
    assert np.allclose(low.size, (84.9e-6, 63.7e-6), rtol=1e-12)
    sq_low, sq_up = tp.level(low).rms_height(), tp.level(up).rms_height()
    # Table 5 prints 3-4 significant digits: 1 % is the bar
    assert abs(sq_low / samples.TABLE5_SQ_LOW[k] - 1) < 0.01
    assert abs(sq_up / samples.TABLE5_SQ_UP[k] - 1) < 0.01
    table_sq = (94.1e-9, 144.0e-9, 177.5e-9, 157.0e-9, 136.4e-9, 165.0e-9)[k]
    assert abs(np.hypot(sq_low, sq_up) / table_sq - 1) < 0.01


@pytest.mark.parametrize("k", [1, 2, 3])
def test_pins_and_disks_are_like_the_measurements(k):
    pin = read_topography(SAMPLE / f"pin_{k}.npz")
    disk = read_topography(SAMPLE / f"disk_{k}.npz")
    assert pin.shape == disk.shape == (500, 500)
    assert np.allclose(pin.size, (8e-3, 8e-3))
    assert pin.mask is not None and 0 < (~pin.mask).sum() < 0.1 * pin.heights.size
    mounted = prepare_pin(pin)
    face = tp.pin_face(mounted)
    # an 8 mm face fills pi/4 of the 8 x 8 mm map; crown plus roll-off of a few um
    assert abs(face.mean() - np.pi / 4) < 0.05
    inner = tp.radial_mask(mounted, 3.5e-3)        # inside the filtered rim
    assert face[inner].all() and 1e-6 < np.ptp(mounted.heights[inner]) < 15e-6
    # disk waviness below 1 um: the long-wave part of the levelled disk
    wavy = tp.gaussian_filter(tp.level(tp.fill_defects(disk)), 31)
    assert np.ptp(wavy.heights[20:-20, 20:-20]) < 1e-6


def test_regeneration_is_identical(tmp_path):
    written = samples.generate(tmp_path)
    assert sorted(p.name for p in written) == sorted(samples.sample_files())
    for path in written:
        shipped = SAMPLE / path.name
        with np.load(path) as new, np.load(shipped) as old:
            assert sorted(new.files) == sorted(old.files)
            for key in new.files:
                assert np.array_equal(new[key], old[key]), f"{path.name}: {key} differs"
        assert path.read_bytes() == shipped.read_bytes(), f"{path.name}: bytes differ"
