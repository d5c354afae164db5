"""Re-assembly on structured pixel grids, shared by the cell problems and the macro scale.

Every element of a pixel mesh is the same rectangle, so element matrices are sums of
reference tensors that scikit-fem assembles once on a single element (:func:`unit_element`);
a new matrix is then a dense product and a ``bincount`` of the element entries onto a sparse
pattern fixed in advance (:class:`FixedPattern`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.sparse as sp
import skfem

from .ordering import nested_dissection_torus


def unit_element(spacing, intorder: int = 2) -> skfem.Basis:
    """Q1 basis on one ``dx1 x dx2`` rectangle [m], local nodes as in the pixel meshes."""
    dx1, dx2 = spacing
    one = skfem.MeshQuad1(np.array([[0, dx1, dx1, 0], [0, 0, dx2, dx2]], float),
                          np.array([[0], [1], [2], [3]]))
    return skfem.Basis(one, skfem.ElementQuad1(), intorder=intorder)


def element_entries(dofs):
    """Row and column of every entry of the 4 x 4 element matrices, element-major with the
    ``(i, j)`` pair inner, for the ``(4, nelems)`` global dofs ``dofs``."""
    return np.repeat(dofs, 4, axis=0).T.ravel(), np.tile(dofs, (4, 1)).T.ravel()


@dataclass(frozen=True, eq=False)
class FixedPattern:
    """CSR pattern of an ``n x n`` matrix whose entries arrive as a list ``(rows, cols)``
    with repeats (summed).  ``slot[k]`` is the position of entry ``k`` in the CSR data."""

    slot: np.ndarray
    indptr: np.ndarray
    indices: np.ndarray
    n: int

    @classmethod
    def from_entries(cls, rows, cols, n) -> "FixedPattern":
        key = np.asarray(rows, np.int64) * n + np.asarray(cols, np.int64)
        uniq, slot = np.unique(key, return_inverse=True)
        pattern = sp.csr_matrix((np.ones(uniq.size), (uniq // n, uniq % n)), shape=(n, n))
        pattern.sort_indices()          # CSR data order = the sorted keys np.unique returns
        if uniq.size < 2 ** 31:         # 4 B an entry instead of 8: 64 B a node of a Q1 grid
            slot = slot.astype(np.int32)
        return cls(slot, pattern.indptr, pattern.indices, int(n))

    def values(self, data) -> np.ndarray:
        """CSR data of the matrix with entries ``data`` (one per listed entry)."""
        return np.bincount(self.slot, weights=np.ravel(data), minlength=self.indices.size)

    def csr(self, data) -> sp.csr_matrix:
        return sp.csr_matrix((self.values(data), self.indices, self.indptr),
                             shape=(self.n, self.n))


#: the local nodes of a Q1 pixel element as (row, column) offsets from its first node, in
#: the order of :func:`fem_twin.io.mesh.grid_mesh` and :func:`unit_element`
CORNERS = ((0, 0), (0, 1), (1, 1), (1, 0))


@dataclass(frozen=True, eq=False)
class GridStencil:
    """CSR pattern of the 3 x 3 stencil on a non-periodic ``(ny, nx)`` node grid.

    A matrix on it is a stencil array ``S`` (ny, nx, 3, 3): ``S[r, c, a, b]`` couples node
    ``(r, c)`` with ``(r + a - 1, c + b - 1)``; ``valid`` masks the offsets inside the grid,
    and ``S[valid]`` is the CSR data in this pattern's (sorted) order.  Element matrices are
    added block by block (:meth:`add_elements`), so no list of element entries is kept
    (a :class:`FixedPattern` holds 64 B a node for it)."""

    shape: tuple
    valid: np.ndarray
    indptr: np.ndarray
    indices: np.ndarray

    @classmethod
    def of(cls, shape) -> "GridStencil":
        """The pattern of the grid ``shape`` (ny, nx) (column indices int32, sorted)."""
        ny, nx = shape
        r = np.arange(ny)[:, None, None, None] + np.arange(-1, 2)[None, None, :, None]
        c = np.arange(nx)[None, :, None, None] + np.arange(-1, 2)[None, None, None, :]
        valid = (r >= 0) & (r < ny) & (c >= 0) & (c < nx)
        indices = (r * nx + c)[valid].astype(np.int32)
        indptr = np.r_[0, np.cumsum(valid.sum(axis=(2, 3)).ravel())].astype(np.int32)
        return cls((ny, nx), valid, indptr, indices)

    def add_elements(self, S, local, r0: int) -> None:
        """Add the 4 x 4 matrices ``local`` (4, 4, rows, nx - 1) of the elements whose first
        node is in rows ``r0, r0 + 1, ...`` (local nodes :data:`CORNERS`) into ``S``."""
        rows, nx = local.shape[2], self.shape[1]
        for i, (ai, bi) in enumerate(CORNERS):
            for j, (aj, bj) in enumerate(CORNERS):
                S[r0 + ai:r0 + ai + rows, bi:nx - 1 + bi, aj - ai + 1, bj - bi + 1] += \
                    local[i, j]

    def csr(self, S) -> sp.csr_matrix:
        """The ``(n, n)`` CSR matrix of the stencil array ``S`` (sharing the pattern)."""
        n = self.shape[0] * self.shape[1]
        return sp.csr_matrix((S[self.valid], self.indices, self.indptr), shape=(n, n))


def at_points(phi, field, r0: int, r1: int) -> np.ndarray:
    """A nodal ``field`` ``(..., ny, nx)`` interpolated with the corner weights ``phi``
    (4, npoints; corners :data:`CORNERS`) at the points of the pixels whose first node is in
    rows ``r0`` to ``r1 - 1``: ``(npoints, ..., r1 - r0, nx - 1)``."""
    f = np.asarray(field, float)
    nx = f.shape[-1]
    corners = np.stack([f[..., r0 + a:r1 + a, b:nx - 1 + b] for a, b in CORNERS])
    return (phi.T @ corners.reshape(4, -1)).reshape(-1, *corners.shape[1:])


@lru_cache(maxsize=8)
def grid_stencil(shape) -> GridStencil:
    """The (cached) :class:`GridStencil` of the grid ``shape`` (ny, nx)."""
    return GridStencil.of(tuple(shape))


def periodic_unknowns(shape, pinned: int):
    """Unknowns of a periodic cell with one pixel pinned, numbered in the nested-dissection
    order of the torus (fill-reducing, 1.6x faster to factorise than SuperLU's own MMD
    ordering at 256^2): ``free`` (pixel of each unknown) and ``renum`` (unknown of each
    pixel, -1 for the pinned one)."""
    n = shape[0] * shape[1]
    order = nested_dissection_torus(shape)
    free = order[order != pinned]
    renum = np.full(n, -1)
    renum[free] = np.arange(n - 1)
    return free, renum
