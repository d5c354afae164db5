"""CSV tables of a run: one writer, with each column's SI unit in its header name.

A header names the quantity and ends in its SI unit (``speed_m_s``, ``h0_m``, ``p_con_Pa``,
``viscosity_Pa_s``, ``friction_force_N``); dimensionless columns carry no suffix.  Floats
are written with 10 significant digits, integers and strings as they are.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from ..errors import InputError
from .atomic import atomic_path


def write_csv(path, columns: dict) -> Path:
    """Write ``columns`` (header name -> 1D sequence, all of one length) atomically."""
    path = Path(path)
    values = [list(v) for v in columns.values()]
    if len({len(v) for v in values}) > 1:
        raise InputError(f"columns of {path.name} differ in length: "
                         f"{ {k: len(v) for k, v in zip(columns, values)} }")
    with atomic_path(path) as tmp:
        with open(tmp, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(list(columns))
            w.writerows([_cell(v) for v in row] for row in zip(*values))
    return path


def _cell(v) -> str:
    if isinstance(v, (float, np.floating)):
        return f"{v:.10g}"
    return str(v)
