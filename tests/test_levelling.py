"""Pin levelling by torque balance (eqs 1-7) and set averaging."""

import numpy as np
import pytest
from conftest import SAMPLE

from fem_twin import Topography, read_topography
from fem_twin.contact.levelling import average_pins, level_pin, tilt_pin, torque_residuals
from fem_twin.topography.prepare import MacroOptions, prepare_pin


def _flat_pin(n=64):
    dx = 8e-3 / n
    x = (np.arange(n) - (n - 1) / 2) * dx
    X1, X2 = np.meshgrid(x, x)
    return Topography(np.where(np.hypot(X1, X2) < 4e-3, 0.0, -1e-3), dx, origin=(x[0], x[0]))


def test_tilted_flat_pin_levels_to_the_imposed_tilt():
    flat = _flat_pin()
    imposed = (2e-4, -1e-4)
    misaligned = tilt_pin(flat, (-imposed[0], -imposed[1]))
    res = level_pin(misaligned)
    assert np.max(np.abs(res.residuals)) < 1e-6               # paper's tolerance
    assert np.allclose(res.tilt, imposed, rtol=1e-9, atol=0)  # eq 7 undone exactly
    assert np.all(res.pin.heights[res.pin.heights < -1e-4] == -1e-3)   # holder untouched
    assert abs(res.contact.load / 50.0 - 1) < 1e-8


def test_pid_of_the_paper_and_broyden_reach_the_same_tilt():
    pin = prepare_pin(read_topography(SAMPLE / "pin_1.npz"), MacroOptions(resolution=(64, 64)))
    pin = tilt_pin(pin, (3e-5, -2e-5))
    fast = level_pin(pin)
    pid = level_pin(pin, method="pid", max_iter=300)
    for r in (fast, pid):
        assert np.max(np.abs(r.residuals)) < 1e-6
    # both stop at residuals < 1e-6; the tilts agree far better than the torque tolerance
    assert np.allclose(fast.tilt, pid.tilt, rtol=1e-3)
    assert len(fast.history) < len(pid.history)


def test_average_of_offset_copies_is_the_rezeroed_pin():
    pin = prepare_pin(read_topography(SAMPLE / "pin_2.npz"), MacroOptions(resolution=(64, 64)))
    face = pin.heights > -1e-3
    raised = pin.with_heights(np.where(face, pin.heights + 2e-6, -1e-3))
    avg = average_pins([pin, raised, pin])
    single = average_pins([pin])
    assert np.allclose(avg.heights, single.heights, rtol=0, atol=1e-15)
    assert np.all((avg.heights == -1e-3) | (avg.heights > -20e-6))


def test_torque_residuals_need_contact():
    x = np.zeros((3, 3))
    with pytest.raises(ValueError, match="no contact"):
        torque_residuals(x, x, x)


@pytest.mark.integration
def test_a_fine_pin_is_levelled_on_every_other_pixel(tmp_path):
    """fem_twin.stages.geometry.levelled_pin: a pin of more than LEVELLING_GRID pixels a
    side is levelled on every k-th pixel and tilted by the result.  Sample pin 1 on disk 1
    at 999 px (the measured 500 px points and one between each pair), levelled on every
    other pixel: the tilt within 1e-7 rad of the 500 px pin's own (measured 5e-9 and
    4.2e-8 rad, 0.2 nm over the 4 mm face radius; levelling all 999 px took 40 s against
    3.5 s, and moved the tilt by 1.4e-7 rad); the grid and the holder are the pin's own."""
    from fem_twin.case import load_case
    from fem_twin.stages import geometry
    from fem_twin.topography.prepare import prepare_disk
    case = load_case(SAMPLE.parent.parent / "examples" / "pin_on_disk.toml")
    pin_map = read_topography(SAMPLE / "pin_1.npz")
    disk_map = read_topography(SAMPLE / "disk_1.npz")

    def levelled(n):
        opts = MacroOptions(resolution=(n, n))
        pin = prepare_pin(pin_map, opts)
        return pin, geometry.levelled_pin(pin, prepare_disk(disk_map, opts), case)

    _, measured = levelled(500)
    pin, fine = levelled(999)
    assert fine.shape == pin.shape == (999, 999)
    assert np.abs(np.subtract(fine.meta["tilt_rad"], measured.meta["tilt_rad"])).max() < 1e-7
    face = pin.heights > -0.5e-3
    assert np.array_equal(fine.heights[~face], pin.heights[~face])
    assert np.array_equal(fine.heights, tilt_pin(pin, fine.meta["tilt_rad"]).heights)
