"""Group ``pin-grading``: where a pin's film would need a fine mesh, and whether a
tensor-product graded mesh (the ball's, ``[macro] mesh = "graded"``) could coarsen the rest.

    FEM_TWIN_BENCH_DIR=DIR python benchmarks/run.py estimate-paper pin-grading

Reads the fields of the ``estimate-paper`` group's reference (the paper pair on a 512² grid,
its 25 speeds at 0.066 Pa s) from ``$FEM_TWIN_BENCH_DIR/paper_reference``.  The indicator of
a Q1 mesh's interpolation error at a node is the sum of the magnitudes of the second
differences of a field along x1 and x2 over the face; rows, per speed: the share of the
face's nodes that carry 90 % of its sum, and the shares of the grid's rows and columns over
the face whose indicator sum exceeds ``LINE_SHARE`` of the largest line's (a tensor-product
mesh refines whole lines), for the total pressure (film and contact) and for the separation
h0.  Baseline: reading the fields.  Checked: the share of the lines a tensor-product mesh
could coarsen (the fewest rows or columns over ``LINE_SHARE`` at any speed, either field)."""

from __future__ import annotations

import os
import time

import numpy as np
from common import Check

DEFAULT = False
#: a line is needed fine when its indicator sum exceeds this share of the largest line's
LINE_SHARE = 0.01


def _indicator(field, face):
    """``|d2f/dx1^2| + |d2f/dx2^2|`` by second differences (pitches squared), zero off the face."""
    d2 = np.zeros_like(field)
    d2[1:-1, :] += np.abs(field[2:, :] - 2 * field[1:-1, :] + field[:-2, :])
    d2[:, 1:-1] += np.abs(field[:, 2:] - 2 * field[:, 1:-1] + field[:, :-2])
    return np.where(face, d2, 0.0)


def _shares(d2, face):
    """(share of the face's nodes with 90 % of the sum, share of rows, share of columns)."""
    v = np.sort(d2[face])[::-1]
    nodes = np.searchsorted(np.cumsum(v), 0.9 * v.sum()) / face.sum()
    lines = [float((s > LINE_SHARE * s.max()).sum() / (s > 0).sum())
             for s in (d2.sum(axis=1), d2.sum(axis=0))]
    return float(nodes), *lines


def run():
    from fem_twin.results import open_run

    folder = os.path.join(os.environ.get("FEM_TWIN_BENCH_DIR", ""), "paper_reference")
    if not os.path.isfile(os.path.join(folder, "fields.nc")):
        return 0.0, [], Check(None, f"no {folder}/fields.nc: run estimate-paper first with "
                                    "FEM_TWIN_BENCH_DIR")
    t0 = time.perf_counter()
    fields = open_run(folder).fields
    rows, fewest = [], 1.0
    for speed in fields.speed.values:
        s = fields.sel(speed=speed).isel(viscosity=0)
        face = s.face.values > 0.5
        notes = []
        for name, f in (("pressure", (s.pressure + s.contact_pressure).values),
                        ("h0", s.h0.values)):
            nodes, rows_, cols = _shares(_indicator(f, face), face)
            fewest = min(fewest, rows_, cols)
            notes.append(f"{name}: 90 % on {nodes:.2f} of the face's nodes, lines over "
                         f"{LINE_SHARE:.0%}: {rows_:.2f} of rows, {cols:.2f} of columns")
        rows.append((f"{speed:.4g} m/s", 0.0, "; ".join(notes)))
    return time.perf_counter() - t0, rows, Check(
        fewest > 0.25, f"a tensor-product mesh must keep at least {fewest:.2f} of the lines "
                       "fine at some speed (more than a quarter)")
