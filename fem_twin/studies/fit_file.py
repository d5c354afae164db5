"""The ``fit.json`` of ``fem-twin fit`` read back: checked before a report, a prediction or
``run --from-fit`` uses it."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np

from ..checks import OFF_AT_ZERO, QUANTITIES, plausible
from ..errors import InputError
from ..macro.laws.boundary_laws import LAWS
from ..macro.laws.viscosity import WaltherLaw
from ..stribeck.fit import parameters

#: the plausible quantity (:data:`fem_twin.checks.QUANTITIES`) of each fitted value but the
#: temperatures: the fit's own and the boundary laws' (their ``fitted``)
QUANTITY = {"load_share": "load_share", "bulk_resistance": "thermal_resistance"}


def temperature_offset(result: dict) -> float | None:
    """Mean fitted contact temperature minus the nominal oil temperature [K] (None when no
    temperature was fitted)."""
    fitted = [k for k in result["fit"]["parameters"] if k.startswith("temperature_")]
    if not fitted:
        return None
    nominal = result["case"]["temperatures"]
    return float(np.mean([result[k]["value"] - t for k, t in zip(fitted, nominal)]))


def read_fit(path) -> dict:
    """A ``fit.json`` of ``fem-twin fit``, checked for what :func:`apply_fit` reads
    (:func:`check_fit`)."""
    try:
        result = json.loads(Path(path).read_text())
    except (OSError, ValueError) as err:
        raise InputError(f"{path}: not a fit.json of fem-twin fit ({err}); run fem-twin fit "
                         "again to rewrite it") from None
    return check_fit(result, str(path))


def check_fit(result, where: str = "fit") -> dict:
    """``result`` (a ``fit.json``'s content) with its fitted values as numbers, or
    :class:`InputError` naming ``where``: a known parameter set, values inside the case
    parser's ranges, a contact temperature within 100 K of the oil's."""
    fit = result.get("fit") if isinstance(result, dict) else None
    params = fit.get("parameters") if isinstance(fit, dict) else None
    if not isinstance(params, list) or not all(isinstance(k, str) for k in params):
        raise InputError(f"{where}: not a fit.json of fem-twin fit (its fit.parameters must "
                         f"be a list of names, got {params!r}); run fem-twin fit again to "
                         "rewrite it")
    try:
        result["case"]["temperatures"]
        known = {**QUANTITY, **{name: fitted.quantity for law in LAWS.values()
                                for name, fitted in law.fitted.items()}}
        quantity = {name: known[name] for name in parameters() if name in known}
        unknown = [k for k in params if k not in parameters()
                   and not re.fullmatch(r"temperature_[1-9][0-9]*", k)]
        values = {k: float(result[k]["value"]) for k in quantity if k in result}
        offset = temperature_offset(result)
        law = None if offset is None else WaltherLaw(**result["case"]["law"])
        law is None or float(law.viscosity(20.0))
    except (ValueError, KeyError, TypeError, IndexError) as err:
        raise InputError(f"{where}: not a fit.json of fem-twin fit ({err!r}); run fem-twin "
                         "fit again to rewrite it") from err
    if unknown:
        raise InputError(f"{where}: unknown fitted parameter(s) {unknown}; fem-twin fit writes "
                         f"{', '.join(parameters())} and temperature_K")
    for name, value in values.items():          # the case parser's ranges
        off = quantity[name] in OFF_AT_ZERO     # below its floor (tau_0: 10 kPa), none
        if off and 0 <= value < QUANTITIES[quantity[name]][0]:
            value = 0.0                         # the data can tell
        plausible(f"{where} {name}", value, quantity[name])
        result[name]["value"] = value           # a number, whatever the file spelled
    if offset is not None and not -100.0 <= offset <= 100.0:
        raise InputError(f"{where}: the fitted contact temperature lies {offset:+.3g} K from "
                         "the oil's; at most 100 K either way")
    return result
