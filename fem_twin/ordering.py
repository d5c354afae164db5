"""Fill-reducing orders of the pixels of a grid (geometric nested dissection).

Sparse LU of the 5- and 9-point operators on pixel grids is fastest in these orders:
rectangles are bisected recursively along their longer side and the separators come last.
Used by the periodic cell problems (torus) and the macro Reynolds problem (open grid).
"""

from __future__ import annotations

import numpy as np

from .errors import SolverError


def _dissect(rows, cols, nx, out, leaf):
    if len(rows) * len(cols) <= leaf * leaf or min(len(rows), len(cols)) < 3:
        out.append((rows[:, None] * nx + cols[None, :]).ravel())
    elif len(cols) >= len(rows):
        m = len(cols) // 2
        _dissect(rows, cols[:m], nx, out, leaf)
        _dissect(rows, cols[m + 1:], nx, out, leaf)
        out.append(rows * nx + cols[m])
    else:
        m = len(rows) // 2
        _dissect(rows[:m], cols, nx, out, leaf)
        _dissect(rows[m + 1:], cols, nx, out, leaf)
        out.append(rows[m] * nx + cols)


def _checked(out, n):
    order = np.concatenate(out)
    if order.size != n or np.unique(order).size != n:   # guard against a wrong partition
        raise SolverError("nested dissection lost or repeated pixels")
    return order


def nested_dissection(shape, leaf: int = 4) -> np.ndarray:
    """Order of the pixels (flat indices) of a non-periodic ``(ny, nx)`` grid."""
    ny, nx = shape
    out = []
    _dissect(np.arange(ny), np.arange(nx), nx, out, leaf)
    return _checked(out, ny * nx)


def nested_dissection_torus(shape, leaf: int = 4) -> np.ndarray:
    """Order of the pixels of a periodic grid.

    Columns 0 and nx/2 and then rows 0 and ny/2 cut the torus into four open rectangles,
    which are dissected as in :func:`nested_dissection`; the cuts come last.
    """
    ny, nx = shape
    out = []
    cy, cx = ny // 2, nx // 2
    for cols in (np.arange(1, cx), np.arange(cx + 1, nx)):
        for rows in (np.arange(1, cy), np.arange(cy + 1, ny)):
            if len(rows) and len(cols):
                _dissect(rows, cols, nx, out, leaf)
        out.append(cols)                          # row 0
        out.append(cy * nx + cols)                # row ny/2
    out.append(np.unique(np.r_[np.arange(ny) * nx, np.arange(ny) * nx + cx]))
    return _checked(out, ny * nx)
