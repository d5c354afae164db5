"""A case file's tables read into their settings dataclasses: each key's declared type,
plausible range and choices (:func:`fem_twin.checks.setting`) checked, the key, the
section and the file named in every refusal (:class:`CaseError`)."""

from __future__ import annotations

import math
from dataclasses import MISSING, fields

from ..checks import check_choice, plausible
from ..errors import InputError


class CaseError(InputError):
    """A case file that is missing, malformed or inconsistent."""


def read_table(data, name, cls, where, positive=False, zero_ok=(), files=None):
    """The table ``name`` of ``data`` (scalars and lists) into the dataclass ``cls`` (lists
    become tuples); the settings declared with a file unit read by ``files(key, value,
    unit)``; ``positive``: numbers without a declared range must be positive (those in
    ``zero_ok`` may be 0)."""
    table = data.get(name, {})
    only(table, {f.name for f in fields(cls)}, f"{where} [{name}]")
    values = {}
    for f in fields(cls):
        if f.name not in table:
            continue
        if f.metadata.get("section"):
            raise CaseError(f"{where} [{name}] {f.name}: set by [{f.metadata['section']}], "
                            "not here")
        _plausible(name, f, table[f.name], where)
        _choice(name, f, table[f.name], where)
        v = table[f.name]
        if files is not None and f.metadata.get("unit", "").startswith("file path"):
            values[f.name] = files(f.name, v, f.metadata["unit"])
            continue
        ranged = f.metadata.get("quantity") is not None     # its range replaces "positive"
        # the declared default: an instance's may be normalised (time_tol 0 -> None)
        default = f.default if f.default is not MISSING else getattr(cls(), f.name)
        if isinstance(default, tuple):
            if not isinstance(v, list) or not all(isinstance(x, (int, float)) for x in v):
                raise CaseError(f"{where} [{name}] {f.name}: expected a list of numbers")
            if default and isinstance(default[0], int) and not all(isinstance(x, int)
                                                                    for x in v):
                raise CaseError(f"{where} [{name}] {f.name}: expected whole numbers, got {v}")
            v = tuple(type(default[0])(x) if default else x for x in v)
            if not all(math.isfinite(x) for x in v):
                raise CaseError(f"{where} [{name}] {f.name}: values must be finite numbers")
            if positive and not ranged and any(x <= 0 for x in v):
                raise CaseError(f"{where} [{name}] {f.name}: values must be positive (SI units)")
        elif isinstance(default, bool):
            if not isinstance(v, bool):
                raise CaseError(f"{where} [{name}] {f.name}: expected true or false")
        elif default is None or isinstance(default, str):
            if not isinstance(v, (str, int)) or isinstance(v, bool):
                raise CaseError(f"{where} [{name}] {f.name}: expected a string")
        elif isinstance(default, (int, float)):
            if not isinstance(v, (int, float)) or isinstance(v, bool):
                raise CaseError(f"{where} [{name}] {f.name}: expected a number (SI units)")
            if isinstance(default, int) and not isinstance(v, int):
                raise CaseError(f"{where} [{name}] {f.name}: expected a whole number, got {v}")
            if not math.isfinite(v):
                raise CaseError(f"{where} [{name}] {f.name}: must be a finite number, got {v}")
            if positive and not ranged and (v < 0 if f.name in zero_ok else v <= 0):
                raise CaseError(f"{where} [{name}] {f.name}: must be positive (SI units)")
            v = type(default)(v) if isinstance(default, float) else v
        values[f.name] = v
    try:
        return cls(**values)
    except CaseError:
        raise
    except InputError as err:            # a rule of the settings themselves (__post_init__)
        raise CaseError(f"{where} [{name}]: {err}") from err


def _plausible(section: str, f, value, where):
    """Refuse a number outside the plausible SI range its declaration names
    (:func:`fem_twin.checks.plausible`), naming the key; other values are the type checks'."""
    quantity = f.metadata.get("quantity")
    values = value if isinstance(value, list) else [value]
    if quantity and values and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                   and math.isfinite(v) for v in values):
        try:
            plausible(f"{where} [{section}] {f.name}", values, quantity)
        except InputError as err:
            raise CaseError(str(err)) from None


def _choice(section: str, f, value, where):
    """Refuse a text setting outside its declared choices (:func:`fem_twin.checks.check_choice`)."""
    try:
        check_choice(f"{where} [{section}] {f.name}", value, f.metadata.get("choices"))
    except InputError as err:
        raise CaseError(str(err)) from None


def only(section, allowed: set, where: str):
    """Refuse a table that is not one, or holds keys outside ``allowed``."""
    if not isinstance(section, dict):
        raise CaseError(f"{where}: expected a table")
    unknown = set(section) - allowed
    if unknown:
        raise CaseError(f"{where}: unknown key(s) {sorted(unknown)}; allowed: {sorted(allowed)}")


def int_pair(value, where: str, minimum: int = 2) -> tuple[int, int]:
    """``value`` as two whole numbers of at least ``minimum``, or :class:`CaseError`."""
    if (not isinstance(value, list) or len(value) != 2
            or not all(isinstance(v, int) and v >= minimum for v in value)):
        raise CaseError(f"{where}: expected two integers >= {minimum}, got {value!r}")
    return (value[0], value[1])
