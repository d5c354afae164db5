"""Repair of measurement defects by harmonic (Laplace) interpolation (paper 2.2.1)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..checks import arguments
from ..errors import InputError
from .core import Topography

#: the fraction of measured pixels below which a map is refused, not filled
MIN_VALID = 0.01


@arguments(topo=Topography)
def fill_defects(topo: Topography) -> Topography:
    """Fill invalid pixels with the solution of the Laplace equation.

    The missing heights z solve ``d2z/dx1^2 + d2z/dx2^2 = 0`` (5-point stencil weighted by
    the pixel pitch) with the valid pixels as Dirichlet data and zero normal derivative
    where a hole touches the edge of the map, as Gwyddion's "Laplace" defect removal does.
    The stencil is exact for harmonic polynomials up to degree 3.

    Returns a new, fully valid :class:`Topography`; raises :class:`~fem_twin.errors.InputError`
    for a map with fewer than ``MIN_VALID`` (1 %) or 3 measured pixels.
    """
    if topo.mask is None:
        return topo
    valid = int(topo.mask.sum())
    if valid < max(3, MIN_VALID * topo.mask.size):
        raise InputError(f"only {valid} of {topo.mask.size} pixels hold a height: too few to "
                         f"fill the defects from (at least {MIN_VALID:.0%} and 3 are needed)")
    ny, nx = topo.shape
    holes = ~topo.mask
    z = np.where(topo.mask, topo.heights, 0.0)
    index = np.full(topo.shape, -1, dtype=np.int64)
    n = int(holes.sum())
    index[holes] = np.arange(n)
    i2, i1 = np.nonzero(holes)
    w1, w2 = 1.0 / topo.spacing[0] ** 2, 1.0 / topo.spacing[1] ** 2

    rows, cols, vals = [], [], []
    diag = np.zeros(n)
    rhs = np.zeros(n)
    me = index[i2, i1]
    for d2, d1, w in ((0, 1, w1), (0, -1, w1), (1, 0, w2), (-1, 0, w2)):
        j2, j1 = i2 + d2, i1 + d1
        inside = (j2 >= 0) & (j2 < ny) & (j1 >= 0) & (j1 < nx)
        diag[inside] += w
        jj2, jj1, mine = j2[inside], j1[inside], me[inside]
        other = index[jj2, jj1]
        unknown = other >= 0
        rows.append(mine[unknown])
        cols.append(other[unknown])
        vals.append(np.full(unknown.sum(), -w))
        np.add.at(rhs, mine[~unknown], w * z[jj2[~unknown], jj1[~unknown]])
    rows.append(np.arange(n))
    cols.append(np.arange(n))
    vals.append(diag)
    a = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(n, n))
    filled = z.copy()
    filled[holes] = spla.spsolve(a.tocsc(), rhs)
    return topo.with_heights(filled, mask=None,
                             meta=topo.with_history(f"fill_defects(laplace, {n} px)"))
