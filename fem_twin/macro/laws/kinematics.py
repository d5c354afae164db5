"""The disk's velocity over the pin face: a rotating disk, ``u = omega x r``.

The disk turns about an axis at the track radius ``R`` from the face's centre (the pin's
axis), on the ``-x2`` side of the grid, so that at the centre it slides at the sweep's
speed ``u_r`` along ``+x1``.  Relative to ``u_r`` its velocity at ``x`` (from the centre) is

    v(x) = ((R + x2) / R, -x1 / R),

faster outward, turning by ``-atan(x1 / (R + x2))`` (an 8 mm pin at 30 mm: speeds 0.87 to
1.13 u_r, directions within 7.6 degrees).  The flow factors are computed for sliding along
the cell's x1; at a node whose sliding turns by ``phi`` they are rotated into the grid
(``A -> Q A Q^T``, ``b -> Q b``, ``C -> Q C Q^T``, ``d -> Q d``), exact for roughness
whose statistics do not depend on the direction (docs/model.md, "The rotating disk").
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...checks import arguments, as_spacing, plausible
from ...errors import InputError
from ...numerics.graded_mesh import Mesh


@arguments(face="field", spacing="spacing", track_radius="number")
def disk_velocity(face, spacing, track_radius=None) -> np.ndarray | None:
    """``v`` (ny, nx, 2): the disk's velocity over the grid of the pin ``face`` (bool,
    x1 along the columns, pitch ``spacing`` [m]) relative to ``u_r`` [-], the disk's axis
    ``track_radius`` [m] from the face's centroid on the ``-x2`` side; None (uniform
    sliding along x1) when ``track_radius`` is None."""
    if track_radius is None:
        return None
    if not np.isfinite(track_radius) or track_radius <= 0:
        raise InputError(f"track radius must be positive [m], got {track_radius}")
    spacing = as_spacing("spacing", spacing)
    plausible("disk_velocity: spacing [m]", getattr(spacing, "pitch", spacing), "pitch")
    face = np.asarray(face, bool)
    ny, nx = face.shape
    centre = face_centre(face if face.any() else np.ones_like(face), spacing)
    x1, x2 = node_lines(spacing, face.shape)
    x1, x2 = x1 - float(centre[0]), x2 - float(centre[1])
    if track_radius <= np.abs(x2).max():
        raise InputError(f"track radius {track_radius:g} m: the disk's axis lies inside the "
                         "macro grid")
    v = np.empty((ny, nx, 2))
    v[..., 0] = (track_radius + x2[:, None]) / track_radius
    v[..., 1] = -x1[None, :] / track_radius
    return v


def face_centre(face, spacing) -> tuple:
    """The centroid (x1, x2) [m] of the ``face`` nodes (bool grid), from the first node;
    on a graded ``Mesh`` weighted by the nodes' areas."""
    if isinstance(spacing, Mesh):
        x1, x2 = spacing.coordinates
        w = spacing.area * np.asarray(face, bool)
        return float((w * x1[None, :]).sum() / w.sum()), float((w * x2[:, None]).sum() / w.sum())
    rows, cols = np.nonzero(np.asarray(face, bool))
    return float(cols.mean() * spacing[0]), float(rows.mean() * spacing[1])


def node_lines(spacing, shape) -> tuple[np.ndarray, np.ndarray]:
    """``(x1, x2)`` [m] of the node lines of a ``shape`` grid of ``spacing`` (dx1, dx2), or
    of a graded ``Mesh``, from the first node."""
    if isinstance(spacing, Mesh):
        return spacing.coordinates
    return np.arange(shape[1]) * float(spacing[0]), np.arange(shape[0]) * float(spacing[1])


def rotations(v) -> tuple:
    """``(cos phi, sin phi, |v|)`` of each node's sliding direction."""
    speed = np.hypot(v[..., 0], v[..., 1])
    return v[..., 0] / speed, v[..., 1] / speed, speed


def rotate_vector(x, c, s):
    """``Q x`` for vectors ``x`` (..., 2) with ``Q`` the rotation by ``phi``."""
    out = np.empty(np.shape(x))
    out[..., 0] = c * x[..., 0] - s * x[..., 1]
    out[..., 1] = s * x[..., 0] + c * x[..., 1]
    return out


def rotate_tensor(T, c, s):
    """``Q T Q^T`` for tensors ``T`` (..., 2, 2)."""
    QT = np.empty(np.shape(T))
    for j in range(2):
        QT[..., j] = rotate_vector(T[..., j], c, s)        # Q T, column by column
    out = np.empty(np.shape(T))
    for i in range(2):
        out[..., i, :] = rotate_vector(QT[..., i, :], c, s)  # (Q (Q T)^T)^T = Q T Q^T
    return out


def in_grid_frame(loc, turn):
    """The :class:`~fem_twin.micro.LocalFactors` ``loc`` (cell frame: sliding along x1)
    rotated into the grid at each node's sliding direction, ``turn`` the
    :func:`rotations` of the disk's velocity (None: unchanged).
    ``pressure_friction`` and the scalars stay (the Poiseuille friction weight, completed
    isotropically, commutes with rotations: docs/model.md)."""
    if turn is None:
        return loc
    c, s, _ = turn
    moved = {}
    for name, rotate in (("A", rotate_tensor), ("C", rotate_tensor), ("b", rotate_vector),
                         ("d", rotate_vector)):
        x = getattr(loc, name)
        if x is not None:
            moved[name] = rotate(x, c, s)
    return replace(loc, **moved)
