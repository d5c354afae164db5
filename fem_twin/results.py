"""A run's results as data: xarray Datasets with coordinates and units, in NetCDF files.

``fem-twin run`` writes ``OUT/results.nc`` (groups ``flow_factors`` and ``stribeck``, the run's
settings and error estimates in attributes) and ``OUT/fields.nc`` (the macro fields of every
Stribeck point over (viscosity, speed, x2, x1)); :func:`open_run` reads them back.  Engine:
h5netcdf (NetCDF-4 on h5py, BSD-3; groups and compression without the netCDF-C library).
Units are in each variable's ``units`` attribute, SI throughout.
"""

from __future__ import annotations

import gc
import json
import os
import re
import sys
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .checks import arguments
from .errors import FileSystemError, InputError, MissingFile
from .io.atomic import atomic_path
from .io.layout import RunLayout
from .macro.coupling.result import FIELDS
from .macro.estimate import PARTS
from .macro.laws.kinematics import node_lines
from .micro.flow_factors import FlowFactors
from .stribeck.curve import BOUNDARY_SHARE, LEGACY, OPTIONAL, UNITS, StribeckCurve

ENGINE = "h5netcdf"
#: ``fields.nc``'s variables and units: an operating point's fields
#: (:data:`fem_twin.macro.coupling.result.FIELDS`), its piezoviscous viscosity as
#: ``local_viscosity`` (``viscosity`` is the coordinate mu_0 of the sweep)
FIELD_UNITS = {("local_viscosity" if k == "viscosity" else k): u for k, u in FIELDS.items()}

@dataclass(frozen=True)
class RunResults:
    """What :func:`open_run` returns: ``flow_factors`` over (patch, h0), ``stribeck`` over
    (viscosity, speed), ``fields`` over (viscosity, speed, x2, x1) (None when the run kept no
    fields), ``summary`` (the run's ``summary.json``: settings, timings, error estimates)."""

    flow_factors: object
    stribeck: object
    fields: object
    summary: dict


@arguments(factors=[FlowFactors], labels=[str])
def flow_factor_dataset(factors, labels):
    """Flow factors of several patches as a Dataset over (patch, h0), h0 the union of their
    samples: NaN where a patch's adaptive sample skipped an h0 (its interpolant,
    ``FlowFactors.at``, reads it there); A, b, C, d and the friction tensor C_F split into
    named components (A11, A12, ..., d2), the friction factors as sC, fP1 and fP2, the
    local shear's spread as film_fraction and log_sC."""
    import xarray as xr
    h0 = np.unique(np.concatenate([f.h0 for f in factors]))
    where = [np.searchsorted(h0, f.h0) for f in factors]

    def stack(name):
        out = np.full((len(factors), h0.size) + getattr(factors[0], name).shape[1:], np.nan)
        for k, (f, idx) in enumerate(zip(factors, where)):
            out[k, idx] = getattr(f, name)
        return out
    data = {"h_m": (stack("h_m"), "m", "mean gap (eq 12)"),
            "p_con": (stack("p_con"), "Pa", "mean contact pressure (eq 11)"),
            "contact_fraction": (stack("contact_fraction"), "1", "pixels in contact")}
    for name, eq in (("A", 13), ("C", 15)):
        for i in range(2):
            for j in range(2):
                data[f"{name}{i + 1}{j + 1}"] = (stack(name)[:, :, i, j], "1", f"eq {eq}")
    for name, eq in (("b", 14), ("d", 16)):
        for i in range(2):
            data[f"{name}{i + 1}"] = (stack(name)[:, :, i], "1", f"eq {eq}")
    data["sC"] = (stack("friction_factor"), "1", "Couette friction on the pin, mu u_r s_C / h_m")
    for i in range(2):
        data[f"fP{i + 1}"] = (stack("pressure_friction")[:, :, i], "1",
                              "Poiseuille friction on the pin, -(h_m / 2) fP . grad p")
    data["film_fraction"] = (stack("film_fraction"), "1", "share of the cell whose film "
                             "carries film friction (thicker than the boundary film)")
    data["log_sC"] = (stack("log_friction"), "1", "log mean of the local dissipation over "
                      "that film, h_m s (the Eyring film's spread)")
    ds = xr.Dataset({k: (("patch", "h0"), v, {"units": u, "long_name": n})
                     for k, (v, u, n) in data.items()},
                    coords={"patch": list(labels), "h0": ("h0", h0, {"units": "m"})})
    ds.attrs["error_estimate"] = json.dumps(factors[-1].meta.get("error_estimate", {}))
    return ds


@arguments(curves=[StribeckCurve], patch_curves=(list, tuple))
def stribeck_dataset(curves, patch_curves=None):
    """Stribeck curves as a Dataset over (viscosity, speed) (NaN where a curve has no point);
    ``patch_curves``: optional single-patch curves [patch][viscosity] (same speeds), as
    ``patch_friction_coefficient`` over (patch, viscosity, speed) and its band, ``cf_min``
    and ``cf_max`` over the patches."""
    import xarray as xr
    speed = np.unique(np.concatenate([c.speed for c in curves]))
    mu = np.array([c.viscosity for c in curves])
    out = {}
    for k in UNITS:
        if k not in ("cf_min", "cf_max"):
            out[k] = np.full((mu.size, speed.size), np.nan)
            for i, c in enumerate(curves):
                out[k][i, np.searchsorted(speed, c.speed)] = getattr(c, k)
    coords = {"viscosity": ("viscosity", mu, {"units": "Pa s"}),
              "speed": ("speed", speed, {"units": "m/s"})}
    if patch_curves and any(len(per_mu) != len(curves) for per_mu in patch_curves):
        raise InputError("stribeck_dataset: patch_curves holds, for each patch, one curve per "
                         f"viscosity of curves ({len(curves)}), at the run's speeds")
    if patch_curves:
        cf = np.full((len(patch_curves), mu.size, speed.size), np.nan)
        for p, per_mu in enumerate(patch_curves):
            for i, c in enumerate(per_mu):
                cf[p, i, np.searchsorted(speed, c.speed)] = c.friction_coefficient
        out["cf_min"], out["cf_max"] = cf.min(axis=0), cf.max(axis=0)
        coords["patch"] = [str(p + 1) for p in range(len(patch_curves))]
    ds = xr.Dataset({k: (("viscosity", "speed"), v, {"units": UNITS[k][0],
                                                     "long_name": UNITS[k][1]})
                     for k, v in out.items()}, coords=coords)
    if patch_curves:
        ds["patch_friction_coefficient"] = (("patch", "viscosity", "speed"), cf, {
            "units": "1", "long_name": "C_f with one patch's flow factors"})
    share = np.full((mu.size, speed.size), np.nan)
    for i, c in enumerate(curves):
        share[i, np.searchsorted(speed, c.speed)] = c.boundary_share
    ds[BOUNDARY_SHARE[0]] = (("viscosity", "speed"), share, {"units": BOUNDARY_SHARE[1],
                                                             "long_name": BOUNDARY_SHARE[2]})
    for name, (_, unit, meaning) in OPTIONAL.items():
        if any(getattr(c, name) is not None for c in curves):
            v = np.full((mu.size, speed.size), np.nan)
            for i, c in enumerate(curves):
                if getattr(c, name) is not None:
                    v[i, np.searchsorted(speed, c.speed)] = getattr(c, name)
            ds[name] = (("viscosity", "speed"), v, {"units": unit, "long_name": meaning})
    if any(c.friction_error is not None for c in curves):
        parts = {"cf_err": "total"} | ({f"cf_err_{p}": p for p in PARTS} if any(
            c.friction_error_parts for c in curves) else {})   # a CSV's curves: total only
        for name, part in parts.items():
            v = np.full((mu.size, speed.size), np.nan)
            for i, c in enumerate(curves):
                value = _error_part(c, part)
                if value is not None:
                    v[i, np.searchsorted(speed, c.speed)] = value
            ds[name] = (("viscosity", "speed"), v, {
                "units": "1", "long_name": f"estimated discretisation error of C_f, {part}"
                + (" (fem_twin.macro.estimate)" if part == "total" else " part")})
    return ds


def _error_part(curve, part: str):
    """The estimated C_f error of ``curve`` [-] in total or its ``part``, or None where the
    curve has none (a curve read back from a CSV keeps the total only)."""
    if part == "total":
        return curve.friction_error
    return (curve.friction_error_parts or {}).get(part)


@arguments(sweeps=[tuple], origin="pair")
def fields_dataset(sweeps, origin=(0.0, 0.0)):
    """Macro fields of the points of ``sweeps``, ``[(viscosity, {speed: MixedResult})]``
    (one entry per sweep, in the run's order), as a Dataset over (viscosity, speed, x2,
    x1); the coordinate ``viscosity`` is mu_0 of the sweep, the field ``local_viscosity``
    the piezoviscous mu(p) of eq 23."""
    import xarray as xr
    points = {(mu, u): res for mu, sweep in sweeps for u, res in sweep.items()}
    mus = np.unique([mu for mu, _ in sweeps])
    speeds = np.unique([k[1] for k in points])
    first = next(iter(points.values()))
    ny, nx = first.pressure.shape
    x1, x2 = node_lines(first.spacing, (ny, nx))         # a grid's or a graded mesh's
    fields = {k: np.full((mus.size, speeds.size, ny, nx), np.nan) for k in FIELD_UNITS}
    for (mu, u), res in points.items():
        i, j = np.searchsorted(mus, mu), np.searchsorted(speeds, u)
        for k, v in res.fields().items():
            fields["local_viscosity" if k == "viscosity" else k][i, j] = v
    coords = {"viscosity": ("viscosity", mus, {"units": "Pa s"}),
              "speed": ("speed", speeds, {"units": "m/s"}),
              "x2": ("x2", origin[1] + x2, {"units": "m"}),
              "x1": ("x1", origin[0] + x1, {"units": "m"})}
    return xr.Dataset({k: (("viscosity", "speed", "x2", "x1"), v, {"units": FIELD_UNITS[k]})
                       for k, v in fields.items()}, coords=coords)


@arguments(path="path", groups=dict)
def write_netcdf(path, groups: dict, attrs: dict | None = None) -> Path:
    """Datasets {group: Dataset} into one NetCDF-4 file, atomically (zlib level 1 after a
    byte shuffle, lossless: faster and smaller than level 4 without it); the group None is
    the file's root."""
    path = Path(path)
    with atomic_path(path) as tmp, _write_errors(path):
        mode = "w"
        for name, ds in groups.items():
            ds = ds.copy()
            ds.attrs.update(attrs or {})
            enc = {v: {"zlib": True, "complevel": 1, "shuffle": True} for v in ds.data_vars}
            ds.to_netcdf(tmp, mode=mode, group=name, engine=ENGINE, encoding=enc)
            mode = "a"
    return path


@contextmanager
def _write_errors(path):
    """A failed NetCDF write as one :class:`FileSystemError` (an OSError) with its errno (a
    full disk: ENOSPC): h5py reports it as a RuntimeError or OSError whose text carries
    ``errno = N``, and the HDF5 objects it frees afterwards print their own tracebacks
    (through ``sys.excepthook`` and ``sys.unraisablehook``), which this drops for the
    write's duration."""
    hooks = sys.excepthook, sys.unraisablehook
    sys.excepthook, sys.unraisablehook = (lambda *args: None), (lambda unraisable: None)
    try:
        yield
    except (RuntimeError, OSError) as err:
        found = re.search(r"errno = (\d+)", str(err))
        gc.collect()                                    # the failed write's objects, quietly
        if found is None:
            raise
        code = int(found.group(1))
        raise FileSystemError(code, f"{os.strerror(code)}: writing {path.name}") from None
    finally:
        sys.excepthook, sys.unraisablehook = hooks


@arguments(outdir="path")
def open_run(outdir) -> RunResults:
    """The results of a run's output folder as xarray Datasets (loaded in memory; the fields
    lazily): what ``fem-twin run CASE -o OUTDIR`` wrote."""
    import xarray as xr
    out = RunLayout(outdir)
    path = out.results
    if not path.is_file():
        raise MissingFile(f"{path}: no results; run `fem-twin run CASE -o {outdir}` "
                                "first")
    with _damaged(outdir):
        fields = (xr.open_dataset(out.fields_nc, engine=ENGINE) if out.fields_nc.is_file()
                  else None)
        summary = json.loads(out.summary.read_text()) if out.summary.is_file() else {}
        stribeck, factors = (xr.load_dataset(path, group=group, engine=ENGINE)
                             for group in ("stribeck", "flow_factors"))
    stribeck = stribeck.rename({k: v for k, v in LEGACY.items() if k in stribeck.data_vars})
    return RunResults(factors, stribeck, fields, summary)


@contextmanager
def _damaged(outdir):
    """A results file that cannot be read (truncated, not NetCDF, a damaged summary.json)
    as one :class:`InputError` naming the fix."""
    try:
        yield
    except (OSError, ValueError, KeyError) as err:
        first = str(err).splitlines()[0] if str(err) else type(err).__name__
        raise InputError(f"{outdir}: its results cannot be read ({first[:120]}); run the "
                         "same `fem-twin run` command again to rewrite them") from None
