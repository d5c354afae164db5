"""The converged operating point of the macro scale: fields, friction (eqs 31-34), files."""

from __future__ import annotations

import json
from dataclasses import dataclass, field, fields, is_dataclass, replace
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ...io.atomic import atomic_path
from ...micro.rolling import at_slide_to_roll
from ...numerics.graded_mesh import Mesh
from ..film.reynolds import trapezoid_weights
from ..laws.boundary_friction import asperity_load, boundary_area, traction
from ..laws.friction import FilmFields, confined_shear, disk_shear, hydrodynamic_shear
from ..laws.kinematics import disk_velocity, rotations

#: the grid fields of an operating point and their SI units: declared once, for the
#: checkpoints, VTU files and ``fields.nc`` (:func:`fem_twin.results.fields_dataset`)
FIELDS = {"pressure": "Pa", "contact_pressure": "Pa", "cavity_fraction": "1", "h0": "m",
          "mean_gap": "m", "elastic_deformation": "m", "viscosity": "Pa s",
          "density_ratio": "1", "shear_stress": "Pa", "boundary_shear": "Pa", "face": "1"}


@dataclass(frozen=True, eq=False)
class MixedResult:
    """A converged operating point (SI units).

    Scalars: ``speed`` U [m/s], ``imposed_load`` F_N,imp and ``normal_load`` F_N (eq 28) [N],
    ``h_d`` [m], ``friction_force`` F_T (eq 33) with its ``hydrodynamic_friction`` and
    ``boundary_force`` parts [N], ``friction_coefficient`` C_f (eq 34),
    ``contact_load`` (integral of p_con) [N]; the asperities' ``asperity_load`` (of
    p_con + p a_r, :func:`.boundary_friction.asperity_load`) [N] and ``real_contact_area`` (of the
    dry contact fraction a_c, which tau_0 multiplies) [m^2] over the face, each node
    weighted by the x1 share of its sliding direction (1 under uniform sliding): the
    integrals the boundary law reads along the load cell.
    Fields (ny, nx): ``pressure`` p_hd, ``contact_pressure`` p_con [Pa], ``cavity_fraction``,
    ``h0``, ``mean_gap`` h_m, ``elastic_deformation`` h_el [m], ``viscosity`` [Pa s],
    ``density_ratio`` rho/rho_0, ``shear_stress`` tau_tot and its ``boundary_shear`` part
    (x1, :mod:`.boundary_friction`) [Pa], ``face`` (pin face mask).
    ``history``: rows (iteration, r_hel, r_pcon, r_p, r_F, h_d, newton steps).
    """

    speed: float
    imposed_load: float
    normal_load: float
    h_d: float
    friction_force: float
    hydrodynamic_friction: float
    boundary_force: float
    friction_coefficient: float
    contact_load: float
    asperity_load: float
    real_contact_area: float
    spacing: tuple
    pressure: np.ndarray
    contact_pressure: np.ndarray
    cavity_fraction: np.ndarray
    h0: np.ndarray
    mean_gap: np.ndarray
    elastic_deformation: np.ndarray
    viscosity: np.ndarray
    density_ratio: np.ndarray
    shear_stress: np.ndarray
    boundary_shear: np.ndarray
    face: np.ndarray
    iterations: int = 0
    history: np.ndarray = field(default_factory=lambda: np.zeros((0, 7)))
    meta: dict = field(default_factory=dict)

    def fields(self) -> dict:
        """The grid fields by name (for VTU output)."""
        return {k: np.asarray(getattr(self, k), float) for k in FIELDS}

    def scalars(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)
                if f.name not in FIELDS and f.name not in ("history", "meta")}

    def save(self, path) -> Path:
        """Write ``.npz`` (fields, history, scalars and meta as JSON; a graded mesh's
        lines) atomically."""
        path = Path(path)
        scalars, lines = self.scalars(), {}
        if isinstance(self.spacing, Mesh):
            scalars["spacing"] = self.spacing.pitch
            lines = {"mesh_lines1": self.spacing.lines[0], "mesh_lines2": self.spacing.lines[1]}
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as f:
                np.savez(f, **self.fields(), history=self.history, **lines,
                         scalars=np.array(json.dumps(scalars)),
                         meta=np.array(json.dumps(self.meta, sort_keys=True)))
        return path

    @classmethod
    def load(cls, path) -> "MixedResult":
        with np.load(path) as data:
            scalars = json.loads(str(data["scalars"]))
            scalars["spacing"] = tuple(scalars["spacing"])
            if "mesh_lines1" in data:
                scalars["spacing"] = Mesh(scalars["spacing"], (data["mesh_lines1"],
                                                               data["mesh_lines2"]))
            arrays = {k: data[k] for k in FIELDS}
            arrays["face"] = arrays["face"].astype(bool)
            return cls(**scalars, **arrays, history=data["history"],
                       meta=json.loads(str(data["meta"])))

    def contact_load_below(self, h0_min: float) -> float:
        """The share of the normal load F_N carried by asperity contact where the
        separation lies below ``h0_min`` [m], the smallest computed by the micro scale:
        there :meth:`~fem_twin.micro.FlowFactors.at` extrapolates p_con instead of reading
        it from a cell problem (lumped nodal areas, the face alone) [-]."""
        below = self.face & (self.h0 < h0_min)
        if isinstance(self.spacing, Mesh):
            return float((self.spacing.area * self.contact_pressure)[below].sum()
                         / self.normal_load)
        cell = self.spacing[0] * self.spacing[1]
        return float(self.contact_pressure[below].sum() * cell / self.normal_load)

    def write_vtu(self, path, origin=(0.0, 0.0)) -> Path:
        """Fields on the structured grid for ParaView (:func:`fem_twin.io.mesh.write_vtu`),
        SI units; ``pressure`` is absolute (its minimum is p_cav), ``pressure_gauge`` is
        ``pressure - p_amb``; ``face`` is 1 on the pin face (threshold on it in ParaView)."""
        from ...io.mesh import grid_mesh, write_vtu
        gm = grid_mesh(self.pressure.shape, self.spacing, origin)
        p_amb = self.meta.get("settings", {}).get("ambient_pressure", 0.0)
        return write_vtu(path, gm, {**self.fields(), "pressure_gauge": self.pressure - p_amb})



@dataclass(frozen=True)
class Convergence:
    """How a coupling reached its converged state: its ``iterations``, the ``history`` rows
    of :attr:`MixedResult.history`, the wall time ``seconds`` [s] and the ``coupling``'s
    name (None: the settings')."""

    iterations: int
    history: list
    seconds: float
    coupling: str | None = None


def mixed_result(P, ev, h_el, h_d, run: Convergence) -> MixedResult:
    """The :class:`MixedResult` of a converged state of ``P`` (a :class:`.problem.Problem`):
    ``ev`` its :class:`.evaluation.Evaluation`, the elastic deformation ``h_el`` [m] and
    the separation ``h_d`` [m], reached as ``run`` says; the friction of eqs 31-34 over the
    point's face."""
    point = P.point
    s, dx, area, face = point.settings, point.spacing, P.area, point.face
    loc = ev.loc
    p_hd = ev.p + s.cavitation_pressure
    fields = PointFields(pressure=p_hd, cavity_fraction=ev.theta, viscosity=ev.mu, h0=ev.h0,
                         mean_gap=loc.h_m, contact_pressure=ev.p_con, face=face)
    tau_hd, tau_con, asperity, a_r = pin_friction(fields, point, P.factors, P.velocity)
    weights = area * face                         # the load's trapezoidal rule on the face
    F_hd = float(np.sum(weights * tau_hd))
    F_con = float(np.sum(weights * tau_con))
    F_N = ev.F
    return MixedResult(
        speed=float(point.speed), imposed_load=float(point.load), normal_load=F_N,
        h_d=float(h_d),
        friction_force=F_hd + F_con, hydrodynamic_friction=F_hd, boundary_force=F_con,
        friction_coefficient=(F_hd + F_con) / F_N,
        contact_load=float(np.sum(area * ev.p_con)),
        asperity_load=float(np.sum(weights * asperity)),
        real_contact_area=float(np.sum(weights * a_r)), spacing=dx,
        pressure=p_hd, contact_pressure=ev.p_con, cavity_fraction=ev.theta,
        h0=ev.h0, mean_gap=loc.h_m, elastic_deformation=h_el,
        viscosity=ev.mu, density_ratio=ev.rho, shear_stress=tau_hd + tau_con,
        boundary_shear=tau_con * face, face=face, iterations=run.iterations,
        history=np.array(run.history),
        meta={"settings": _plain(s),
              "lubricant": point.lubricant.__dict__.copy(), "seconds": run.seconds,
              "coupling": run.coupling or ("anderson" if s.coupling == "auto"
                                           else s.coupling),
              "entrainment": float(point.u_m)})


def _plain(settings) -> dict:
    """``settings`` as JSON-ready values (tuples as lists, nested settings as dicts)."""
    return {f.name: (_plain(v) if is_dataclass(v) else list(v) if isinstance(v, tuple) else v)
            for f in fields(settings) for v in [getattr(settings, f.name)]}


@dataclass(frozen=True, eq=False)
class PointFields(FilmFields):
    """The fields of a converged operating point that its friction reads (a
    :class:`MixedResult` has the same names): the film's (:class:`~.friction.FilmFields`:
    ``pressure`` (absolute) [Pa], ``mean_gap`` h_m [m], ``cavity_fraction`` [-], local
    ``viscosity`` [Pa s]), the separation ``h0`` [m], the ``contact_pressure`` [Pa] and the
    pin ``face`` (bool), all (ny, nx)."""

    h0: np.ndarray
    contact_pressure: np.ndarray
    face: np.ndarray


def pin_friction(fields, point, factors, velocity=None):
    """The film's and the contacts' tangential tractions [Pa] of a converged state's
    ``fields`` (:class:`PointFields` or a :class:`MixedResult`) at the operating ``point``
    (an :class:`~fem_twin.macro.point.OperatingPoint`: its grid, settings, lubricant and
    speeds) as the rig reads them (``settings.reading``): on the pin along x1 (eqs 31-32,
    or the force on the pin: ``settings.friction``, :func:`.friction.hydrodynamic_shear`),
    or the disk's drag times ``|v|`` (its torque over the track radius,
    :func:`.friction.disk_shear`), with the flow ``factors`` at the point's slide-to-roll
    ratio and the disk's ``velocity`` (:func:`.kinematics.disk_velocity`; None: along x1);
    and the asperities' load field (:func:`.boundary_friction.asperity_load`) [Pa] and the dry
    contact fraction a_c [-] the law reads, each weighted alike (the x1 share of the
    sliding, or ``|v|``).  The confined films' viscous shear (``thin_films = "viscous"``)
    joins the film's traction."""
    settings, lubricant, speed = point.settings, point.lubricant, point.speed
    dx, h0, face, p_con = point.spacing, fields.h0, fields.face, fields.contact_pressure
    shear = factors.at(h0)              # the shear factors (the iterations read none)
    cos, _, local = (1.0, 0.0, 1.0) if velocity is None else rotations(velocity)
    if settings.reading == "torque":    # the disk's drag times |v| = r / R (its lever)
        along = local
        tau_hd = disk_shear(fields, shear, dx, speed, eyring_stress=lubricant.eyring_stress,
                            velocity=velocity) * local
    else:                               # the load cell on the pin: the x1 component
        along = cos
        tau_hd = hydrodynamic_shear(fields, shear, dx, speed, entrainment=point.u_m,
                                    eyring_stress=lubricant.eyring_stress,
                                    law=settings.friction, face=face,
                                    ambient_pressure=settings.ambient_pressure,
                                    velocity=velocity)
    law = settings.boundary
    gauge = np.maximum(np.asarray(fields.pressure, float) - settings.ambient_pressure, 0.0)
    if law.thin_films == "viscous":      # the confined films' viscous shear, along the sliding
        tau_hd = tau_hd + thin_film_shear(fields, shear, gauge, speed * local, point) * along
    load = asperity_load(p_con, gauge, boundary_area(shear, law), law)
    tau_con = traction(load, shear.contact_fraction, speed * local, law,
                       settings.boundary_friction)
    return (tau_hd, tau_con * along * (speed > 0),   # along the reading; 0: no sliding
            load * along, shear.contact_fraction * along)


def thin_film_shear(fields, shear, gauge, speed, point) -> np.ndarray:
    """The confined films' shear [Pa] (``thin_films = "viscous"``) of a converged state's
    ``fields`` with its shear factors ``shear``: viscous (:func:`.friction.confined_shear`
    at the local sliding ``speed`` [m/s]) up to a limiting shear, the ``point``'s boundary
    law's shear on their film pressure ``gauge`` [Pa] over their area (``thin_area``;
    without tau_0): at a ball's GPa the piezoviscous Eyring shear of nanometre films grows
    without bound (docs/model.md, "Boundary friction")."""
    law = point.settings.boundary
    limit = traction(gauge * np.clip(shear.thin_area, 0.0, 1.0), 0.0, speed, law,
                     point.settings.boundary_friction)
    return np.minimum(confined_shear(fields.viscosity, speed, shear, fields.mean_gap,
                                     fields.cavity_fraction, point.lubricant.eyring_stress),
                      np.maximum(limit, 0.0))


def friction_with(result: MixedResult, factors, point) -> float:
    """The friction coefficient of ``result``, the operating ``point``'s
    (:class:`~fem_twin.macro.point.OperatingPoint`, with the film's lubricant), with the
    shear factors of ``factors`` (a :class:`~fem_twin.micro.FlowFactors` at the pin's SRR
    2, carried to the point's), the point's fields unchanged: for factors that differ only
    in what the Reynolds equation does not read (the friction factors)."""
    moved = at_slide_to_roll(factors, point.slide_to_roll)
    velocity = disk_velocity(point.face, point.spacing, point.settings.track_radius)
    tau_hd, tau_con, *_ = pin_friction(result, point, moved, velocity)
    weights = trapezoid_weights(result.face.shape, point.spacing) * result.face
    return float(np.sum(weights * (tau_hd + tau_con)) / result.normal_load)


def on_grid(result: MixedResult, shape, dx) -> MixedResult:
    """``result`` interpolated (linearly, by coordinates from the first node) onto a grid
    or a graded ``Mesh`` ``dx``."""
    if _same_grid(result.spacing, result.pressure.shape, dx, shape):
        return result
    fields = {k: resampled(getattr(result, k), result.spacing, shape, dx)
              for k in FIELDS if k != "face"}
    return replace(result, spacing=dx if isinstance(dx, Mesh) else tuple(dx), **fields,
                   face=resampled(result.face, result.spacing, shape, dx) > 0.5)


def resampled(field, spacing, shape, dx) -> np.ndarray:
    """A nodal ``field`` on a grid of ``spacing`` interpolated (linearly, by coordinates from
    the first node, held at the last node beyond it) onto the grid ``shape``, ``dx`` [m]:
    bilinear, one axis after the other (half the time of ``scipy.ndimage.map_coordinates``
    at 2048^2, equal to 1e-14); from or onto a graded ``Mesh`` by its coordinates."""
    if isinstance(spacing, Mesh) or isinstance(dx, Mesh):
        return _by_coordinates(field, _coordinates(spacing, np.shape(field)),
                               _coordinates(dx, shape))
    out = np.asarray(field, float)
    for axis, (n_new, d_new, d_old) in enumerate(((shape[0], dx[1], spacing[1]),
                                                 (shape[1], dx[0], spacing[0]))):
        n = out.shape[axis]
        x = np.clip(np.arange(n_new) * (d_new / d_old), 0, n - 1)
        below = np.minimum(x.astype(int), n - 1)
        above = np.minimum(below + 1, n - 1)
        t = x - below
        if axis == 0:
            out = out[below] * (1 - t)[:, None] + out[above] * t[:, None]
        else:
            out = out[:, below] * (1 - t) + out[:, above] * t
    return out


def _same_grid(spacing, shape, dx, new_shape) -> bool:
    if isinstance(spacing, Mesh) or isinstance(dx, Mesh):
        return spacing is dx
    return tuple(shape) == tuple(new_shape) and np.allclose(spacing, dx)


def _coordinates(spacing, shape) -> tuple:
    """``(x1, x2)`` of a grid's node lines from its first node [m]."""
    if isinstance(spacing, Mesh):
        return spacing.coordinates
    return np.arange(shape[1]) * spacing[0], np.arange(shape[0]) * spacing[1]


def _by_coordinates(field, old, new) -> np.ndarray:
    """Bilinear interpolation of ``field`` on the lines ``old`` (x1, x2) at the lines
    ``new``, held at the last line beyond it."""
    M1, M2 = (_interpolation(n, o) for n, o in zip(new, old))
    return np.asarray(M1 @ np.asarray(M2 @ np.asarray(field, float)).T).T


def _interpolation(new, old) -> sp.csr_matrix:
    """(new, old): linear interpolation between the lines ``old`` at ``new``."""
    k = np.clip(np.searchsorted(old, new, side="right") - 1, 0, old.size - 2)
    t = np.clip((new - old[k]) / (old[k + 1] - old[k]), 0.0, 1.0)
    rows = np.arange(new.size)
    return sp.csr_matrix((np.r_[1 - t, t], (np.r_[rows, rows], np.r_[k, k + 1])),
                         shape=(new.size, old.size))
