"""The bundled sample twin: a seeded, documented stand-in for the paper's measurements.

The paper's measured topographies are not public; this generator makes files of the same
structure (``meshes/README.md``): 3 worn pins, FRT-like (500 x 500 px over 8 x 8 mm: a
crowned 8 mm face with an edge roll-off, a small tilt, fine roughness, noise, the holder
far below, invalid pixels and dropouts); 3 matching disks (flat, waviness below 1 um, a
faint wear track at 30 mm, dropouts); and 6 roughness patch pairs, Sensofar-like
(768 x 576 px over 84.9 x 63.7 um, self-affine with Hurst 0.8, Sq after levelling as Table
5 of the paper).  Heights are integer multiples of a quantum, as instruments store them
(1 nm macro, 0.1 nm patches), in fem_twin's ``.npz`` with fixed zip timestamps, so
regenerating gives byte-identical files on the same library versions."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..topography.core import Topography
from ..topography.levelling import level
from ..topography.synthetic import self_affine
from .files import write_topography

SEED = 2023
#: Table 5 of the paper: Sq of the roughness patches of test 2.1 [m], (disk = up, pin = low).
TABLE5_SQ_UP = (84.5e-9, 84.6e-9, 118.3e-9, 119.9e-9, 96.3e-9, 100.1e-9)
TABLE5_SQ_LOW = (41.5e-9, 116.5e-9, 132.3e-9, 101.4e-9, 96.7e-9, 131.2e-9)
MACRO_SHAPE, MACRO_SIZE = (500, 500), 8e-3
PATCH_SHAPE, PATCH_SIZE = (576, 768), (84.9e-6, 63.7e-6)
PIN_RADIUS = 4e-3
SLIDING_RADIUS = 30e-3
MACRO_QUANTUM, PATCH_QUANTUM = 1e-9, 1e-10


def sample_files() -> list[str]:
    """Names of the files the generator writes."""
    names = [f"pin_{k}.npz" for k in (1, 2, 3)] + [f"disk_{k}.npz" for k in (1, 2, 3)]
    names += [f"patch_{k}_{s}.npz" for k in range(1, 7) for s in ("pin", "disk")]
    return names


def generate(outdir) -> list[Path]:
    """Write the sample twin into ``outdir`` and return the file paths."""
    outdir = Path(outdir)
    rng = np.random.default_rng(SEED)
    seeds = rng.integers(0, 2**31, size=len(sample_files()))
    files = iter(zip(sample_files(), seeds))
    written = []
    for k in (1, 2, 3):
        name, seed = next(files)
        written.append(write_topography(outdir / name, worn_pin(seed, k),
                                        height_scale=MACRO_QUANTUM))
    for k in (1, 2, 3):
        name, seed = next(files)
        written.append(write_topography(outdir / name, worn_disk(seed, k),
                                        height_scale=MACRO_QUANTUM))
    for k in range(6):
        for sq, (name, seed) in zip((TABLE5_SQ_LOW[k], TABLE5_SQ_UP[k]),
                                    (next(files), next(files))):
            patch = roughness_patch(seed, sq, f"{name[:-4]} (Table 5 patch {k + 1})")
            written.append(write_topography(outdir / name, patch, height_scale=PATCH_QUANTUM))
    return written


def _macro_grid():
    dx = MACRO_SIZE / MACRO_SHAPE[1]
    x = (np.arange(MACRO_SHAPE[1]) - (MACRO_SHAPE[1] - 1) / 2) * dx
    return dx, x


def worn_pin(seed: int, k: int) -> Topography:
    """Measured worn pin ``k`` (heights as the instrument sees them, face up)."""
    rng = np.random.default_rng(seed)
    dx, x = _macro_grid()
    centre = rng.uniform(-40e-6, 40e-6, size=2)
    X1, X2 = np.meshgrid(x - centre[0], x - centre[1])
    r = np.hypot(X1, X2)
    crown = rng.uniform(1.5e-6, 3.0e-6)               # face crown [m] over the radius
    roll = rng.uniform(3e-6, 6e-6)                    # extra edge roll-off [m]
    r_roll = rng.uniform(3.2e-3, 3.5e-3)              # where the roll-off starts [m]
    face = (-crown * (r / PIN_RADIUS) ** 2
            - roll * np.clip((r - r_roll) / (PIN_RADIUS - r_roll), 0, None) ** 2)
    # running-in leaves a slightly asymmetric face: low-order waviness of ~0.3 um
    face += 0.3e-6 * rng.uniform(0.5, 1) \
        * np.cos(2 * np.pi * X1 / 9e-3 + rng.uniform(0, 2 * np.pi)) \
        * np.cos(2 * np.pi * X2 / 11e-3 + rng.uniform(0, 2 * np.pi))
    rough = self_affine(MACRO_SHAPE, dx, 0.8, 0.25e-6, rolloff_wavelength=0.2e-3,
                        rng=rng).heights
    noise = 20e-9 * rng.standard_normal(MACRO_SHAPE)
    chamfer = -60e-6 - 40e-3 * (r - PIN_RADIUS)       # steep chamfer far below the face
    z = np.where(r <= PIN_RADIUS, face + rough, chamfer) + noise
    tilt = rng.uniform(-3e-4, 3e-4, size=2)           # sample not level under the microscope
    z += tilt[0] * X1 + tilt[1] * X2 + rng.uniform(-5e-6, 5e-6)
    invalid = (r > PIN_RADIUS) & (r < PIN_RADIUS + 0.2e-3)          # no signal on the flank
    invalid |= rng.random(MACRO_SHAPE) < 2e-3                        # isolated dropouts
    for _ in range(4):                                               # a few small holes
        c = rng.integers(100, 400, size=2)
        invalid[c[0]:c[0] + rng.integers(2, 6), c[1]:c[1] + rng.integers(2, 6)] = True
    z[invalid] = np.nan
    meta = {"sample": f"worn pin {k}",
            "instrument": "FRT-like confocal, 500 x 500 px over 8 x 8 mm",
            "generator": "fem_twin.io.samples.worn_pin", "seed": int(seed), "unit": "m",
            "pin_radius": PIN_RADIUS, "crown": crown, "edge_roll_off": roll}
    return Topography(z, dx, origin=(x[0], x[0]), meta=meta)


def worn_disk(seed: int, k: int) -> Topography:
    """Measured disk ``k`` around the wear track (face up, x1 along sliding)."""
    rng = np.random.default_rng(seed)
    dx, x = _macro_grid()
    X1, X2 = np.meshgrid(x, x)
    # the pin's path on the sliding radius: a shallow groove of the pin's width
    dist = np.abs(np.hypot(X1, SLIDING_RADIUS - X2) - SLIDING_RADIUS)
    depth = rng.uniform(0.15e-6, 0.3e-6)
    track = -depth * 0.5 * (1 - np.tanh((dist - 3.6e-3) / 0.15e-3))
    lam = rng.uniform(20e-3, 40e-3, size=2)
    wave = 0.2e-6 * np.sin(2 * np.pi * X1 / lam[0] + rng.uniform(0, 2 * np.pi)) \
        + 0.1e-6 * np.sin(2 * np.pi * X2 / lam[1] + rng.uniform(0, 2 * np.pi))
    rough = self_affine(MACRO_SHAPE, dx, 0.8, 0.08e-6, rolloff_wavelength=0.2e-3, rng=rng).heights
    tilt = rng.uniform(-3e-4, 3e-4, size=2)
    z = track + wave + rough + 10e-9 * rng.standard_normal(MACRO_SHAPE)
    z += tilt[0] * X1 + tilt[1] * X2 + rng.uniform(-5e-6, 5e-6)
    z[rng.random(MACRO_SHAPE) < 1e-3] = np.nan
    meta = {"sample": f"disk {k}", "instrument": "FRT-like confocal, 500 x 500 px over 8 x 8 mm",
            "generator": "fem_twin.io.samples.worn_disk", "seed": int(seed), "unit": "m",
            "sliding_radius": SLIDING_RADIUS, "track_depth": depth}
    return Topography(z, dx, origin=(x[0], x[0]), meta=meta)


def roughness_patch(seed: int, sq: float, label: str) -> Topography:
    """Sensofar-like roughness patch whose Sq after levelling is ``sq`` [m]."""
    rng = np.random.default_rng(seed)
    spacing = (PATCH_SIZE[0] / PATCH_SHAPE[1], PATCH_SIZE[1] / PATCH_SHAPE[0])
    z = self_affine(PATCH_SHAPE, spacing, 0.8, sq, rolloff_wavelength=20e-6,
                    short_cutoff=0.5e-6, rng=rng)
    tilt = rng.uniform(-2e-3, 2e-3, size=2)
    X1, X2 = z.coordinates()
    levelled = level(z)
    heights = levelled.heights * (sq / levelled.rms_height())
    heights = heights + tilt[0] * X1 + tilt[1] * X2        # measurement tilt, removed by level
    meta = {"sample": label, "instrument": "Sensofar-like WLI, 768 x 576 px over 84.9 x 63.7 um",
            "generator": "fem_twin.io.samples.roughness_patch", "seed": int(seed), "unit": "m",
            "sq_levelled": sq, "hurst": 0.8}
    return Topography(heights, spacing, meta=meta)
