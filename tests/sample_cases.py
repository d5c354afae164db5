"""The bundled sample twin's small cases, shared by the tests: the bundled case file at
reduced size (``small_case``), pin 1 on its disk at n x n nodes over 8 x 8 mm, the flow
factors of patch 1 at 32 x 32 pixels (14 h0 x 4 steps), and smooth factors (no roughness).  The
``factors`` fixture (tests/conftest.py) computes the rough ones once per session."""

from pathlib import Path

import numpy as np

from fem_twin.io.files import read_topography
from fem_twin.micro import FlowFactors, homogenise
from fem_twin.topography import pin_face, resample_cell
from fem_twin.topography.prepare import MacroOptions, prepare_disk, prepare_patch, prepare_pin

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "meshes" / "sample"


def macro_case(n):
    """``(gap, spacing, face)`` of sample pin 1 on disk 1 at ``n`` x ``n`` nodes."""
    opts = MacroOptions(resolution=(n, n))
    pin = prepare_pin(read_topography(SAMPLE / "pin_1.npz"), opts)
    disk = prepare_disk(read_topography(SAMPLE / "disk_1.npz"), opts)
    return disk.heights - pin.heights, pin.spacing, pin_face(pin, opts.holder_height)


def sample_factors():
    """Flow factors of sample patch pair 1 at 32 x 32 pixels, 14 h0 x 4 steps."""
    low = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_1_pin.npz")), (32, 32))
    up = resample_cell(prepare_patch(read_topography(SAMPLE / "patch_1_disk.npz"), upper=True),
                       (32, 32))
    return homogenise(low, up, np.geomspace(2e-8, 1e-6, 14), steps=4)


def smooth_factors():
    """The factors of smooth surfaces: h_m = h0, no contact, identity flow tensors."""
    h0 = np.geomspace(1e-9, 1e-3, 7)
    n = h0.size
    return FlowFactors(h0=h0, h_m=h0.copy(), p_con=np.zeros(n), A=np.tile(np.eye(2), (n, 1, 1)),
                       b=np.tile([1.0, 0.0], (n, 1)), C=np.tile(np.eye(2), (n, 1, 1)),
                       d=np.zeros((n, 2)), friction_factor=np.ones(n),
                       pressure_friction=np.tile([1.0, 0.0], (n, 1)), contact_fraction=np.zeros(n))


def small_case(tmp_path, workers=1, band=False):
    """The bundled case with reduced settings (48^2 macro, 16^2 x 6 h0 x 4 steps micro,
    2 patches, 5 speeds, no patch band unless ``band``) so the whole pipeline runs in
    seconds."""
    text = (ROOT / "examples" / "pin_on_disk.toml").read_text()
    text = text.replace("../meshes/", str(ROOT / "meshes") + "/")
    for old, new in (("resolution = [128, 128]      # reduced", "resolution = [48, 48] #"),
                     ("resolution = [128, 128]      # patches", "resolution = [16, 16] #"),
                     ("h0_count = 16", "h0_count = 6"), ("steps = 32", "steps = 4"),
                     ("count = 12", "count = 5"), ("speed_min = 0.005", "speed_min = 0.01"),
                     ("refine = 1 ", "refine = 0 "),
                     ("workers = 0", f"workers = {workers}"),
                     ("patch_band = true", f"patch_band = {str(band).lower()}")):
        assert old in text
        text = text.replace(old, new)
    lines = [ln for ln in text.splitlines() if "patch_3" not in ln and "patch_4" not in ln
             and "patch_5" not in ln and "patch_6" not in ln]
    path = tmp_path / "case.toml"
    path.write_text("\n".join(lines))
    return path
