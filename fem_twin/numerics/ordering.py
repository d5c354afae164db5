"""Fill-reducing orders of the pixels of a grid (geometric nested dissection).

Sparse LU of the 5- and 9-point operators on pixel grids is fastest in these orders:
rectangles are bisected recursively along their longer side and the separators come last.
Used by the periodic cell problems (torus) and the macro Reynolds problem (open grid).
"""

from __future__ import annotations

import numpy as np

from ..errors import SolverError

#: the pieces a sub-grid's order (:func:`subgrid_order`) stops bisecting at (2 is as fast
#: as 4 or faster for both solvers, measured on the macro Newton matrices to 2048^2;
#: ``python benchmarks/run.py amg`` times both solvers in this order)
SUBGRID_LEAF = 2
#: the deepest bisection whose base-3 keys fit in 64 bits (sides up to about 2^19 pixels)
MAX_DEPTH = 39


def _dissect(rows, cols, nx, out, leaf):
    """Append the nested-dissection order of the rectangle ``rows`` x ``cols`` (contiguous
    ranges) of a grid ``nx`` wide to ``out``: both halves, then the separator, recursively
    bisected along the longer side until at most ``leaf`` x ``leaf`` pixels or a side below
    3 remain (each piece row-major).  The boxes of one depth are split at once; each piece
    gets a base-3 key, one digit per depth (0 first half, 1 second half, 2 separator,
    padded with 0 below where it stops), and the pieces follow in the order of their keys
    (a 2048^2 grid in 0.3 s instead of 4.8 s for a recursion)."""
    box = [np.array([v]) for v in (rows[0], len(rows), cols[0], len(cols), 0, 0)]
    pieces = []
    for _ in range(MAX_DEPTH + 1):
        h, w = box[1], box[3]
        split = (h * w > leaf * leaf) & (np.minimum(h, w) >= 3)
        pieces.append([v[~split] for v in box])
        if not split.any():
            break
        r0, h, c0, w, key, depth = (v[split] for v in box)
        across = w >= h                               # split the columns
        length = np.where(across, w, h)
        m = length // 2
        starts = [np.zeros_like(m), m + 1, m]         # first half, second half, separator
        lengths = [m, length - m - 1, np.ones_like(m)]
        halves = [[np.where(across, r0, r0 + s), np.where(across, h, n),
                   np.where(across, c0 + s, c0), np.where(across, n, w)]
                  for s, n in zip(starts, lengths)]
        pieces.append([*halves[2], 3 * key + 2, depth + 1])
        box = [np.concatenate(v) for v in zip(*(
            [*halves[d], 3 * key + d, depth + 1] for d in (0, 1)))]
    else:
        raise SolverError("nested dissection deeper than its keys hold")
    r0, h, c0, w, key, depth = (np.concatenate(v) for v in zip(*pieces))
    sort = np.argsort(key * 3 ** (depth.max() - depth))
    r0, h, c0, w = r0[sort], h[sort], c0[sort], w[sort]
    counts = h * w
    piece = np.repeat(np.arange(counts.size), counts)
    k = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    out.append((r0[piece] + k // w[piece]) * nx + c0[piece] + k % w[piece])


def is_permutation(order, n: int) -> bool:
    """Whether ``order`` holds each of ``0`` to ``n - 1`` exactly once."""
    order = np.asarray(order)
    return order.size == n and bool(np.all(np.bincount(order, minlength=n) == 1))


def _checked(out, n):
    order = np.concatenate(out)
    if not is_permutation(order, n):                # guard against a wrong partition
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


def subgrid_order(shape, position, leaf: int = SUBGRID_LEAF) -> np.ndarray:
    """The unknowns of a subset of the pixels of a non-periodic ``(ny, nx)`` grid in the
    order of :func:`nested_dissection` (the subset's unknown numbers; ``position``: each
    pixel's number, flat, -1 outside the subset).  For a pin face inside its grid, PARDISO
    factorises the macro Newton matrices in this order faster than in METIS's on large grids
    (0.67x at 2048^2), with less fill and a quarter of the analysis time."""
    order = np.asarray(position)[nested_dissection(shape, leaf)]
    return order[order >= 0]
