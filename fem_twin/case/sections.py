"""The case file's sections, one frozen dataclass each: every key declared once
(:func:`fem_twin.checks.setting`: default, one-line doc, plausible range or unit, choices).
The parser (:mod:`fem_twin.case`), the stages and the documentation's case-file reference
read these declarations; ``[preprocessing]`` is
:class:`fem_twin.topography.prepare.MacroOptions`."""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from pathlib import Path

from .. import tables as T
from ..checks import check_ranges, setting
from ..macro.coupling.settings import MacroSettings
from ..macro.laws.boundary_friction import BoundaryLaw, boundary_friction_setting
from ..macro.laws.friction import READINGS
from ..macro.laws.thermal import ThermalSettings
from ..micro.homogenisation import H0_COUNT, H0_MAX, H0_MIN, h0_candidates
from ..micro.sliding import CellSettings
from ..topography.prepare import MacroOptions


@dataclass(frozen=True)
class Geometry:
    """``[geometry]``: measured topography files (paths relative to the case file are
    resolved) and the window the roughness patches are cut from."""

    pins: tuple[Path, ...] = setting(
        (), "macro pin maps (8 x 8 mm), one file per pin; the set average is the macro pin",
        unit="file paths")
    disks: tuple[Path, ...] = setting(
        (), "the disk map measured with each pin (none: a flat disk)", unit="file paths")
    patches: tuple[tuple[Path, Path], ...] = setting(
        (), "roughness patch pairs [pin patch, disk patch], one micro problem each",
        unit="file path pairs")
    patch_shape: tuple[int, int] = setting(
        (256, 256), "rows and columns of each patch, cut without interpolation", "pixels")
    patch_start: tuple[int, int] = setting((0, 0), "first row and column of the cut",
                                           "pixel_offset")
    ball: Path | None = setting(
        None, "a measured ball cap, the ball-on-disk's macro gap (its sphere fitted for the "
        "radius, the cap read around its apex); none: the smooth sphere of ball_radius",
        unit="file path")

    def __post_init__(self):
        check_ranges(self)


@dataclass(frozen=True)
class Tribometer:
    """``[tribometer]``: operating conditions (Tables 1 and 6).  ``kind = "ball-on-disk"``:
    a ball on the disk at ``slide_to_roll`` = u_r / u_m (MTM convention; the sweep's speeds
    are then entrainment speeds u_m)."""

    load: float = setting(T.LOAD, "imposed normal load F_N,imp (Table 6)", "load")
    pin_diameter: float = setting(T.PIN_DIAMETER, "pin diameter D of the Hersey number (eq 46)",
                                  "pin_diameter")
    sliding_radius: float = setting(30e-3, "radius of the pin's track on the disk (its "
                                    "centre's; the sweep's speeds are the sliding speeds there)",
                                    "length")
    kinematics: str = setting("rotating", "the disk's motion under the face: turning about "
                              "its axis (u = omega x r over the face), or sliding uniformly "
                              "along x1 (the paper)", choices=("rotating", "uniform"))
    boundary_friction: float = boundary_friction_setting(
        "C_f,b of eq 32 (the paper's 1/(3 sqrt 3)); also the scale of C_f,dev (eq 35)")
    load_share: float = setting(
        1.0, "share of the load the pin face carries (film and contact, eq 28); C_f stays "
        "the friction force over the imposed load (1: the paper)", "load_share")
    kind: str = setting("pin-on-disk", "the tribometer", choices=("pin-on-disk",
                                                                  "ball-on-disk"))
    reading: str = setting("force", "what the rig reads, C_f's numerator: the tangential "
                           "force on the pin holder (a load cell), or the disk's reaction "
                           "torque over the track radius", choices=READINGS)
    ball_radius: float = setting(12.5e-3, "radius of a ball-on-disk's ball", "length")
    slide_to_roll: float = setting(0.5, "slide-to-roll ratio u_r / u_m of a ball's Stribeck "
                                   "curve (2: a stationary ball)", "ball_slide_to_roll")
    track_radius: float = setting(20e-3, "radius of a ball's track on the disk (its "
                                  "contact's centre's)", "length")

    def __post_init__(self):
        check_ranges(self)

    @property
    def ball(self) -> bool:
        return self.kind == "ball-on-disk"

    @property
    def disk_radius(self) -> float | None:
        """The track radius of the macro grid's centre [m]; None: uniform sliding."""
        if self.kinematics == "uniform":
            return None
        return self.track_radius if self.ball else self.sliding_radius


@dataclass(frozen=True)
class LubricantSpec:
    """``[lubricant]``: mu_0 per temperature (Table 3) and the constants of eqs 23-24
    (Table 6)."""

    viscosities: tuple[float, ...] = setting(
        (0.066, 0.024), "mu_0 at ambient pressure, one Stribeck curve each (Table 3)",
        "viscosity")
    temperatures: tuple[float, ...] = setting(
        (24.0, 50.0), "oil temperature of each viscosity: curve labels, and the Walther law "
        "of fem-twin fit", "temperature_C")
    density: float = setting(T.DENSITY, "rho_0 at ambient pressure (eq 24)", "density")
    roelands_alpha: float = setting(T.ROELANDS_ALPHA, "pressure-viscosity coefficient of "
                                    "Roelands (eq 23)", "pressure_viscosity")
    roelands_p0: float = setting(T.ROELANDS_P0, "Roelands reference pressure p_0 (eq 23)",
                                 "pressure_scale")
    dh_c1: float = setting(T.DH_C1, "Dowson-Higginson C_1 (eq 24)", "pressure_scale")
    dh_c2: float = setting(T.DH_C2, "Dowson-Higginson C_2 (eq 24)", "dh_ratio")
    eyring_stress: float = setting(0.0, "tau_0 of Eyring shear thinning (0: Newtonian; "
                                   "needed for EHL traction)", "eyring_stress")

    def __post_init__(self):
        check_ranges(self)

    def lubricants(self) -> list:
        """One :class:`fem_twin.macro.Lubricant` per viscosity."""
        from ..macro.laws.lubricant import Lubricant
        return [Lubricant(mu, density=self.density, roelands_alpha=self.roelands_alpha,
                          roelands_p0=self.roelands_p0, dh_c1=self.dh_c1, dh_c2=self.dh_c2,
                          eyring_stress=self.eyring_stress or None)
                for mu in self.viscosities]


@dataclass(frozen=True)
class Materials:
    """``[materials]``: elastic constants of pin and disk (Table 4) and the hardness cap."""

    e_pin: float = setting(T.E_STEEL, "Young's modulus of the pin (or ball)", "modulus")
    nu_pin: float = setting(T.NU_STEEL, "Poisson ratio of the pin (or ball)", "poisson")
    e_disk: float = setting(T.E_STEEL, "Young's modulus of the disk", "modulus")
    nu_disk: float = setting(T.NU_STEEL, "Poisson ratio of the disk", "poisson")
    hardness: float = setting(T.HARDNESS, "hardness: the cap on the contact pressure",
                              "hardness")

    def __post_init__(self):
        check_ranges(self)

    @property
    def e_reduced(self) -> float:
        """E' of eq 22 [Pa]."""
        from ..contact.elastic import reduced_modulus
        return reduced_modulus(self.e_pin, self.nu_pin, self.e_disk, self.nu_disk)


@dataclass(frozen=True)
class MicroSpec(CellSettings):
    """``[micro]``: the roughness scale (eqs 8-16): every setting of the cell problems
    (:class:`fem_twin.micro.CellSettings`, declared there once: time steps, method, squeeze
    term, adaptive instants, tolerances), the patches' resolution and the h0 candidates."""

    model: str = setting("cells", "the flow factors: the cell problems on the measured "
                         "patches (the twin), or the statistical average-flow model "
                         "(Patir-Cheng, Greenwood-Tripp: a screening run in seconds, with no "
                         "error bar; docs/peers.md)", choices=("cells", "average-flow"))
    resolution: tuple[int, int] = setting((128, 128), "patches resampled (periodically) to "
                                          "this grid, at least 8 each (the paper: its 256 px "
                                          "patches as cut; docs/accuracy.md, 'Cheaper "
                                          "defaults')", "pixels")
    h0_min: float = setting(H0_MIN, "smallest separation h0", "separation")
    h0_max: float = setting(H0_MAX, "largest separation h0 (above: the paper's rules)",
                            "separation")
    h0_count: int = setting(H0_COUNT, "h0 candidates, log-spaced (the paper: 100)", "samples")
    h0_tol: float = setting(0.01, "adaptive h0: solve the candidates the log-h0 "
                            "interpolant needs to read the others within this (0: all, the "
                            "paper)", "adaptive_tolerance")

    def h0_candidates(self, count: int | None = None):
        """The h0 candidates [m] of ``[micro]`` (``count`` of them; default ``h0_count``):
        :func:`fem_twin.micro.homogenisation.h0_candidates`."""
        return h0_candidates(self.h0_min, self.h0_max, count or self.h0_count)


@dataclass(frozen=True)
class MacroSpec(MacroSettings):
    """``[macro]``: the homogenised Reynolds scale (eqs 17-34): every setting of the macro
    solver (:class:`fem_twin.macro.coupling.settings.MacroSettings`, declared there once), the macro
    pin and a ball's grid."""

    pin: str | int = setting("average", "the macro pin: the levelled set's average, or a "
                             "pin number from 1", "pin_number")
    grid: int = setting(97, "nodes per side of a ball's grid over [-4a, 2a] x [-3a, 3a]",
                        "nodes")
    mesh: str = setting("uniform", "a ball's film mesh: \"uniform\" (the grid itself) or "
                        "\"graded\" (the grid's pitch over the Hertz zone, coarser outward, on "
                        "the grid's lines; the elastic FFT stays on the grid)",
                        choices=("uniform", "graded"))


@dataclass(frozen=True)
class SweepSpec:
    """``[sweep]``: speeds from ``speed_max`` down to ``speed_min``, ``count`` log-spaced,
    then ``refine`` passes that add midpoints where C_f jumps."""

    speed_max: float = setting(2.0, "fastest sliding speed (the paper: 2 m/s)", "speed")
    speed_min: float = setting(0.01, "slowest sliding speed (the paper: 0.01 m/s)", "speed")
    count: int = setting(25, "speeds, log-spaced from fast to slow", "samples")
    refine: int = setting(1, "passes adding midpoints where C_f jumps (0: off, at most 4)",
                          "passes")
    refine_step: float = setting(0.1, "... by more than this share of C_f,b",
                                 "share")
    error_tolerance: float = setting(0.005, "warn where a point's estimated discretisation "
                                     "error of C_f exceeds this share of C_f,b",
                                     "share")

    def __post_init__(self):
        check_ranges(self)

    @property
    def speeds(self):
        import numpy as np
        return np.geomspace(self.speed_max, self.speed_min, self.count)


@dataclass(frozen=True)
class RunSpec:
    """``[run]``: where independent work runs, and whether the main job adds the patch
    scatter band."""

    workers: int = setting(0, "local processes (0: all cores)", "workers")
    scheduler: str | None = setting(None, "a Dask scheduler's address instead, e.g. "
                                    '"tcp://10.0.0.1:8786", or "local": a Dask LocalCluster '
                                    "of `workers` processes (the cluster extra)",
                                    unit="address")
    patch_band: bool = setting(True, "one more sweep per patch: the roughness scatter band "
                               "(Figure 13)", unit="true or false")
    # "coarsest": a patch's C_f within 0.45 % C_f,b of the band swept on the full grid,
    # on a band about 46 % C_f,b wide, at a third of the time (docs/accuracy.md, "The patch
    # scatter band"; python benchmarks/run.py paper)
    band_grid: str = setting("coarsest", "the band's macro grid, C_f corrected by the "
                             "average curve's relative change to the full grid: \"coarsest\" (the "
                             "grid coarsened down to 48-95 px a side: 64^2 from 128^2 to "
                             '1024^2), "coarse" (every other node) or "full"',
                             unit="coarsest, coarse or full",
                             choices=("coarsest", "coarse", "full"))
    # 1e-3: the patches' C_f within 0.04 % C_f,b of 1e-4, far below the band's own grid
    # error, in fewer Newton steps (python benchmarks/run.py paper)
    band_tol: float = setting(1e-3, "coupling tolerance of the band's sweeps ([macro] tol "
                              "for the main curves, which carry the error estimates)",
                              "solver_tolerance")

    def __post_init__(self):
        check_ranges(self)


#: each setting a stage's settings take from another section (declared with
#: ``setting(..., section=...)``): its section and how the case gives it.  The cells slide
#: at ``CellSettings``' own SRR 2 (the pin at rest) in every case, no case key sets it: a
#: ball's ratio reaches the flow factors by the frame change of
#: :func:`fem_twin.micro.at_slide_to_roll` in ``solve_mixed``.
FILLED = {"e_reduced": ("materials", lambda case: case.materials.e_reduced),
          "hardness": ("materials", lambda case: case.materials.hardness),
          "boundary_friction": ("tribometer", lambda case: case.tribometer.boundary_friction),
          "track_radius": ("tribometer", lambda case: case.tribometer.disk_radius),
          "reading": ("tribometer", lambda case: case.tribometer.reading),
          "boundary": ("boundary", lambda case: case.boundary)}


#: ``band_grid = "coarsest"`` coarsens the macro grid down to this side to twice it [nodes]
#: (the band's accuracy was measured at 64^2, docs/accuracy.md); the nested solves go on to
#: 36-71 (:data:`fem_twin.macro.mixed.COARSE_START`), where a ball's 37^2 guides its 73^2
BAND_SMALLEST = 48
#: the case file's sections and the dataclass that declares each one's keys
#: (``[validation]`` has one key, ``measured``; ``name`` is top-level)
SECTIONS = {"geometry": Geometry, "preprocessing": MacroOptions, "tribometer": Tribometer,
            "lubricant": LubricantSpec, "materials": Materials, "micro": MicroSpec,
            "macro": MacroSpec, "thermal": ThermalSettings, "boundary": BoundaryLaw,
            "sweep": SweepSpec, "run": RunSpec}


@dataclass(frozen=True)
class Case:
    """A whole case: geometry sources, pre-processing, physics, scales, sweep, execution."""

    name: str
    geometry: Geometry
    preprocessing: MacroOptions = field(default_factory=MacroOptions)
    tribometer: Tribometer = field(default_factory=Tribometer)
    lubricant: LubricantSpec = field(default_factory=LubricantSpec)
    materials: Materials = field(default_factory=Materials)
    micro: MicroSpec = field(default_factory=MicroSpec)
    macro: MacroSpec = field(default_factory=MacroSpec)
    thermal: ThermalSettings = field(default_factory=ThermalSettings)
    boundary: BoundaryLaw = field(default_factory=BoundaryLaw)
    sweep: SweepSpec = field(default_factory=SweepSpec)
    run: RunSpec = field(default_factory=RunSpec)
    measured: tuple[Path | None, ...] = ()   # [validation] measured curves per viscosity
    source: Path | None = None
    defaulted: tuple[str, ...] = ()          # sections absent from the file (defaults used)

    def filled(self, settings):
        """``settings`` (a stage's settings dataclass) with every field another section
        sets taken from this case (:data:`FILLED`)."""
        return replace(settings, **{f.name: FILLED[f.name][1](self) for f in fields(settings)
                                    if f.metadata.get("section")})

    @property
    def macro_shape(self) -> tuple[int, int]:
        """The macro grid's nodes: a ball's ``[macro] grid`` a side, else the pin's
        ``[preprocessing] resolution`` (256^2 where the maps' own grid is kept)."""
        if self.tribometer.ball:
            return (self.macro.grid,) * 2
        return tuple(self.preprocessing.resolution or (256, 256))

    def band_coarsening(self, shape) -> int:
        """Coarsenings by two of the band's grid below a macro grid of ``shape``
        (``[run] band_grid``): none ("full"), one ("coarse"), or down to 48-95 nodes a side
        ("coarsest", at least one: 64^2 for the grids 128^2 to 1024^2, where the band's
        accuracy was measured), the main sweeps' coarsest nested grid where that is as
        large (:data:`BAND_SMALLEST`)."""
        from ..macro.nested import nested_levels
        return {"full": 0, "coarse": 1}.get(self.run.band_grid,
                                            max(1, nested_levels(shape, BAND_SMALLEST)))

    def band_after_guides(self, shape) -> bool:
        """Whether the band's sweeps start from the main sweeps' guides (their grid is the
        guides' coarsest nested grid), so each pass of the band runs beside the main
        points, rather than from the points' kept levels, after them."""
        from ..macro.nested import nested_levels
        return self.run.patch_band and self.band_coarsening(shape) == nested_levels(shape)
