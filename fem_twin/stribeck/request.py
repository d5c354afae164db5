"""What one Stribeck sweep is asked to solve, as a value: :class:`SweepRequest`, with the
contact's motion a value of its own (:class:`Sliding` or :class:`RollingSliding`).

Every command builds its sweeps as requests (:func:`fem_twin.stages.requests.sweep_request`
from a case) and changes them with :func:`dataclasses.replace`; a request's :attr:`key`
names its point checkpoints (:func:`~fem_twin.stribeck.sweep.point_file`)."""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass, fields, is_dataclass, replace
from pathlib import Path

import numpy as np

from .. import tables as T
from ..checks import as_field, as_spacing, check, number
from ..errors import InputError
from ..io.checkpoint import input_key
from ..macro import Lubricant, MacroSettings
from ..macro.point import OperatingPoint, coarsened
from ..micro.flow_factors import FlowFactors


@dataclass(frozen=True)
class Sliding:
    """A pin sliding on the disk (the paper): a sweep's speeds are sliding speeds U [m/s]."""

    @property
    def key(self):
        """What the motion adds to a sweep's checkpoint key (nothing: the paper's)."""
        return None

    def speeds(self, speed: float) -> dict:
        """``solve_mixed``'s speeds at the sweep speed U [m/s]: the sliding speed."""
        return {"speed": speed}

    def sweep_speed(self, speed: float, meta: dict) -> float:
        """The sweep speed of a point that slid at ``speed`` [m/s] (its ``meta``)."""
        return speed


@dataclass(frozen=True)
class RollingSliding:
    """A ball rolling and sliding on the disk at ``slide_to_roll`` = u_r / u_m in (0, 2]
    (MTM convention; 2: the ball at rest): a sweep's speeds are entrainment speeds u_m
    [m/s].  Pure rolling (0) slides at no speed: it is a traction curve's SRR 0
    (:func:`~fem_twin.stribeck.traction.traction_sweep`)."""

    slide_to_roll: float

    def __post_init__(self):
        number("slide_to_roll", self.slide_to_roll, "ball_slide_to_roll")

    @property
    def key(self) -> float:
        """What the motion adds to a sweep's checkpoint key: its ratio."""
        return self.slide_to_roll

    def speeds(self, u_m: float) -> dict:
        """``solve_mixed``'s speeds at the entrainment speed u_m [m/s]."""
        return {"speed": self.slide_to_roll * u_m, "entrainment": u_m}

    def sweep_speed(self, speed: float, meta: dict) -> float:
        """The sweep speed of a point: its entrainment speed u_m [m/s] (in its ``meta``)."""
        return meta["entrainment"]


@dataclass(frozen=True, eq=False)
class SweepRequest:
    """One viscosity's sweep: the macro ``gap`` [m] on a grid of ``spacing`` [m], the flow
    ``factors``, the ``speeds`` [m/s] (fast to slow), the imposed ``load`` F_N,imp [N] of
    which the face carries ``load_share`` (eq 28 balances their product; C_f and the
    Hersey number refer to ``load``), the ``lubricant``, the ``motion``, D of the Hersey number
    ``hersey_length`` [m] (eq 46), the pin ``face`` (None: the whole grid), the macro
    ``settings`` and a ``thermal`` model (None: isothermal, the boundary law's temperature
    term at the ``oil_temperature`` [C], or at its reference where that is None).
    ``factors_key``: a key of the factors' inputs, hashed instead of their bits;
    ``checkpoint``: the points' folder; ``fields``: a VTU per speed there (``origin``
    [m]); ``error_estimate``: each point's C_f error;
    ``keep_level``: keep each point's nested solve that many coarsenings down, which a
    sweep with ``guide`` (that level's key, :meth:`level_key`) starts from."""

    gap: np.ndarray
    spacing: tuple
    factors: FlowFactors
    speeds: np.ndarray
    _: KW_ONLY
    load: float
    lubricant: Lubricant
    load_share: float = 1.0
    motion: Sliding | RollingSliding = Sliding()
    hersey_length: float = T.PIN_DIAMETER
    face: np.ndarray | None = None
    settings: MacroSettings = MacroSettings()
    thermal: object = None
    oil_temperature: float | None = None
    factors_key: str | None = None
    checkpoint: Path | None = None
    fields: Path | None = None
    origin: tuple = (0.0, 0.0)
    error_estimate: bool = False
    keep_level: int = 0
    guide: str | None = None

    def __post_init__(self):
        name = "SweepRequest"
        check(f"{name}: speeds", self.speeds, "numbers")
        speeds = np.asarray(self.speeds, float)
        if speeds.ndim != 1 or speeds.size == 0 or np.any(~(speeds > 0)):
            raise InputError(f"{name}: speeds must be a non-empty list of positive values "
                             "[m/s]")
        for field_, kind in (("factors", FlowFactors), ("lubricant", Lubricant),
                             ("motion", (Sliding, RollingSliding))):
            check(f"{name}: {field_}", getattr(self, field_), kind)
        object.__setattr__(self, "gap", as_field(f"{name}: gap", self.gap))
        object.__setattr__(self, "spacing", as_spacing(f"{name}: spacing", self.spacing))
        object.__setattr__(self, "speeds", speeds)
        object.__setattr__(self, "load", number(f"{name}: load", self.load, "load"))
        number(f"{name}: load_share", self.load_share, "load_share")

    @property
    def face_load(self) -> float:
        """The load the face carries, ``load`` times ``load_share`` [N] (eq 28)."""
        return self.load * self.load_share

    def operating_point(self, speed: float) -> OperatingPoint:
        """The macro operating point at the sweep ``speed`` [m/s] (a sliding speed, or an
        entrainment speed, by the ``motion``), the face carrying :attr:`face_load`."""
        return OperatingPoint(self.gap, self.spacing, self.factors, load=self.face_load,
                              lubricant=self.lubricant, face=self.face,
                              settings=self.settings, **self.motion.speeds(speed))

    @property
    def key(self) -> str:
        """The key of the sweep's point checkpoints: a hash of all that sets its points."""
        return self.key_with(self.motion.key)

    def key_with(self, motion_key) -> str:
        """:attr:`key` with ``motion_key`` for the motion's (a traction curve's)."""
        keyed = {f.name: getattr(self, f.name) for f in fields(self) if f.name not in NOT_KEYED}
        keyed["settings"] = {"class": type(self.settings).__name__,      # as a dataclass's
                             **{f.name: getattr(self.settings, f.name)
                                for f in fields(self.settings) if f.name not in ESTIMATE_ONLY}}
        keyed["motion"] = motion_key
        if self.factors_key is None:            # the factors' own values, not their meta
            keyed["factors"] = {f.name: getattr(self.factors, f.name)
                                for f in fields(self.factors) if f.name != "meta"}
        return sweep_key(keyed)

    def level_key(self, level: int) -> str:
        """The :attr:`key` of this sweep on the grid coarsened ``level`` times
        (:func:`~fem_twin.macro.nested.coarsened`): where ``keep_level`` keeps its nested
        solves."""
        return self.coarsened(level).key

    def coarsened(self, level: int = 1) -> SweepRequest:
        """This sweep on the grid coarsened ``level`` times."""
        gap, spacing, face = self.gap, self.spacing, self.face
        for _ in range(level):
            gap, spacing, face = coarsened(gap, spacing, face)
        return replace(self, gap=gap, spacing=spacing, face=face)


#: the request's fields that do not set its points' converged states: where the points
#: are written and what is written beside them, the speeds (each point's own key), the
#: Hersey length (applied to the curve), the starts (``guide``, ``keep_level``: iterations,
#: not results) and the factors when ``factors_key`` names their inputs instead
NOT_KEYED = frozenset({"checkpoint", "fields", "origin", "error_estimate", "speeds",
                       "hersey_length", "keep_level", "guide", "factors"})
#: the macro settings that set only the points' C_f error estimate, which records them
#: (:func:`fem_twin.macro.estimate.is_current` makes it again where they changed)
ESTIMATE_ONLY = frozenset({"grid_order"})


def sweep_key(keyed: dict) -> str:
    """Key of a sweep's checkpoints (``point_KEY_*.npz``): a hash of ``keyed``, the
    request's fields that set its points (every field but :data:`NOT_KEYED`), dataclasses
    by their fields and arrays by their bits."""
    arrays = []
    skeleton = _skeleton(keyed, arrays)
    return input_key(*arrays, skeleton, length=12)


def _skeleton(value, arrays: list):
    """``value`` with its arrays moved to ``arrays`` (hashed by their bits) and dataclasses
    as dicts of their fields: a JSON form that names every number."""
    if isinstance(value, np.ndarray):
        arrays.append(value)
        return f"array {len(arrays)}"
    if is_dataclass(value) and not isinstance(value, type):
        return {"class": type(value).__name__,
                **{f.name: _skeleton(getattr(value, f.name), arrays) for f in fields(value)}}
    if isinstance(value, dict):
        return {str(k): _skeleton(v, arrays) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_skeleton(v, arrays) for v in value]
    return value
