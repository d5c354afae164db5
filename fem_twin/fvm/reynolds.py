"""Finite-volume Poiseuille operator of the Reynolds equation (the paper's scheme).

Node-centred control volumes on the pixel grid; the flux through the face between two
neighbours is ``g_f (p_i - p_j) * width / distance`` with ``g_f`` the arithmetic mean of the
two nodal coefficients (second-order central).  The Couette term and the cavitation loop are
shared with the FE path (:mod:`fem_twin.macro.reynolds`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def fvm_poiseuille(g, spacing) -> sp.csr_matrix:
    """5-point operator of ``-div(g grad p)`` times the cell area, non-periodic grid.

    Faces between two edge nodes only enter the rows of Dirichlet nodes, so the half cells
    along the edges need no special weights.
    """
    g = np.asarray(g, float)
    ny, nx = g.shape
    dx1, dx2 = spacing
    idx = np.arange(ny * nx).reshape(ny, nx)
    rows, cols, vals = [], [], []
    for a, b, ga, gb, w in ((idx[:, :-1], idx[:, 1:], g[:, :-1], g[:, 1:], dx2 / dx1),
                            (idx[:-1, :], idx[1:, :], g[:-1, :], g[1:, :], dx1 / dx2)):
        c = (ga + gb).ravel() / 2 * w
        a, b = a.ravel(), b.ravel()
        rows += [a, b, a, b]
        cols += [a, b, b, a]
        vals += [c, c, -c, -c]
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(ny * nx, ny * nx))
