"""One operating point of the macro scale as a value, checked once: what
:func:`~fem_twin.macro.mixed.solve_point`, :func:`~fem_twin.macro.nested.solve_nested` and
:func:`~fem_twin.macro.estimate.friction_error` take.  A sweep request makes one per speed
(:meth:`fem_twin.stribeck.SweepRequest.operating_point`)."""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass, replace

import numpy as np

from ..checks import arguments, as_field, as_spacing, number, plausible
from ..errors import InputError
from ..micro.flow_factors import FlowFactors
from ..numerics.graded_mesh import Mesh
from .coupling.settings import MacroSettings
from .film.reynolds import check_closed
from .laws.lubricant import Lubricant

#: the largest rigid gap [m] either way: a pin's holder lies 1 mm below its face
MAX_GAP = 0.05


@dataclass(frozen=True, eq=False)
class OperatingPoint:
    """The rigid ``gap`` h_g (ny, nx) [m] on a grid of ``spacing`` (dx1, dx2) [m], x1 (the
    disk's sliding) along the columns; the flow ``factors`` (the cell's, pin at rest); the
    imposed ``load`` F_N,imp the face carries [N] (eq 28); the sliding ``speed`` u_r [m/s];
    the ``entrainment`` speed u_m [m/s] where it is not u_r / 2 (a ball at SRR = u_r / u_m;
    u_r 0 with u_m given: pure rolling); the ``lubricant``; the pin ``face`` for the
    friction integral (eq 33; None: the whole grid, stored as such a mask) and the macro
    ``settings``."""

    gap: np.ndarray
    spacing: tuple
    factors: FlowFactors
    _: KW_ONLY
    load: float
    speed: float
    lubricant: Lubricant
    entrainment: float | None = None
    face: np.ndarray | None = None
    settings: MacroSettings = MacroSettings()

    def __post_init__(self):
        if not isinstance(self.factors, FlowFactors):
            raise InputError(f"factors must be FlowFactors (fem_twin.micro.homogenise, or "
                             f"FlowFactors.smooth()), got {type(self.factors).__name__}")
        gap = as_field("gap [m]", self.gap, 3)
        if np.abs(gap).max() > MAX_GAP:
            raise InputError(f"gap [m] spans {gap.min():.3g} to {gap.max():.3g} m: implausible "
                             f"for a pin or a ball (at most {MAX_GAP:g} m either way); give it "
                             "in metres")
        check_closed(gap)
        spacing = as_spacing("spacing [m]", self.spacing)
        plausible("spacing [m]", getattr(spacing, "pitch", spacing), "pitch")
        if isinstance(spacing, Mesh) and spacing.shape != gap.shape:
            raise InputError(f"the gap {gap.shape} is not on the mesh's nodes {spacing.shape}")
        face = np.ones(gap.shape, bool) if self.face is None else np.asarray(self.face, bool)
        if face.shape != gap.shape:
            raise InputError(f"face mask {face.shape} does not match the gap {gap.shape}")
        if not face.any():
            raise InputError("face mask: no node of the grid lies on the face (all False)")
        if not isinstance(self.lubricant, Lubricant) or not isinstance(self.settings,
                                                                       MacroSettings):
            raise InputError("OperatingPoint: lubricant must be a Lubricant and settings "
                             f"MacroSettings, got {type(self.lubricant).__name__} and "
                             f"{type(self.settings).__name__}")
        values = dict(gap=gap, spacing=spacing, face=face,
                      load=number("load [N]", self.load, "load"))
        if self.entrainment is None or self.speed != 0:   # 0 with u_m: pure rolling
            values["speed"] = number("speed [m/s]", self.speed, "speed")
        if self.entrainment is not None:
            values["entrainment"] = number("entrainment [m/s]", self.entrainment, "speed")
        for name, value in values.items():
            object.__setattr__(self, name, value)

    @property
    def u_m(self) -> float:
        """The entrainment speed u_m [m/s]: ``entrainment``, else u_r / 2 (a pin at rest);
        the one place this convention is written (the macro scale reads it here)."""
        return self.speed / 2 if self.entrainment is None else self.entrainment

    @property
    def slide_to_roll(self) -> float:
        """SRR = u_r / u_m [-], 2 for a pin at rest (the flow factors' own)."""
        return self.speed / self.u_m

    @property
    def surface_speeds(self) -> tuple[float, float]:
        """``(u_1, u_2)``: the pin's (or ball's) and the disk's speeds along x1 [m/s]."""
        return self.u_m - self.speed / 2, self.u_m + self.speed / 2

    def coarsened(self) -> OperatingPoint:
        """The point on every other node of the grid."""
        gap, spacing, face = coarsened(self.gap, self.spacing, self.face)
        return replace(self, gap=gap, spacing=spacing, face=face)


@arguments(gap="field", spacing="spacing")
def coarsened(gap, spacing, face):
    """``(gap, spacing, face)`` on every other node of the grid [m], or every other line
    of a graded :class:`~fem_twin.numerics.graded_mesh.Mesh` (``face`` None: None)."""
    if isinstance(spacing, Mesh):
        return (spacing.every_other(gap), spacing.coarsened(),
                None if face is None else spacing.every_other(np.asarray(face, bool)))
    return (np.asarray(gap)[::2, ::2], (2 * spacing[0], 2 * spacing[1]),
            None if face is None else np.asarray(face, bool)[::2, ::2])
