"""Structured scikit-fem meshes on topography grids, and grid <-> meshio <-> VTU transfers.

Nodes are pixels.  Unlike ``skfem.MeshQuad1.init_tensor`` (which numbers nodes with x2
fastest), mesh nodes here are numbered row-major like ``heights.ravel()``, so that a nodal
vector and a grid field are the same numbers.

A periodic grid of ``(ny, nx)`` pixels is meshed over its full period with an unfolded
``(ny + 1) x (nx + 1)`` node grid whose last row and column are images of the first; the
sparse map ``P`` (nodes x pixels) identifies them.  A periodic FE operator is ``P.T @ A @ P``
(Galerkin-consistent, unlike ``skfem.utils.mpc``), and VTU files hold the unfolded mesh.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
import zlib
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import meshio
import numpy as np
import scipy.sparse as sp
import skfem

from ..checks import arguments
from ..errors import InputError, MissingFile
from ..numerics.graded_mesh import Mesh
from .atomic import atomic_path


@dataclass(frozen=True, eq=False)
class GridMesh:
    """A scikit-fem mesh whose nodes are the pixels of a ``shape = (ny, nx)`` grid.

    Attributes
    ----------
    mesh : skfem.MeshQuad1 or skfem.MeshTri1
    shape : (ny, nx) pixel grid
    spacing : (dx1, dx2) [m]
    origin : (x1, x2) of pixel [0, 0] [m]
    periodic : bool
        Periodic in both directions (period ``nx dx1`` by ``ny dx2``).
    lines : the node lines (x1, x2) on the grid of a graded mesh
        (:class:`fem_twin.numerics.graded_mesh.Mesh`), None: every line
    """

    mesh: skfem.Mesh
    shape: tuple[int, int]
    spacing: tuple[float, float]
    origin: tuple[float, float]
    periodic: bool
    lines: tuple | None = None

    @property
    def node_shape(self) -> tuple[int, int]:
        """Shape of the node grid: ``shape``, or ``(ny + 1, nx + 1)`` when periodic."""
        ny, nx = self.shape
        return (ny + 1, nx + 1) if self.periodic else (ny, nx)

    @cached_property
    def node_pixel(self) -> np.ndarray:
        """Flat (row-major) pixel index of every mesh node."""
        ny, nx = self.shape
        j, i = np.indices(self.node_shape)
        return ((j % ny) * nx + (i % nx)).ravel()

    @cached_property
    def periodic_map(self) -> sp.csr_matrix:
        """Sparse ``P`` (nodes x pixels) with ``P[node, pixel] = 1``; identity if not periodic."""
        n = self.node_pixel.size
        return sp.csr_matrix((np.ones(n), (np.arange(n), self.node_pixel)),
                             shape=(n, self.shape[0] * self.shape[1]))

    def to_nodes(self, field: np.ndarray) -> np.ndarray:
        """Grid field ``(ny, nx)`` -> nodal vector (images copied on a periodic mesh)."""
        field = np.asarray(field)
        if field.shape[:2] != tuple(self.shape):
            raise InputError(f"field shape {field.shape} does not match grid {self.shape}")
        return field.reshape(self.shape[0] * self.shape[1], *field.shape[2:])[self.node_pixel]

    def to_grid(self, nodal: np.ndarray) -> np.ndarray:
        """Nodal vector -> grid field ``(ny, nx)`` (values at the pixels' own nodes)."""
        nodal = np.asarray(nodal)
        if nodal.shape[0] != self.mesh.nvertices:
            raise InputError(f"nodal vector has {nodal.shape[0]} entries, mesh has "
                             f"{self.mesh.nvertices} nodes")
        ny, nx = self.shape
        return nodal.reshape(*self.node_shape, *nodal.shape[1:])[:ny, :nx]


@arguments(shape="shape", spacing="spacing")
def grid_mesh(shape, spacing, origin=(0.0, 0.0), *, periodic: bool = False,
              kind: str = "quad") -> GridMesh:
    """Structured mesh with one node per pixel of a ``(ny, nx)`` grid of pitch ``spacing`` [m],
    or on the nodes of a graded :class:`~fem_twin.numerics.graded_mesh.Mesh` ``spacing``.

    ``kind`` is ``"quad"`` (bilinear quadrilaterals, one per pixel square) or ``"tri"`` (each
    square split along its diagonal).  ``periodic=True`` meshes the full period.
    """
    ny, nx = (int(v) for v in shape)
    if ny < 2 or nx < 2:
        raise InputError(f"a grid mesh needs at least 2 x 2 pixels, got {shape}")
    graded = isinstance(spacing, Mesh)
    if graded and (periodic or tuple(shape) != spacing.shape):
        raise InputError(f"a graded mesh of {spacing.shape} nodes is not periodic and has "
                         f"no other shape, got {tuple(shape)}")
    dx1, dx2 = spacing.pitch if graded else (
        float(v) for v in np.broadcast_to(np.asarray(spacing, float), (2,)))
    if not (dx1 > 0 and dx2 > 0):
        raise InputError(f"spacing must be positive [m], got {spacing}")
    if kind not in ("quad", "tri"):
        raise InputError(f"kind must be 'quad' or 'tri', got {kind!r}")
    my, mx = (ny + 1, nx + 1) if periodic else (ny, nx)
    x1, x2 = spacing.coordinates if graded else (dx1 * np.arange(mx), dx2 * np.arange(my))
    x1, x2 = origin[0] + x1, origin[1] + x2
    X1, X2 = np.meshgrid(x1, x2)
    p = np.vstack([X1.ravel(), X2.ravel()])
    n00 = (np.arange(my - 1)[:, None] * mx + np.arange(mx - 1)[None, :]).ravel()
    n10, n11, n01 = n00 + 1, n00 + mx + 1, n00 + mx
    if kind == "quad":
        mesh = skfem.MeshQuad1(p, np.vstack([n00, n10, n11, n01]))
    else:
        t = np.hstack([np.vstack([n00, n10, n11]), np.vstack([n00, n11, n01])])
        mesh = skfem.MeshTri1(p, t)
    return GridMesh(mesh, (ny, nx), (dx1, dx2), (float(origin[0]), float(origin[1])),
                    bool(periodic), spacing.lines if graded else None)


# -- meshio ------------------------------------------------------------------------------
@arguments(gm=GridMesh)
def to_meshio(gm: GridMesh, point_data: dict | None = None, *,
              elevation: str | None = None) -> meshio.Mesh:
    """A ``meshio.Mesh`` of ``gm`` with grid fields ``(ny, nx[, ...])`` as point data.

    The grid (shape, spacing, origin, periodic) travels in ``field_data`` so that
    :func:`from_meshio` restores it bit for bit.  ``elevation`` names a field used as the
    x3 coordinate of the points (for a 3D view in ParaView).
    """
    point_data = dict(point_data or {})
    nodal = {name: gm.to_nodes(np.asarray(v, dtype=float)) for name, v in point_data.items()}
    z = nodal[elevation] if elevation else np.zeros(gm.mesh.nvertices)
    points = np.column_stack([gm.mesh.p.T, z])
    cell_type = "quad" if isinstance(gm.mesh, skfem.MeshQuad1) else "triangle"
    grid = {"shape": list(gm.shape), "spacing": list(gm.spacing), "origin": list(gm.origin),
            "periodic": gm.periodic, "kind": "quad" if cell_type == "quad" else "tri"}
    if gm.lines is not None:
        grid["lines"] = [v.tolist() for v in gm.lines]
    field_data = {"fem_twin_grid": np.frombuffer(json.dumps(grid).encode(), dtype=np.uint8)}
    return meshio.Mesh(points, [(cell_type, gm.mesh.t.T.copy())], point_data=nodal,
                       field_data=field_data)


@arguments(mesh=meshio.Mesh)
def from_meshio(mesh: meshio.Mesh, *, periodic: bool | None = None) -> tuple[GridMesh, dict]:
    """Recover the grid and its fields ``(ny, nx)`` from a ``meshio.Mesh``.

    Meshes written by :func:`to_meshio` carry their grid description; for others the grid is
    inferred from the point coordinates (any node order, e.g. after ParaView), and
    ``periodic=True`` says that the last row and column are periodic images.
    """
    info = _grid_info(mesh)
    x, y = mesh.points[:, 0], mesh.points[:, 1]
    if info is not None:
        spacing = (Mesh(info["spacing"], info["lines"]) if "lines" in info
                   else info["spacing"])
        gm = grid_mesh(info["shape"], spacing, info["origin"],
                       periodic=info["periodic"], kind=info.get("kind", "quad"))
        my, mx = gm.node_shape
        lines = gm.lines or (np.arange(mx), np.arange(my))
        i = np.searchsorted(lines[0], np.rint((x - gm.origin[0]) / gm.spacing[0]))
        j = np.searchsorted(lines[1], np.rint((y - gm.origin[1]) / gm.spacing[1]))
    else:
        ux, uy = _unique_coords(x), _unique_coords(y)
        mx, my = ux.size, uy.size
        if mx * my != len(x):
            raise InputError(f"points do not form a structured grid ({mx} x {my} coordinates "
                             f"for {len(x)} points)")
        i, j = _nearest(ux, x), _nearest(uy, y)
        spacing = ((ux[-1] - ux[0]) / (mx - 1), (uy[-1] - uy[0]) / (my - 1))
        per = bool(periodic)
        shape = (my - 1, mx - 1) if per else (my, mx)
        gm = grid_mesh(shape, spacing, (ux[0], uy[0]), periodic=per)
    if np.unique(j * mx + i).size != len(x):
        raise InputError("points do not map one-to-one onto the grid")
    fields = {}
    for name, values in mesh.point_data.items():
        v = np.asarray(values)
        nodes = np.empty((my, mx) + v.shape[1:], v.dtype)
        nodes[j, i] = v
        if gm.periodic and not (np.array_equal(nodes[-1], nodes[0])
                                and np.array_equal(nodes[:, -1], nodes[:, 0])):
            raise InputError(f"field {name!r} is not periodic on the periodic mesh")
        fields[name] = nodes[:gm.shape[0], :gm.shape[1]].copy()
    return gm, fields


def _grid_info(mesh: meshio.Mesh):
    raw = mesh.field_data.get("fem_twin_grid")
    if raw is None:
        return None
    return json.loads(np.asarray(raw, dtype=np.uint8).tobytes().decode())


def _unique_coords(c: np.ndarray) -> np.ndarray:
    """Distinct coordinates, merging values closer than 1e-9 of the extent."""
    s = np.sort(c)
    tol = 1e-9 * max(np.ptp(s), np.abs(s).max(), 1e-300)
    return s[np.concatenate([[True], np.diff(s) > tol])]


def _nearest(u: np.ndarray, c: np.ndarray) -> np.ndarray:
    k = np.clip(np.searchsorted(u, c), 1, u.size - 1)
    return np.where(np.abs(c - u[k - 1]) <= np.abs(c - u[k]), k - 1, k)


# -- VTK files ---------------------------------------------------------------------------
@arguments(path="path", gm=GridMesh)
def write_vtu(path, gm: GridMesh, point_data: dict | None = None, *,
              elevation: str | None = None) -> Path:
    """Write grid fields on ``gm`` to a binary VTU file for ParaView, atomically."""
    path = Path(path)
    if path.suffix != ".vtu":
        raise InputError(f"VTU files end in .vtu, got {path.name}")
    m = to_meshio(gm, point_data, elevation=elevation)
    with atomic_path(path) as tmp, _fast_zlib():
        meshio.write(tmp, m, file_format="vtu", binary=True)
        # meshio reads but does not write VTU FieldData: add the grid description ourselves
        grid = m.field_data["fem_twin_grid"]
        field = (f'<FieldData><DataArray type="UInt8" Name="fem_twin_grid" '
                 f'NumberOfTuples="{grid.size}" format="ascii">'
                 f'{" ".join(map(str, grid))}</DataArray></FieldData>')
        text = tmp.read_text()
        tmp.write_text(text.replace("<UnstructuredGrid>", "<UnstructuredGrid>" + field, 1))
    return path


#: zlib level of the VTU data blocks (meshio compresses at zlib's default, 6): twice as
#: fast, the same size (heights hardly compress at any level, the mesh at any)
VTU_LEVEL = 1


class _Zlib:
    """zlib at :data:`VTU_LEVEL`, for meshio's VTU writer."""

    @staticmethod
    def compress(data: bytes) -> bytes:
        return zlib.compress(data, VTU_LEVEL)


@contextmanager
def _fast_zlib():
    """meshio's VTU writer compressing at :data:`VTU_LEVEL` (its module's ``zlib``, swapped
    for the write; unchanged where meshio keeps it elsewhere)."""
    vtu = getattr(getattr(meshio, "vtu", None), "_vtu", None)
    if vtu is None or getattr(vtu, "zlib", None) is not zlib:
        yield
        return
    vtu.zlib = _Zlib
    try:
        yield
    finally:
        vtu.zlib = zlib


@arguments(path="path")
def read_vtu(path, *, periodic: bool | None = None) -> tuple[GridMesh, dict]:
    """Read a VTU written by :func:`write_vtu` (or any structured-grid VTU) back to grids."""
    if not Path(path).is_file():
        raise MissingFile(f"{path}: no such VTU file")
    return from_meshio(meshio.read(path), periodic=periodic)


@arguments(path="path", entries=[tuple])
def write_pvd(path, entries) -> Path:
    """Write a ParaView collection ``path`` (.pvd) of ``(time, vtu_path)`` entries."""
    path = Path(path)
    root = ET.Element("VTKFile", type="Collection", version="0.1")
    coll = ET.SubElement(root, "Collection")
    for time, vtu in entries:
        rel = Path(vtu).resolve().relative_to(path.resolve().parent)
        ET.SubElement(coll, "DataSet", timestep=repr(float(time)), part="0", file=str(rel))
    with atomic_path(path) as tmp:
        ET.ElementTree(root).write(tmp, xml_declaration=True, encoding="utf-8")
    return path
