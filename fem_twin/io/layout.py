"""The output folder of a run: every file and folder it writes and reads, named once.

``fem-twin run CASE -o OUT`` writes ``summary.json``, ``run.log``, ``stage_keys.json``;
``geometry/`` (the prepared pins, disks, patches and their VTU), ``levelling/``, ``micro/``
(the flow factors of every patch and their average, with the per-h0 checkpoints),
``stribeck/checkpoints/`` (one file per point), ``fields/`` (VTU + PVD per sweep), and
``stribeck.csv``, its plots, ``results.nc``, ``fields.nc``, ``validation*`` and
``report.html``.  ``compare`` and ``calibrate`` add their files and sub-runs (``fe/``,
``fvm/``, ``reference/``, ``variant_K/``); every file is listed with its units in
docs/reference/outputs.md.

The pipeline, ``compare``, ``calibrate``, ``report``, ``results`` and the CLI take their paths
from a :class:`RunLayout`; pin, disk and patch numbers ``k`` count from 1."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError


@dataclass(frozen=True)
class RunLayout:
    """Paths of one run's output folder ``root``."""

    root: Path

    def __post_init__(self):
        root = Path(self.root)
        if root.exists() and not root.is_dir():
            raise InputError(f"{root} is a file: give a folder for the results (-o)")
        object.__setattr__(self, "root", root)

    # -- the run ---------------------------------------------------------------------------
    @property
    def summary(self) -> Path:
        return self.root / "summary.json"

    @property
    def log(self) -> Path:
        return self.root / "run.log"

    @property
    def stage_keys(self) -> Path:
        return self.root / "stage_keys.json"

    @property
    def lock(self) -> Path:
        return self.root / ".lock"

    def stage(self, name: str) -> Path:
        """The folder of a cached stage (``geometry``, ``levelling``, ``micro``)."""
        return self.root / name

    # -- geometry and levelling ------------------------------------------------------------
    @property
    def geometry(self) -> Path:
        return self.root / "geometry"

    def pin(self, k: int) -> Path:
        return self.geometry / f"pin_{k}.npz"

    def disk(self, k: int) -> Path:
        return self.geometry / f"disk_{k}.npz"

    def macro_vtu(self, k: int) -> Path:
        return self.geometry / f"macro_{k}.vtu"

    def patch(self, k: int, side: str) -> Path:
        """Prepared roughness patch ``k``, ``side`` ``"low"`` (pin) or ``"up"`` (disk)."""
        return self.geometry / f"patch_{k}_{side}.npz"

    def patch_vtu(self, k: int) -> Path:
        return self.geometry / f"patch_{k}.vtu"

    @property
    def levelling(self) -> Path:
        return self.root / "levelling"

    def levelled_pin(self, k: int | str) -> Path:
        """Levelled pin ``k``, or ``"average"``: the set average."""
        return self.levelling / f"pin_{k}.npz"

    def levelled_pins(self) -> list[Path]:
        """Every levelled pin written (the average among them)."""
        return sorted(self.levelling.glob("pin_*.npz"))

    # -- micro -----------------------------------------------------------------------------
    @property
    def micro(self) -> Path:
        return self.root / "micro"

    @property
    def flow_factors(self) -> Path:
        """The patch average's flow factors."""
        return self.micro / "flow_factors.npz"

    def patch_factors(self, k: int | None) -> Path:
        """Flow factors of patch ``k`` (None: the patch average)."""
        if k is None:
            return self.flow_factors
        return self.micro / f"patch_{k}" / self.flow_factors.name

    def patch_checkpoints(self, k: int) -> Path:
        return self.micro / f"patch_{k}" / "checkpoints"

    @property
    def flow_factors_csv(self) -> Path:
        return self.root / "flow_factors.csv"

    @property
    def flow_factors_png(self) -> Path:
        return self.root / "flow_factors.png"

    # -- Stribeck curves -------------------------------------------------------------------
    @property
    def points(self) -> Path:
        """Checkpoints of the Stribeck points."""
        return self.root / "stribeck" / "checkpoints"

    @property
    def fields(self) -> Path:
        """VTU/PVD of the operating points, for ParaView."""
        return self.root / "fields"

    @property
    def stribeck_csv(self) -> Path:
        return self.root / "stribeck.csv"

    def stribeck_png(self, x: str) -> Path:
        """The Stribeck plot against ``x`` (``"speed"`` or ``"hersey"``)."""
        return self.root / f"stribeck_{x}.png"

    @property
    def parts_png(self) -> Path:
        """C_f split into its film (predicted) and boundary (calibrated) parts."""
        return self.root / "stribeck_parts.png"

    @property
    def temperature_png(self) -> Path:
        """A thermal run's contact temperatures against speed."""
        return self.root / "contact_temperature.png"

    def fields_png(self, viscosity: float) -> Path:
        return self.root / f"fields_mu{viscosity:g}.png"

    @property
    def validation_csv(self) -> Path:
        return self.root / "validation.csv"

    def validation_png(self, viscosity: float) -> Path:
        return self.root / f"validation_mu{viscosity:g}.png"

    def fields_pngs(self) -> list[Path]:
        """Every :meth:`fields_png` written."""
        return sorted(self.root.glob("fields_mu*.png"))

    def validation_of(self, measured: Path, suffix: str) -> Path:
        """Output of ``fem-twin validate`` against the measured CSV ``measured``."""
        return self.root / f"validation_{Path(measured).stem}{suffix}"

    def validation_pngs(self) -> list[Path]:
        """Every :meth:`validation_png` written."""
        return sorted(self.root.glob("validation_mu*.png"))

    @property
    def results(self) -> Path:
        return self.root / "results.nc"

    # -- traction curves (fem-twin traction) -------------------------------------------------
    @property
    def traction_csv(self) -> Path:
        """C_f versus the slide-to-roll ratio per viscosity."""
        return self.root / "traction.csv"

    @property
    def traction_png(self) -> Path:
        return self.root / "traction.png"

    @property
    def traction_points(self) -> Path:
        """Checkpoints of the traction points."""
        return self.root / "traction" / "checkpoints"

    @property
    def fields_nc(self) -> Path:
        return self.root / "fields.nc"

    @property
    def fit(self) -> Path:
        """``fem-twin fit``: the fitted parameters with their 95 % intervals."""
        return self.root / "fit.json"

    @property
    def fit_png(self) -> Path:
        return self.root / "fit.png"

    def prediction(self, temperature: float | None = None) -> Path:
        """``fem-twin fit --predict T``: the curve predicted for the oil at ``T`` [C];
        without ``T``, the band of ``fem-twin run --from-fit`` around the run's curves."""
        name = "prediction.csv" if temperature is None else f"prediction_{temperature:g}C.csv"
        return self.root / name

    def prediction_at_load(self, load: float) -> Path:
        """``fem-twin fit --predict-load L``: the curves predicted at the load ``L`` [N]."""
        return self.root / f"prediction_{load:g}N.csv"

    @property
    def fit_points(self) -> Path:
        """The checkpoints of the sweeps at other load shares (``load_share`` fits)."""
        return self.root / "fit" / "checkpoints"

    @property
    def report(self) -> Path:
        return self.root / "report.html"

    @property
    def report_figures(self) -> Path:
        """The figures ``report.html`` embeds that the run did not draw."""
        return self.root / "report"

    # -- studies (fem-twin compare, fem-twin calibrate) --------------------------------------
    @property
    def compare(self) -> Path:
        return self.root / "compare.json"

    @property
    def compare_factors_csv(self) -> Path:
        return self.root / "compare_flow_factors.csv"

    @property
    def compare_stribeck_csv(self) -> Path:
        return self.root / "compare_stribeck.csv"

    @property
    def compare_png(self) -> Path:
        return self.root / "compare.png"

    @property
    def calibration(self) -> Path:
        return self.root / "calibration.json"

    @property
    def deviation_png(self) -> Path:
        """C_f,dev of a calibration study's variants against its reference."""
        return self.root / "cf_dev.png"

    def deviation_pngs(self) -> list[Path]:
        """Every :attr:`deviation_png` in this folder and below (studies run into it)."""
        return sorted(self.root.glob(f"**/{self.deviation_png.name}"))

    def sub(self, name: str) -> "RunLayout":
        """The layout of a sub-run (a method of ``compare``, a variant of ``calibrate``)."""
        return RunLayout(self.root / name)
