"""Reading and writing topographies.

Native formats: ``.npz`` (fem_twin format with pitch, origin, mask and metadata), ``.npy``
(heights only), ASCII matrices (``.txt``, ``.asc``, ``.csv``) and XYZ point lists
(``.xyz``).  Instrument formats (FRT ``.frt``, Sensofar ``.plu``, Gwyddion ``.gwy``,
ISO 25178 ``.x3p``, Digital Surf ``.sur``, Zygo, Wyko, Alicona, ...) are read through the
maintained SurfaceTopography library (optional extra ``fem-twin[instruments]``).
Everything is converted to metres on reading.
"""

from __future__ import annotations

import io
import json
import re
import warnings
import zipfile
from pathlib import Path

import numpy as np

from ..checks import arguments
from ..errors import InputError, MissingFile
from ..topography.core import Topography
from .atomic import atomic_path

FORMAT = "fem_twin.topography/1"
ASCII_SUFFIXES = {".txt", ".asc", ".csv", ".xyz"}
#: Length units as they appear in instrument files, in metres.
UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6, "nm": 1e-9,
         "Å": 1e-10, "A": 1e-10, "pm": 1e-12}
#: Fixed zip timestamp so that writing the same topography twice gives identical bytes.
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)


class TopographyFileError(InputError):
    """A file that cannot be read as a topography (unknown format, corrupt, no data)."""


@arguments(path="path")
def read_topography(path, *, spacing=None, unit: str = "m") -> Topography:
    """Read a topography from ``path`` and return it in SI units.

    Parameters
    ----------
    path : str or Path
    spacing : float or (dx1, dx2), optional
        Pixel pitch [m] for formats that do not store it (``.npy``, plain matrices).
    unit : str
        Unit of heights and coordinates in plain ASCII/``.npy`` files (``m``, ``mm``,
        ``um``, ``nm``); instrument files carry their own units.

    Raises
    ------
    TopographyFileError
        Unknown or corrupt file, or one without valid data.
    """
    path = Path(path)
    if not path.is_file():
        raise MissingFile(f"no such topography file: {path}")
    if unit not in UNITS:
        raise InputError(f"unknown unit {unit!r}; use one of {sorted(UNITS)}")
    reader = READERS.get(path.suffix.lower(), _read_instrument)
    try:
        return reader(path, spacing, UNITS[unit])
    except TopographyFileError:
        raise
    except (ValueError, OSError, KeyError, EOFError, zipfile.BadZipFile) as err:
        raise TopographyFileError(f"cannot read topography from {path}: {err}") from err


@arguments(path="path", topo=Topography)
def write_topography(path, topo: Topography, *, height_scale: float | None = None) -> Path:
    """Write ``topo`` atomically in the format of the suffix (:data:`WRITERS`: .npz, .npy,
    .txt, .asc, .csv, .xyz).

    For ``.npz``, ``height_scale`` [m] stores heights as int32 multiples of that quantum
    (as instruments do), which makes files smaller; rounding error <= height_scale / 2.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    writer = WRITERS.get(suffix)
    if writer is None:
        *others, last = WRITERS
        raise InputError(f"cannot write {suffix!r}; use {', '.join(others)} or {last}")
    with atomic_path(path) as tmp:
        writer(tmp, topo, height_scale)
    return path


# -- native formats ----------------------------------------------------------------------
def _write_npz(path: Path, topo: Topography, height_scale):
    arrays = {"format": np.array(FORMAT), "spacing": np.array(topo.spacing),
              "origin": np.array(topo.origin), "meta": np.array(json.dumps(topo.meta))}
    if height_scale is None:
        arrays["heights"] = topo.heights
    else:
        q = np.round(np.nan_to_num(topo.heights) / height_scale)
        if np.abs(q).max() >= 2 ** 31:
            raise InputError("height_scale too small for int32 storage")
        arrays["heights"] = q.astype(np.int32)
        arrays["height_scale"] = np.array(float(height_scale))
    if topo.mask is not None:
        arrays["mask"] = topo.mask
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for name, arr in arrays.items():
            buf = io.BytesIO()
            np.lib.format.write_array(buf, np.asarray(arr), allow_pickle=False)
            info = zipfile.ZipInfo(f"{name}.npy", date_time=_ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            zf.writestr(info, buf.getvalue())


def topography_shape(path) -> tuple[int, int]:
    """The ``(rows, columns)`` of the height map in ``path``: of a ``.npz`` or ``.npy``
    from its array header, without reading the heights (a case file's maps, checked when it
    is read); of another format by reading it.  :class:`TopographyFileError` for a file
    that does not open as a topography."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".npz", ".npy"):
        return read_topography(path).shape
    try:
        if suffix == ".npy":
            with open(path, "rb") as f:
                return _header_shape(path, f)
        with zipfile.ZipFile(path) as archive, archive.open("heights.npy") as f:
            return _header_shape(path, f)
    except KeyError:
        raise TopographyFileError(f"{path}: .npz has no 'heights' array") from None
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as err:
        raise TopographyFileError(f"cannot read topography from {path}: not a {suffix} of "
                                  f"heights, or damaged ({err})") from err


def _header_shape(path: Path, f) -> tuple[int, int]:
    """The shape in the .npy header at ``f``'s position: a 2D array's."""
    version = np.lib.format.read_magic(f)
    read = (np.lib.format.read_array_header_1_0 if version == (1, 0)
            else np.lib.format.read_array_header_2_0)
    shape, _, _ = read(f)
    if len(shape) != 2:
        raise TopographyFileError(f"{path}: heights of shape {shape}, not a 2D map")
    return shape


def _read_npz(path: Path, spacing, scale) -> Topography:
    try:
        return _read_npz_data(path, spacing, scale)
    except ValueError as err:
        if "pickle" not in str(err):
            raise
        # numpy's hint to unpickle is no advice here
        raise TopographyFileError(f"cannot read topography from {path}: not a .npz of "
                                  "heights (it holds Python objects or is damaged)") from err


def _read_npz_data(path: Path, spacing, scale) -> Topography:
    with np.load(path, allow_pickle=False) as data:
        if "heights" not in data:
            raise TopographyFileError(f"{path}: .npz has no 'heights' array "
                                      f"(found {sorted(data.files)})")
        if "format" in data and str(data["format"]) == FORMAT:
            h = data["heights"].astype(float)
            if "height_scale" in data:
                h = h * float(data["height_scale"])
            mask = data["mask"] if "mask" in data else None
            return Topography(h, tuple(data["spacing"]), mask=mask,
                              origin=tuple(data["origin"]), meta=json.loads(str(data["meta"])))
        # a plain .npz with heights (and possibly spacing) in ``unit``
        sp = data["spacing"] * scale if "spacing" in data else _need_spacing(path, spacing)
        return Topography(data["heights"] * scale, sp, meta={"source": str(path)})


def _read_npy(path: Path, spacing, scale) -> Topography:
    try:
        h = np.load(path, allow_pickle=False)
    except ValueError as err:                     # numpy's hint to unpickle is no advice here
        raise TopographyFileError(f"{path}: not a numeric .npy height map (it holds Python "
                                  "objects or is damaged); save the heights with "
                                  "numpy.save(path, array_of_floats)") from err
    if not np.issubdtype(h.dtype, np.number):
        raise TopographyFileError(f"{path}: .npy holds {h.dtype}, not numbers")
    return Topography(h * scale, _need_spacing(path, spacing), meta={"source": str(path)})


def _write_npy(path: Path, topo: Topography, height_scale=None):
    np.save(path, topo.heights)


def _write_ascii(path: Path, topo: Topography, height_scale=None):
    """A matrix of heights (``,``-separated in a ``.csv``) under a header with the pitch
    and origin."""
    np.savetxt(path, topo.heights, header=_ascii_header(topo),
               delimiter="," if path.suffix.lower() == ".csv" else " ")


def _write_xyz(path: Path, topo: Topography, height_scale=None):
    """One ``x1 x2 height`` row per pixel under the header of :func:`_write_ascii`."""
    x1, x2 = topo.coordinates()
    np.savetxt(path, np.column_stack([x1.ravel(), x2.ravel(), topo.heights.ravel()]),
               header=_ascii_header(topo))


def _ascii_header(topo: Topography) -> str:
    return (f"fem_twin topography; unit = m; spacing = {topo.spacing[0]!r} {topo.spacing[1]!r};"
            f" origin = {topo.origin[0]!r} {topo.origin[1]!r}")


def _read_ascii(path: Path, spacing, scale) -> Topography:
    text = path.read_text(errors="strict")
    header = re.search(r"spacing = (\S+) (\S+); origin = (\S+) (\S+)", text)
    try:
        with warnings.catch_warnings():          # an empty file: refused below, in one line
            warnings.simplefilter("ignore", UserWarning)
            data = np.loadtxt(io.StringIO(text), ndmin=2,
                              delimiter="," if path.suffix.lower() == ".csv" else None)
    except ValueError as err:
        raise TopographyFileError(f"{path}: not a table of heights (expected rows of numbers, "
                                  f"optionally after '#' comment lines): {err}") from err
    if data.size == 0:
        raise TopographyFileError(f"{path}: no numbers in file")
    if path.suffix.lower() == ".xyz":
        return _grid_from_xyz(path, data, scale)
    if header:
        sp, origin = (float(header[1]), float(header[2])), (float(header[3]), float(header[4]))
        return Topography(data, sp, origin=origin, meta={"source": str(path)})
    return Topography(data * scale, _need_spacing(path, spacing), meta={"source": str(path)})


def _grid_from_xyz(path: Path, data: np.ndarray, scale) -> Topography:
    if data.shape[1] != 3:
        raise TopographyFileError(f"{path}: XYZ needs 3 columns, found {data.shape[1]}")
    x, y, z = (data * scale).T
    ux, uy = np.unique(x), np.unique(y)
    if ux.size * uy.size != z.size or ux.size < 2 or uy.size < 2:
        raise TopographyFileError(f"{path}: XYZ points do not form a full regular grid "
                                  f"({ux.size} x {uy.size} coordinates for {z.size} points)")
    dx, dy = np.diff(ux), np.diff(uy)
    if np.ptp(dx) > 1e-6 * dx.mean() or np.ptp(dy) > 1e-6 * dy.mean():
        raise TopographyFileError(f"{path}: XYZ grid is not evenly spaced")
    heights = np.full((uy.size, ux.size), np.nan)
    heights[np.searchsorted(uy, y), np.searchsorted(ux, x)] = z
    return Topography(heights, (dx.mean(), dy.mean()), origin=(ux[0], uy[0]),
                      meta={"source": str(path)})


def _need_spacing(path: Path, spacing):
    if spacing is None:
        raise TopographyFileError(f"{path}: this format does not store the pixel pitch; "
                                  "pass spacing=(dx1, dx2) in metres")
    return spacing


# -- instrument formats via SurfaceTopography ----------------------------------------------
def _read_instrument(path: Path, spacing, scale=None) -> Topography:
    """Any instrument format SurfaceTopography reads; the file carries its own units (the
    ``scale`` of plain formats does not apply)."""
    try:
        from SurfaceTopography import open_topography
        from SurfaceTopography.Exceptions import CannotDetectFileFormat, CorruptFile, ReadFileError
    except ImportError as err:  # pragma: no cover - depends on the installation
        raise TopographyFileError(
            f"{path}: reading instrument files needs SurfaceTopography; "
            "install it with  pip install 'fem-twin[instruments]'") from err
    try:
        reader = open_topography(str(path))
        kwargs = {}
        if reader.default_channel.physical_sizes is None:
            sp = np.broadcast_to(np.asarray(_need_spacing(path, spacing), float), (2,))
            kwargs["physical_sizes"] = tuple(sp * reader.default_channel.nb_grid_pts)
        t = reader.topography(**kwargs)
    except CannotDetectFileFormat as err:
        raise TopographyFileError(f"{path}: not a topography file in any known format "
                                  "(unknown or corrupt)") from err
    except (CorruptFile, ReadFileError) as err:
        raise TopographyFileError(f"{path}: corrupt instrument file: {err}") from err
    if t.dim != 2:
        raise TopographyFileError(f"{path}: holds a {t.dim}D line scan, not a 2D map")
    unit = t.unit
    if unit not in UNITS:
        raise TopographyFileError(
            f"{path}: {type(reader).__name__} found no usable length unit ({unit!r}); the file "
            "is corrupt or not a topography, or its units must be converted first")
    s = UNITS[unit]
    h = t.heights()
    h = np.ma.filled(np.ma.asarray(h, dtype=float), np.nan).T   # (nx, ny) -> (ny, nx)
    nx, ny = t.nb_grid_pts
    sx, sy = t.physical_sizes
    meta = {"source": str(path), "reader": type(reader).__name__, "file_unit": unit}
    return Topography(h * s, (sx * s / nx, sy * s / ny), meta=meta)


#: file suffix -> reader ``(path, spacing, height scale) -> Topography``; any other suffix
#: goes to the instrument readers of SurfaceTopography (the ``instruments`` extra)
READERS = {".npz": _read_npz, ".npy": _read_npy,
           **{suffix: _read_ascii for suffix in ASCII_SUFFIXES}}
#: file suffix -> writer ``(path, topography, height_scale) -> None`` (``height_scale``: the
#: ``.npz`` heights' int32 quantum, or None; the other formats ignore it); no other suffix
#: is written
WRITERS = {".npz": _write_npz, ".npy": _write_npy, ".txt": _write_ascii,
           ".asc": _write_ascii, ".csv": _write_ascii, ".xyz": _write_xyz}
