"""Case files (TOML): what to simulate, validated with clear errors.  SI units throughout."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path

from .topography.prepare import MacroOptions


class CaseError(ValueError):
    """A case file that is missing, malformed or inconsistent."""


@dataclass(frozen=True)
class Geometry:
    """Measured topography files (paths relative to the case file are resolved)."""

    pins: tuple[Path, ...]
    disks: tuple[Path, ...] = ()
    patches: tuple[tuple[Path, Path], ...] = ()   # (pin patch, disk patch) pairs
    patch_shape: tuple[int, int] = (256, 256)
    patch_start: tuple[int, int] = (0, 0)


@dataclass(frozen=True)
class Case:
    """A whole case: geometry sources and the macroscopic reconstruction settings."""

    name: str
    geometry: Geometry
    macro_geometry: MacroOptions = field(default_factory=MacroOptions)
    source: Path | None = None


def load_case(path) -> Case:
    """Read and validate a TOML case file."""
    path = Path(path)
    if not path.is_file():
        raise CaseError(f"case file not found: {path}")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise CaseError(f"{path}: not valid TOML: {err}") from err
    return parse_case(data, base=path.parent, source=path)


def parse_case(data: dict, base: Path = Path("."), source: Path | None = None) -> Case:
    """Validate a case given as a dict (as read from TOML)."""
    where = str(source or "case")
    _only(data, {"name", "geometry", "preprocessing"}, where)
    if "geometry" not in data:
        raise CaseError(f"{where}: missing [geometry] section")
    g = data["geometry"]
    _only(g, {"pins", "disks", "patches", "patch_shape", "patch_start"}, f"{where} [geometry]")

    def files(key, value):
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise CaseError(f"{where} [geometry] {key}: expected a list of file paths")
        out = tuple((base / v).resolve() for v in value)
        for p in out:
            if not p.is_file():
                raise CaseError(f"{where} [geometry] {key}: file not found: {p}")
        return out

    if "pins" not in g or not g["pins"]:
        raise CaseError(f"{where} [geometry]: at least one pin file is required in 'pins'")
    patches = g.get("patches", [])
    if not isinstance(patches, list) or not all(isinstance(p, list) and len(p) == 2 for p in patches):
        raise CaseError(f"{where} [geometry] patches: expected a list of [pin, disk] file pairs")
    geometry = Geometry(
        pins=files("pins", g["pins"]), disks=files("disks", g.get("disks", [])),
        patches=tuple(files("patches", p) for p in patches),
        patch_shape=_int_pair(g.get("patch_shape", [256, 256]), f"{where} [geometry] patch_shape"),
        patch_start=_int_pair(g.get("patch_start", [0, 0]), f"{where} [geometry] patch_start", 0))
    if geometry.disks and len(geometry.disks) != len(geometry.pins):
        raise CaseError(f"{where} [geometry]: {len(geometry.pins)} pins but "
                        f"{len(geometry.disks)} disks (give one disk per pin, or none for flat)")

    pre = data.get("preprocessing", {})
    known = {f.name for f in fields(MacroOptions)}
    _only(pre, known, f"{where} [preprocessing]")
    opts = dict(pre)
    if "resolution" in opts:
        opts["resolution"] = _int_pair(opts["resolution"], f"{where} [preprocessing] resolution")
    for key in ("fwhm_px", "clip", "truncation", "holder_height", "level_radius"):
        if key in opts and not isinstance(opts[key], (int, float)):
            raise CaseError(f"{where} [preprocessing] {key}: expected a number (SI units)")
    if opts.get("clip", 1) <= 0 or opts.get("clip", 0) > 1e-3:
        raise CaseError(f"{where} [preprocessing] clip: expected metres in (0, 1e-3], "
                        f"got {opts['clip']} (20 um is 20e-6)")
    if opts.get("fwhm_px", 0) < 0:
        raise CaseError(f"{where} [preprocessing] fwhm_px must be >= 0 pixels")
    return Case(name=str(data.get("name", source.stem if source else "case")),
                geometry=geometry, macro_geometry=MacroOptions(**opts), source=source)


def _only(section, allowed: set, where: str):
    if not isinstance(section, dict):
        raise CaseError(f"{where}: expected a table")
    unknown = set(section) - allowed
    if unknown:
        raise CaseError(f"{where}: unknown key(s) {sorted(unknown)}; allowed: {sorted(allowed)}")


def _int_pair(value, where: str, minimum: int = 2) -> tuple[int, int]:
    if (not isinstance(value, list) or len(value) != 2
            or not all(isinstance(v, int) and v >= minimum for v in value)):
        raise CaseError(f"{where}: expected two integers >= {minimum}, got {value!r}")
    return (value[0], value[1])
