"""The checkpoints of the roughness scale: one JSON file of space-time moments per h0,
named by a hash of the surfaces and the cell settings, which it also records (written
atomically; an unreadable one, or one made for another key or h0, is recomputed)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io.atomic import atomic_path
from ..io.checkpoint import check_made_for, input_key, load_or_none, made_for


def cell_key(z_low, z_up, spacing, settings) -> str:
    """The key of a cell's checkpoints: its surfaces, spacing and settings, and the moments
    a checkpoint holds (:data:`MOMENTS`; an earlier set is another key, recomputed and
    pruned, not a damaged file)."""
    return input_key(np.asarray(z_low), np.asarray(z_up), list(spacing), settings.__dict__,
                     MOMENTS)


def point_path(folder: Path, key: str, h0: float) -> Path:
    return folder / f"{key}_h0_{h0:.9e}.json"


def save_point(folder, key, h0, moments):
    data = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in moments.items()}
    path = point_path(folder, key, h0)
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps({"h0": float(h0), "moments": data, **made_for(key, h0)}))


#: the moments a checkpoint must hold (eqs 11-16)
MOMENTS = ("h", "h3_grad", "h3_g1", "h_grad", "h_g1", "h3_g1g1", "s_c", "h3_g1_pin",
           "p_con", "contact_fraction", "s_thin", "a_thin")


def read_point(path, key=None, h0=None, required=MOMENTS):
    """The moments of an h0 checkpoint; with ``key`` and ``h0``, refused
    (:class:`~fem_twin.errors.ForeignCheckpoint`) unless it was made for them; refused
    (InputError) without the ``required`` moments or with non-finite ones."""
    data = json.loads(path.read_text())
    if key is not None:
        check_made_for(data, key, h0, path)
    moments = {k: (np.array(v) if isinstance(v, list) else v)
               for k, v in data["moments"].items()}
    missing = [k for k in required if k not in moments]
    if missing or not np.all([np.all(np.isfinite(moments[k])) for k in required]):
        raise InputError(f"checkpoint lacks or has non-finite moments {missing or ''}")
    return moments


def load_point(folder, key, h0):
    return load_or_none(point_path(folder, key, h0), lambda p: read_point(p, key, h0))


def prune_checkpoints(folder, keep) -> int:
    """Delete the h0 checkpoints in ``folder`` (and ``folder/coarse``) whose key is not in
    ``keep`` (``FlowFactors.meta["checkpoint_keys"]``): left by other settings or surfaces.
    Returns the number of files removed."""
    removed = 0
    for path in (*Path(folder).glob("*_h0_*.json"), *Path(folder).glob("coarse/*_h0_*.json")):
        if path.name.split("_h0_")[0] not in keep:
            path.unlink()
            removed += 1
    return removed
