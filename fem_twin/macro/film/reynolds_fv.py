"""Finite-volume Poiseuille operator of the (homogenised) Reynolds equation, eq 17.

The paper's scheme: node-centred control volumes on the pixel grid, second-order central
fluxes.  The flux through the face between two neighbours is
``width * g_f (A_f grad p)_n`` with ``g_f`` and ``A_f`` the arithmetic means of the two
nodal values; the normal derivative is the two-point difference, the tangential one (for
the off-diagonal entries of ``A``) the mean of the central differences at the two nodes.
The Couette term and the cavitation loop are shared with the FE path
(:mod:`fem_twin.macro.film.reynolds`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ...checks import arguments
from ...numerics.graded_mesh import Mesh


@arguments(g="field", spacing="spacing")
def fvm_poiseuille(g, spacing, A=None) -> sp.csr_matrix:
    """Operator of ``-div(g A grad p)`` times the cell area, non-periodic grid.

    ``g`` is ``(ny, nx)``, ``A`` is ``(ny, nx, 2, 2)`` (identity if None).  Faces between
    two edge nodes only enter the rows of Dirichlet nodes, so the half cells along the
    edges need no special weights (and the tangential differences are only formed where
    both neighbours exist).  On a graded ``Mesh`` a face's width is its dual
    cell's and the normal difference spans the element; the tangential difference over the
    two neighbours spans twice the dual width, so its factor stays 1/4.
    """
    g = np.asarray(g, float)
    ny, nx = g.shape
    across1, across2 = _face_ratios(spacing)
    A = np.broadcast_to(np.eye(2), (ny, nx, 2, 2)) if A is None else np.asarray(A, float)
    idx = np.arange(ny * nx).reshape(ny, nx)
    rows, cols, vals = [], [], []

    def add(r, c, v):
        rows.append(r.ravel())
        cols.append(c.ravel())
        vals.append(v.ravel())

    def gmean(f, sl_a, sl_b):
        return (f[sl_a] + f[sl_b]) / 2

    # x1-faces between (i, j) and (i, j+1): normal part
    ea, eb = (slice(None), slice(None, -1)), (slice(None), slice(1, None))
    c = gmean(g, ea, eb) * gmean(A[..., 0, 0], ea, eb) * across1
    a, b = idx[ea], idx[eb]
    for r, s in ((a, 1), (b, -1)):
        add(r, a, s * c)
        add(r, b, -s * c)
    # x2-faces between (i, j) and (i+1, j): normal part
    na, nb = (slice(None, -1), slice(None)), (slice(1, None), slice(None))
    c = gmean(g, na, nb) * gmean(A[..., 1, 1], na, nb) * across2
    a, b = idx[na], idx[nb]
    for r, s in ((a, 1), (b, -1)):
        add(r, a, s * c)
        add(r, b, -s * c)
    # tangential parts (A12 on x1-faces, A21 on x2-faces), interior rows/columns only
    if np.any(A[..., 0, 1]) or np.any(A[..., 1, 0]):
        fa, fb = (slice(1, -1), slice(None, -1)), (slice(1, -1), slice(1, None))
        c = gmean(g, fa, fb) * gmean(A[..., 0, 1], fa, fb) / 4
        a, b = idx[fa], idx[fb]
        for r, s in ((a, 1), (b, -1)):
            for nbr, sign in ((idx[2:, :-1], 1), (idx[:-2, :-1], -1),
                              (idx[2:, 1:], 1), (idx[:-2, 1:], -1)):
                add(r, nbr, -s * sign * c)
        fa, fb = (slice(None, -1), slice(1, -1)), (slice(1, None), slice(1, -1))
        c = gmean(g, fa, fb) * gmean(A[..., 1, 0], fa, fb) / 4
        a, b = idx[fa], idx[fb]
        for r, s in ((a, 1), (b, -1)):
            for nbr, sign in ((idx[:-1, 2:], 1), (idx[:-1, :-2], -1),
                              (idx[1:, 2:], 1), (idx[1:, :-2], -1)):
                add(r, nbr, -s * sign * c)
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(ny * nx, ny * nx))


def _face_ratios(spacing) -> tuple:
    """Face width over node distance of the x1-faces (ny, nx - 1) and x2-faces (ny - 1,
    nx): ``dx2 / dx1`` and ``dx1 / dx2`` on a grid."""
    if isinstance(spacing, Mesh):
        (h1, h2), (w1, w2) = spacing.sizes, spacing.widths
        return w2[:, None] / h1[None, :], w1[None, :] / h2[:, None]
    dx1, dx2 = spacing
    return dx2 / dx1, dx1 / dx2
