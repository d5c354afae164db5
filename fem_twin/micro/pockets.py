"""Sealed fluid regions of a roughness cell: the net squeeze of each region that contact
spots and boundary films wall in is removed from eq 8's source.

A periodic cell's film splits into regions where contact spots close around them.  The
linear cell problem has no compressibility, no micro-cavitation and no micro-EHL, so a
region's net squeeze (its volume change between instants) must leak through the walls: the
contact spots at the gap floor, whose conductance ``h_floor^3`` is a numerical choice.  The
leak's pressure jump across the wall is then ``1/h_floor^3`` large, and its dissipation in
the pixels that straddle a wall dominates ``s_C`` at random (a factor 4 on the bundled
ball's roughest patch, changing sign under the grid estimate).  Sealed (the default,
``CellSettings.pockets``), each region keeps only the squeeze that redistributes its own
fluid; the volume change goes into the deformation the model leaves out ("Model limits").
``"leaking"`` keeps the paper's source.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

#: the neighbours that share a region: the Q1 element couples diagonal nodes (8), the
#: 5-point finite volumes only the faces' (4)
STRUCTURES = {8: np.ones((3, 3), bool), 4: ndimage.generate_binary_structure(2, 1)}


def fluid_regions(gap, wall: float, connectivity: int = 8) -> np.ndarray:
    """Labels ``(ny, nx)`` of the periodic cell's regions of film thicker than ``wall`` [m]
    (0: the walls, contact spots and boundary films), joined across the cell's edges."""
    fluid = np.asarray(gap) > wall
    labels, count = ndimage.label(fluid, structure=STRUCTURES[connectivity])
    parent = np.arange(count + 1)

    def root(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    shifts = (-1, 0, 1) if connectivity == 8 else (0,)
    for first, last in ((labels[0], labels[-1]), (labels[:, 0], labels[:, -1])):
        for s in shifts:
            other = np.roll(last, s)
            both = (first > 0) & (other > 0)
            for a, b in set(zip(first[both].tolist(), other[both].tolist())):
                ra, rb = root(a), root(b)
                if ra != rb:
                    parent[ra] = rb
    roots = np.array([root(a) for a in range(count + 1)])
    return roots[labels]


def sealed(source, labels) -> np.ndarray:
    """``source`` (a nodal or cell load, shaped like ``labels``) with each region's mean
    removed and zero on the walls: every region's net inflow is zero."""
    source = np.asarray(source, float)
    flat = labels.ravel()
    sums = np.bincount(flat, weights=source.ravel())
    counts = np.bincount(flat)
    out = source.ravel() - sums[flat] / counts[flat]
    return np.where(flat > 0, out, 0.0).reshape(source.shape)
