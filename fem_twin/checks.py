"""Plausible physical inputs, declared once for the case file and the Python API.

A value in the wrong unit (mm given as m, GPa as Pa, mPa s as Pa s) is off by 1e3 or more
and lands outside these ranges, which bracket every pin-on-disk, ball-on-disk and MTM setup
with steel, ceramics, polymers and lubricating oils.  :func:`plausible` raises
:class:`~fem_twin.errors.InputError` naming the argument (or case-file key), the range and
an example in SI units; the case parser (:mod:`fem_twin.case`) and the public entry points
(``reduced_modulus``, ``contact.solve``, ``homogenise``, ``solve_mixed``) call it.
"""

from __future__ import annotations

import functools
import inspect
import math
import os
from collections.abc import Collection, Mapping
from dataclasses import field

import numpy as np

from .errors import InputError

#: quantity -> (lowest, highest) plausible value in SI units, and the hint shown
QUANTITIES = {
    "load": (1e-3, 1e4, "N"),
    "length": (1e-4, 1.0, "m (8 mm is 8e-3)"),
    "pin_diameter": (1e-4, 0.1, "m (8 mm is 8e-3)"),
    "friction": (1e-3, 1.0, "(a friction coefficient)"),
    "load_share": (0.05, 1.0, "a fraction of the imposed load, in (0, 1]"),
    "thermal_resistance": (0.0, 100.0, "K/W (a rig's contact to its oil bath: about 1)"),
    "slide_to_roll": (-2.0, 2.0, "u_r / u_m in [-2, 2] (50 % is 0.5; 0: pure rolling; 2: "
                      "the pin or ball at rest)"),
    "ball_slide_to_roll": (1e-3, 2.0, "u_r / u_m of a ball's Stribeck curve, in (0, 2] (50 % "
                           "is 0.5; 2: the ball at rest; pure rolling, 0, is fem-twin "
                           "traction's SRR 0)"),
    "viscosity": (1e-5, 10.0, "Pa s (66 mPa s is 0.066)"),
    "density": (100.0, 2e4, "kg/m^3"),
    "pressure_viscosity": (0.0, 1e-7, "1/Pa (22 GPa^-1 is 22e-9)"),
    "eyring_stress": (1e4, 1e9, "Pa (5 MPa is 5e6; 0: Newtonian)"),
    "modulus": (1e8, 2e12, "Pa (210 GPa is 210e9)"),
    "reduced_modulus": (1e8, 4e12, "Pa (231 GPa is 231e9)"),
    "solver_modulus": (1e8, 1e30, "Pa (231 GPa is 231e9; a rigid limit, 1e20, is allowed)"),
    "poisson": (0.0, 0.4999, "Poisson ratio in [0, 0.5)"),
    "hardness": (1e7, 1e11, "Pa (6.99 GPa is 6.99e9)"),
    "separation": (1e-10, 1e-4, "m (0.1 um is 1e-7)"),
    "speed": (1e-6, 100.0, "m/s"),
    "pitch": (1e-9, 1e-2, "m (0.3 um is 3e-7, 31 um is 3.1e-5)"),
    "map_pitch": (1e-9, 1e-3, "m per pixel of a measured map: give the pitch in metres "
                  "(16 um is 1.6e-5, not 0.016)"),
    "axis_distance": (1e-4, 1e3, "m, the disk's axis from the face's centre (30 mm is "
                      "30e-3; far: uniform sliding)"),
    "fwhm_px": (0.0, 200.0, "pixels (0 or at least 1)"),
    "temperature_C": (-40.0, 300.0, "degrees Celsius, not kelvin (24 C is 24.0, not 297.15)"),
    "film_temperature_C": (-273.15, 1000.0, "degrees Celsius of a heated film (an oil "
                           "decomposes far below 1000 C)"),
    "conductivity": (0.1, 500.0, "W/(m K) (steel: 46)"),
    "diffusivity": (1e-8, 1e-3, "m^2/s (steel: 12 mm^2/s is 1.2e-5)"),
    "spot_radius": (0.0, 1e-3, "m (5 um is 5e-6)"),
    "temperature_tol": (1e-5, 10.0, "K (0.01 K)"),
    "boundary_film": (1e-10, 5e-8, "m, a few nanometres (10 nm is 10e-9)"),
    "gap_floor": (1e-12, 1e-8, "m, about a nanometre (1 nm is 1e-9)"),
    "height": (1e-8, 1e-3, "m, a height on the surface (20 um is 20e-6)"),
    "depth": (-1e-2, -1e-8, "m below the face, negative (-20 um is -20e-6, -1 mm is -1e-3)"),
    "pixels": (2, 16384, "pixels a side, whole numbers"),
    "pixel_offset": (0, 1000000, "pixels from the first row or column, whole numbers"),
    "nodes": (8, 4096, "nodes a side, whole numbers"),
    "pressure": (0.0, 1e7, "Pa, absolute (1 bar is 1e5)"),
    "pressure_scale": (1e5, 1e11, "Pa (0.196 GPa is 1.96e8)"),
    "dh_ratio": (0.1, 100.0, "(the Dowson-Higginson C_2: 1.34)"),
    "time_steps": (1, 4096, "time steps of one sliding pass (the paper: 32)"),
    "samples": (1, 100000, "a count, whole number"),
    "iterations": (1, 100000, "iterations, a whole number"),
    "newton_steps": (0, 1000, "Newton steps, a whole number (0: to convergence)"),
    "history": (1, 100, "iterates kept, a whole number"),
    "passes": (0, 4, "passes, a whole number"),
    "workers": (0, 4096, "processes, a whole number (0: one per core)"),
    "pin_number": (1, 1000, "a pin number from 1"),
    "relaxation": (1e-6, 1.0, "a relaxation factor in (0, 1]"),
    "pid_gain": (0.0, 100.0, "(the paper's K_P, K_I, K_D: 0.012, 0.024, 0.0015)"),
    "solver_tolerance": (1e-15, 0.1, "a relative tolerance (e.g. 1e-6)"),
    "convergence_order": (0.5, 4.0, "an order of convergence (2: second order)"),
    "adaptive_tolerance": (0.0, 0.5, "a fraction (1 % is 0.01; 0: off)"),
    "share": (1e-6, 0.999, "a fraction of C_f,b (0.5 % is 0.005)"),
    "shear_strength": (1e4, 1e9, "Pa (a boundary film's tau_0, 10 MPa is 1e7; 0: none)"),
    "pressure_coefficient": (0.0, 1.0, "(Briscoe-Tabor's alpha, 0.1 is 0.1)"),
    "speed_coefficient": (-0.5, 0.5, "per decade of sliding speed (5 % is 0.05)"),
    "temperature_coefficient": (0.0, 0.1, "1/K (0.2 % per kelvin is 0.002)"),
}

#: quantities whose 0 switches a term off; any other value lies in the range, whose lower
#: bound then catches a unit slip (5 MPa typed as 5.0)
OFF_AT_ZERO = frozenset({"eyring_stress", "shear_strength"})


def plausible(name: str, value, quantity: str):
    """``value`` (a number or an array of them) if finite and inside the plausible range of
    ``quantity`` (:data:`QUANTITIES`; 0 too for :data:`OFF_AT_ZERO`); else
    :class:`InputError` naming ``name``."""
    lo, hi, unit = QUANTITIES[quantity]
    values = np.atleast_1d(np.asarray(value, dtype=float)) if _numeric(value) else None
    if values is None or values.size == 0:
        raise InputError(f"{name}: expected a number in {unit}, got {value!r}")
    for v in values.ravel():
        if not math.isfinite(v):
            raise InputError(f"{name} = {v}: must be a finite number ({unit})")
        if not lo <= v <= hi and not (v == 0 and quantity in OFF_AT_ZERO):
            raise InputError(f"{name} = {v:g}: implausible; expected {lo:g} to {hi:g} {unit}")
    return value


#: peak memory a grid point takes in one process [B]: a macro node (the 2048^2 point of
#: ``benchmarks/run.py scale``) and a cell pixel (PARDISO, 256^2 to 1024^2: ``micro``),
#: and a pixel of a resampled map (its two coordinate grids, the
#: interpolated heights and the topography's copy, float64 each)
BYTES_PER_POINT = {"macro": 1.9e3, "cell": 3.2e3, "map": 32.0}


def memory_shortfall(points: int, grid: str, processes: int = 1) -> str | None:
    """Why a grid of ``points`` cannot run here, or None: more than 80 % of this machine's
    memory in ``processes`` processes at once (:data:`BYTES_PER_POINT`); the caller raises
    its own error with it, before any work."""
    memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    need = BYTES_PER_POINT[grid] * points * processes
    if need <= 0.8 * memory:
        return None
    return (f"{points:,} points in {processes} process(es) need about {need / 2 ** 30:.0f} "
            f"GiB, beyond this machine's {memory / 2 ** 30:.0f} GiB; use a coarser grid or "
            "fewer workers")


def number(name: str, value, quantity: str) -> float:
    """``value`` as one plausible number of ``quantity`` (:func:`plausible`), or
    :class:`InputError` naming ``name``: an array where a number goes is refused."""
    check(name, value, "number")
    return float(plausible(name, value, quantity))


def whole(name: str, value, quantity: str) -> int:
    """``value`` as one plausible whole number of ``quantity`` (a tile, node or worker
    count; :func:`number`), or :class:`InputError` naming ``name``."""
    v = number(name, value, quantity)
    if v != int(v):
        raise InputError(f"{name}: expected a whole number, got {value!r}")
    return int(v)


def as_pair(name: str, value) -> tuple[float, float]:
    """``(v1, v2)`` from a number or a pair of numbers (a pitch ``(dx1, dx2)``), or
    :class:`InputError` naming ``name``; finiteness and range are the caller's."""
    try:
        pair = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a number or a pair of numbers, got {value!r}") from None
    if pair.shape not in ((), (1,), (2,)):
        raise InputError(f"{name}: expected a number or a pair of numbers, got {pair.size} "
                         "values")
    v1, v2 = np.broadcast_to(pair, (2,))
    return float(v1), float(v2)


def as_spacing(name: str, value):
    """A grid's spacing: ``(dx1, dx2)`` (:func:`as_pair`), or a graded mesh as it is (an
    object with a ``pitch`` and node ``lines``, :class:`fem_twin.numerics.graded_mesh.Mesh`, which
    checks itself)."""
    if hasattr(value, "pitch") and hasattr(value, "lines"):
        return value
    return as_pair(name, value)


def as_field(name: str, value, min_side: int = 2) -> np.ndarray:
    """``value`` as a finite 2D float array of at least ``min_side`` a side, or
    :class:`InputError` naming ``name`` (a gap, a map: SI units are the caller's)."""
    try:
        if np.iscomplexobj(value):
            raise TypeError
        field_ = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a 2D array of real numbers, got "
                         f"{type(value).__name__}") from None
    if field_.ndim != 2 or min(field_.shape) < min_side:
        raise InputError(f"{name}: expected a 2D array of at least {min_side} x {min_side}, "
                         f"got shape {field_.shape}")
    if not np.all(np.isfinite(field_)):
        raise InputError(f"{name} must be finite: it contains NaN or inf (fill or repair it)")
    return field_


def arguments(**kinds):
    """Decorator of a public function: its named arguments are checked before the call,
    each against its kind, and a wrong one is an :class:`InputError` naming the function
    and the argument.  A kind is a class (or a tuple of classes: ``isinstance``), a
    sequence of one (``[cls]``: a non-empty collection of such), or one of ``"path"``
    (a str or path), ``"number"`` (one finite real), ``"numbers"`` (a non-empty numeric
    array, finite), ``"field"`` (:func:`as_field`), ``"pair"`` (:func:`as_pair`), ``"spacing"``
    (:func:`as_spacing`),
    ``"shape"`` (two positive whole numbers).  None is accepted where it is the default."""
    def wrap(func):
        signature = inspect.signature(func)

        @functools.wraps(func)
        def checked(*args, **kwargs):
            bound = signature.bind_partial(*args, **kwargs).arguments
            for name, kind in kinds.items():
                if name in bound and not (bound[name] is None
                                          and signature.parameters[name].default is None):
                    check(f"{func.__qualname__}: {name}", bound[name], kind)
            return func(*args, **kwargs)
        return checked
    return wrap


def check(name: str, value, kind) -> None:
    """One argument against its kind (:func:`arguments`), or :class:`InputError` naming
    ``name``."""
    if isinstance(kind, list):
        if (isinstance(value, (str, bytes)) or not isinstance(value, Collection)
                or len(value) == 0):
            raise InputError(f"{name}: expected a non-empty list of {_kind_name(kind[0])}")
        for item in value:
            check(name, item, kind[0])
    elif isinstance(kind, (type, tuple)):
        if not isinstance(value, kind):
            names = " or ".join(k.__name__ for k in (kind if isinstance(kind, tuple) else (kind,)))
            raise InputError(f"{name}: expected {names}, got {type(value).__name__}")
    elif kind == "path":
        if not isinstance(value, (str, os.PathLike)):
            raise InputError(f"{name}: expected a file path, got {type(value).__name__}")
    elif kind == "number":
        if not (_numeric(value) and np.ndim(value) == 0 and math.isfinite(float(value))):
            raise InputError(f"{name}: expected one finite number, got {value!r}"[:200])
    elif kind == "numbers":
        if _numeric(value) and np.size(value) == 0:
            raise InputError(f"{name}: expected at least one number, got none")
        if not _numeric(value) or not np.all(np.isfinite(value)):
            raise InputError(f"{name}: expected finite numbers, got {type(value).__name__}")
    elif kind == "field":
        as_field(name, value)
    elif kind == "pair":
        as_pair(name, value)
    elif kind == "spacing":
        as_spacing(name, value)
    elif kind == "shape":
        if not (isinstance(value, (tuple, list)) and len(value) == 2
                and all(isinstance(v, (int, np.integer)) and v > 0 for v in value)):
            raise InputError(f"{name}: expected (rows, columns), two positive whole numbers, "
                             f"got {value!r}"[:200])
    else:
        raise InputError(f"{name}: unknown argument kind {kind!r}")


def _kind_name(kind) -> str:
    """A kind of :func:`check` in words: ``StribeckCurve``, ``lists of StribeckCurve``."""
    return f"lists of {_kind_name(kind[0])}" if isinstance(kind, list) else kind.__name__


def _numeric(value) -> bool:
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):
        return False
    return array.dtype.kind in "iuf" and array.dtype != bool


def setting(default, doc: str, quantity: str | None = None, *, unit: str = "",
            choices: tuple = (), section: str | None = None):
    """The one declaration of a setting (a dataclass field of its settings object): its
    default, a one-line ``doc``, the ``quantity`` of :data:`QUANTITIES` whose plausible
    range and unit the parser enforces (or a ``unit`` of its own), the ``choices`` of a
    text setting (a registry, a mapping by name, is kept as it is: a name registered
    later is a choice too), and the case-file ``section`` that sets it when that is another
    one (a value the stage takes from elsewhere in the case).  The case parser, the API's
    checks (:func:`check_choices`) and the documentation's case-file reference read it
    (:func:`describe`)."""
    choices = choices if isinstance(choices, Mapping) else tuple(choices)
    return field(default=default, metadata={"doc": doc, "quantity": quantity, "unit": unit,
                                            "choices": choices, "section": section})


def check_choices(settings) -> None:
    """Refuse a text setting of the dataclass ``settings`` outside its declared choices."""
    from dataclasses import fields
    for f in fields(settings):
        check_choice(f.name, getattr(settings, f.name), f.metadata.get("choices"))


def check_ranges(settings) -> None:
    """Refuse a number of the dataclass ``settings`` outside the plausible range its
    declaration names (:func:`setting`'s ``quantity``), a fraction where the declared
    default is a whole number, a flag that is not True or False, and None or text where
    neither the default nor the declared type is, naming the class and the field; text
    where the default is text (a pin's "average") is the settings' own rule."""
    from dataclasses import MISSING, fields
    for f in fields(settings):
        value, default = getattr(settings, f.name), f.default
        name, quantity = f"{type(settings).__name__}.{f.name}", f.metadata.get("quantity")
        if isinstance(default, bool):
            if not isinstance(value, (bool, np.bool_)):
                raise InputError(f"{name}: expected true or false, got {value!r}")
            continue
        if value is None or isinstance(value, str):
            unset = default is None or default is MISSING or "None" in str(f.type)
            if (value is None and unset) or (isinstance(value, str) and (
                    unset or isinstance(default, str))):
                continue
            hint = QUANTITIES[quantity][2] if quantity else f"a value like {default!r}"
            raise InputError(f"{name}: expected {hint}, got {value!r}")
        if not quantity:
            continue
        if not isinstance(default, tuple) and np.ndim(value) != 0:
            raise InputError(f"{name}: expected one number, got {np.size(value)} values")
        plausible(name, value, f.metadata["quantity"])
        if _whole(f.default) and not np.all(np.mod(np.asarray(value, float), 1) == 0):
            raise InputError(f"{name}: expected whole numbers, got {value!r}")


def _whole(default) -> bool:
    """Whether a declared default is a whole number (or a tuple of them)."""
    first = default[0] if isinstance(default, tuple) and default else default
    return isinstance(first, (int, np.integer)) and not isinstance(first, bool)


def check_choice(name: str, value, choices) -> None:
    """Refuse ``value`` outside ``choices`` (none: any; a registry: its keys), naming
    ``name``; an unhashable value (a list) is outside a registry too."""
    try:
        inside = not choices or value in choices
    except TypeError:                                  # a list looked up in a registry
        inside = False
    if not inside:
        raise InputError(f"{name}: one of {', '.join(map(repr, choices))}, got {value!r}")


def registered(name: str, registry, key):
    """The entry ``key`` of ``registry`` (a law or model registry), refused by
    :func:`check_choice` naming ``name`` and the registered keys when it has none."""
    check_choice(name, key, registry)
    return registry[key]


def describe(f) -> dict:
    """What :func:`setting` declared of the dataclass field ``f``: ``doc``, ``unit``,
    ``range`` (lowest, highest, or None) and ``choices``."""
    meta = f.metadata
    quantity = meta.get("quantity")
    lo, hi, hint = QUANTITIES[quantity] if quantity else (None, None, meta.get("unit", ""))
    return {"doc": meta.get("doc", ""), "unit": hint, "choices": meta.get("choices", ()),
            "range": None if quantity is None else (lo, hi)}
