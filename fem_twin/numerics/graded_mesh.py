"""A graded tensor-product Q1 mesh over a uniform grid, and the transfers between the two.

The node lines of a :class:`Mesh` are a subset of a uniform grid's (pitch ``pitch``, the
grid of the FFT half-space, eqs 20-22): the film (eqs 17-18) is solved on the mesh, the
elastic deformation on the grid.  The pressure goes to the grid as the mesh's bilinear
interpolant (:meth:`Mesh.to_grid`) and the deformation comes back by injection
(:meth:`Mesh.from_grid`, every mesh node is a grid node).  The trapezoidal rule is exact on
a bilinear function over a rectangle, so the transfer conserves the load:
``sum(grid_area * to_grid(p)) == sum(mesh.area * p)`` to rounding (tests/test_graded.py).
:func:`graded_lines` chooses the lines from the contact: the grid's pitch over the Hertz
zone, doubling outward (a point contact: :func:`point_contact_mesh`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from ..errors import InputError

#: the widest element over the grid's pitch (2^MAX_LEVEL)
MAX_LEVEL = 3
#: the distance from a fine zone [Hertz half-widths] at which the spacing first doubles;
#: it doubles again at 3, 7, ... times it (a geometric grading of ratio 2)
GROWTH = 0.25
#: a point contact's zones [Hertz half-widths] and their levels: the grid's pitch over the
#: Hertz zone (the mixed regime's asperity load spans it, with the exit constriction and
#: the side lobes), twice it over the inlet along x1
ALONG = ((-1.25, 1.25, 0), (-2.0, 1.25, 1))
ACROSS = ((-1.25, 1.25, 0),)


@dataclass(frozen=True, eq=False)
class Mesh:
    """Node columns ``lines[0]`` (along x1) and rows ``lines[1]`` (along x2) of a uniform
    grid of ``pitch`` (dx1, dx2) [m]: increasing integers from 0; the mesh spans the grid."""

    pitch: tuple[float, float]
    lines: tuple[np.ndarray, np.ndarray]

    def __post_init__(self):
        lines = tuple(np.asarray(v, dtype=np.int64) for v in self.lines)
        for k, v in enumerate(lines):
            if v.ndim != 1 or v.size < 2 or v[0] != 0 or np.any(np.diff(v) <= 0):
                raise InputError(f"mesh lines along x{k + 1} must increase from 0 with at "
                                 f"least two lines, got {v}")
        pitch = tuple(float(v) for v in self.pitch)
        if len(pitch) != 2 or not all(np.isfinite(pitch)) or min(pitch) <= 0:
            raise InputError(f"mesh pitch must be two positive lengths [m], got {self.pitch}")
        object.__setattr__(self, "lines", lines)
        object.__setattr__(self, "pitch", pitch)

    @property
    def shape(self) -> tuple[int, int]:
        """The mesh's nodes (ny, nx)."""
        return self.lines[1].size, self.lines[0].size

    @property
    def grid_shape(self) -> tuple[int, int]:
        """The uniform grid's nodes (NY, NX)."""
        return int(self.lines[1][-1]) + 1, int(self.lines[0][-1]) + 1

    @property
    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """``(x1, x2)`` of the node lines from the first node [m]."""
        return self.lines[0] * self.pitch[0], self.lines[1] * self.pitch[1]

    @property
    def uniform(self) -> bool:
        """True when the mesh is the grid itself."""
        return self.shape == self.grid_shape

    @cached_property
    def area(self) -> np.ndarray:
        """Nodal weights of the trapezoidal rule [m^2] (the dual cells' areas)."""
        w1, w2 = (_widths(x) for x in self.coordinates)
        return w2[:, None] * w1[None, :]

    @property
    def sizes(self) -> tuple[np.ndarray, np.ndarray]:
        """The elements' sides along x1 (nx - 1,) and x2 (ny - 1,) [m]."""
        return tuple(np.diff(x) for x in self.coordinates)

    @property
    def widths(self) -> tuple[np.ndarray, np.ndarray]:
        """The dual cells' widths along x1 (nx,) and x2 (ny,) [m]."""
        return tuple(_widths(x) for x in self.coordinates)

    @cached_property
    def _interpolation(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        return tuple(_interpolation(v) for v in self.lines)

    def to_grid(self, field) -> np.ndarray:
        """The mesh's nodal ``field`` (ny, nx) as its bilinear interpolant on the grid."""
        P1, P2 = self._interpolation
        return np.asarray(P1 @ np.asarray(P2 @ np.asarray(field, float)).T).T

    @cached_property
    def prolongation(self) -> sp.csc_matrix:
        """``(NY * NX, ny * nx)``: :meth:`to_grid` as a matrix on flat fields."""
        P1, P2 = self._interpolation
        return sp.kron(P2, P1, format="csc")

    def from_grid(self, field) -> np.ndarray:
        """A grid field (NY, NX) at the mesh's nodes."""
        return np.asarray(field)[np.ix_(self.lines[1], self.lines[0])]

    @cached_property
    def grid_nodes(self) -> np.ndarray:
        """The flat grid index of each mesh node, (ny * nx,)."""
        return (self.lines[1][:, None] * self.grid_shape[1] + self.lines[0][None, :]).ravel()

    def coarsened(self) -> Mesh:
        """The mesh on the grid of twice the pitch: line ``l`` becomes ``l // 2`` (every
        element at least twice as long; its nodes are this mesh's, :meth:`every_other`).
        The grid must have an even number of cells a side."""
        if any(v[-1] % 2 for v in self.lines):
            raise InputError(f"a mesh on a grid of {self.grid_shape} nodes cannot be "
                             "coarsened by two: its cells a side must be even")
        return Mesh((2 * self.pitch[0], 2 * self.pitch[1]),
                    tuple(np.unique(v // 2) for v in self.lines))

    def every_other(self, field) -> np.ndarray:
        """A nodal field (ny, nx) on :meth:`coarsened`'s nodes."""
        keep = [np.searchsorted(v, 2 * np.unique(v // 2)) for v in self.lines]
        return np.asarray(field)[np.ix_(keep[1], keep[0])]


@dataclass(frozen=True, eq=False)
class MeshElastic:
    """The half-space of eqs 20-22 on a :class:`Mesh`: the nodal pressure [Pa] to the grid
    (:meth:`Mesh.to_grid`), the deformation [m] by FFT there (``grid``, an
    :class:`~fem_twin.contact.elastic.ElasticOperator` on ``mesh.grid_shape``), and back
    at the mesh's nodes."""

    mesh: Mesh
    grid: object

    @property
    def kernel_hat(self) -> np.ndarray:
        return self.grid.kernel_hat

    def __call__(self, pressure) -> np.ndarray:
        return self.mesh.from_grid(self.grid(self.mesh.to_grid(pressure)))


def _widths(x) -> np.ndarray:
    d = np.diff(x)
    return np.r_[d[0] / 2, (d[:-1] + d[1:]) / 2, d[-1] / 2]


def _interpolation(lines) -> sp.csr_matrix:
    """(N, n): the 1-D linear interpolation from the lines onto every grid line."""
    f = np.arange(lines[-1] + 1)
    k = np.clip(np.searchsorted(lines, f, side="right") - 1, 0, lines.size - 2)
    t = (f - lines[k]) / (lines[k + 1] - lines[k])
    rows = np.r_[f, f]
    P = sp.csr_matrix((np.r_[1 - t, t], (rows, np.r_[k, k + 1])), shape=(f.size, lines.size))
    P.eliminate_zeros()                               # grid nodes on a line: one entry
    return P


def graded_lines(levels) -> np.ndarray:
    """Node lines on a grid of ``len(levels)`` cells, each cell allowed an element of up to
    ``2^levels[c]`` pitches: from line 0 the longest step ``2^L`` that starts on a multiple
    of ``2^L`` (so that coarse lines nest) and spans cells all allowing ``L``."""
    levels = np.asarray(levels, int)
    cells, out, i = levels.size, [0], 0
    while i < cells:
        level = int(levels[i])
        while level > 0 and (i % (1 << level) or i + (1 << level) > cells
                             or levels[i:i + (1 << level)].min() < level):
            level -= 1
        i += 1 << level
        out.append(i)
    return np.asarray(out)


def cell_levels(centres, zones, growth, max_level: int = MAX_LEVEL) -> np.ndarray:
    """Each cell's allowed level from its ``centres`` (in any length unit): the least over
    the ``zones`` ((lo, hi, level), ...) of the zone's level plus
    ``floor(log2(1 + d / growth))``, ``d`` the distance from the zone; at most
    ``max_level``."""
    level = np.full(centres.shape, float(max_level))
    for lo, hi, base in zones:
        d = np.maximum.reduce([lo - centres, centres - hi, 0 * centres])
        level = np.minimum(level, base + np.floor(np.log2(1 + d / growth)))
    return level.astype(int)


def point_contact_mesh(n: int, extent, half_widths, graded: bool = True) -> Mesh:
    """The mesh of a point contact on a grid of ``n x n`` nodes over ``extent`` (in the
    Hertz half-widths) with ``half_widths`` (a, b) [m]: the grid itself, or graded
    (:func:`graded_lines`, :func:`cell_levels`) by the zones :data:`ALONG` (x1) and
    :data:`ACROSS` (x2), doubling outward by :data:`GROWTH` half-widths."""
    pitch = tuple((e[1] - e[0]) * w / (n - 1) for e, w in zip(extent, half_widths))
    if not graded:
        return Mesh(pitch, (np.arange(n), np.arange(n)))
    lines = []
    for (lo, hi), zones in zip(extent, (ALONG, ACROSS)):
        centres = lo + (np.arange(n - 1) + 0.5) * (hi - lo) / (n - 1)
        lines.append(graded_lines(cell_levels(centres, zones, GROWTH)))
    return Mesh(pitch, tuple(lines))
