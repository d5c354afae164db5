"""Homogenised flow factors versus the roughness-scale separation h0 (paper eqs 11-16).

A :class:`FlowFactors` value is what the micro scale hands to the macro scale: for each
rigid-body separation ``h0`` the mean gap ``h_m``, the mean asperity contact pressure
``p_con``, the factors ``A``, ``b`` (Poiseuille and Couette flow, eq 17), ``C``, ``d``
(the pin's wall shear, eq 31) and the friction factors ``friction_factor`` s_C and
``pressure_friction`` (the force on the pin: wall shear and the film pressure on its
flanks, from the film's dissipation; docs/model.md "Friction on the pin").  It saves to
and loads from ``.npz`` with its metadata, averages over patches, and interpolates in
``h0`` with the paper's rules beyond the computed range.
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.interpolate import PchipInterpolator

from ..checks import arguments
from ..errors import InputError
from ..io.atomic import atomic_path
from ..io.table import write_csv
from .estimate import combine

#: the arrays of a FlowFactors value, in the order of its fields
ARRAYS = ("h0", "h_m", "p_con", "A", "b", "C", "d", "friction_factor", "pressure_friction",
          "contact_fraction", "film_fraction", "log_friction", "thin_friction", "thin_area")
#: the arrays that files written without them take as none: the local shear's spread and
#: the confined films' friction
OPTIONAL = ("film_fraction", "log_friction", "thin_friction", "thin_area")
#: p_con is interpolated as ``log(p_con + P_CON_FLOOR max p_con)``: it falls by a factor of
#: about 3 per 40 nm of h0, so its logarithm interpolates seven times closer than p_con
#: itself (the measurement is in the commit that chose it, 6d49f8d); the floor keeps the
#: log finite where the surfaces separate (p_con = 0)
P_CON_FLOOR = 1e-6
#: what the friction needs beyond the Reynolds equation (eqs 31-32, the force on the pin)
SHEAR = ("C", "d", "friction_factor", "pressure_friction", "contact_fraction", "film_fraction",
         "log_friction", "thin_friction", "thin_area")
#: relative step of the central differences in h0 (:meth:`FlowFactors.slopes`)
REL_STEP = 1e-6


@dataclass(frozen=True, eq=False)
class FlowFactors:
    """Flow factors of one roughness patch pair (or an average of several), SI units.

    h0 : (n,) rigid-body separations [m], increasing
    h_m : (n,) mean gap, eq 12 [m]
    p_con : (n,) mean asperity contact pressure, eq 11 [Pa]
    A : (n, 2, 2) pressure flow factor, eq 13 [-]
    b : (n, 2) Couette flow factor, eq 14 [-]
    C : (n, 2, 2) pressure-driven shear factor, eq 15 [-]
    d : (n, 2) shear-driven shear factor, eq 16 [-]
    friction_factor : (n,) s_C, Couette friction on the pin ``mu u_r s_C / h_m`` [-]
    pressure_friction : (n, 2) ``2 e1 - b`` (pin at rest), Poiseuille friction on the pin
    ``-(h_m / 2) pressure_friction . grad p`` [-]; eq 31: ``1 - 3 d1`` and ``C``'s first row
    contact_fraction : (n,) space-time mean fraction of pixels in contact [-]
    film_fraction : (n,) w, the fraction of the cell whose film carries film friction
    (thicker than the boundary film) [-]; default 1
    log_friction : (n,) ``<ln(h_m s)>`` over that film, zero elsewhere, with ``s`` the local
    dissipation per ``mu u_r^2`` [1/m], whose cell mean is ``s_C / h_m`` [-]; default
    ``ln s_C``.  With ``film_fraction``, the spread of the local shear that an Eyring film
    averages (:func:`fem_twin.macro.laws.friction.eyring_shear`)
    thin_friction : (n,) ``h_m <1/h>`` over the confined films between the gap floor and the
    boundary film, whose Couette shear is ``mu u_r thin_friction / h_m`` under
    ``[boundary] thin_films = "viscous"`` [-]; default 0 (none known)
    thin_area : (n,) the share of the cell those films cover [-]; default 0
    meta : JSON-able description (patch ids, grid, materials, method, version, ...)
    """

    h0: np.ndarray
    h_m: np.ndarray
    p_con: np.ndarray
    A: np.ndarray
    b: np.ndarray
    C: np.ndarray
    d: np.ndarray
    friction_factor: np.ndarray
    pressure_friction: np.ndarray
    contact_fraction: np.ndarray
    film_fraction: np.ndarray | None = None
    log_friction: np.ndarray | None = None
    thin_friction: np.ndarray | None = None
    thin_area: np.ndarray | None = None
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        for name in ("thin_friction", "thin_area"):       # no confined films known
            if getattr(self, name) is None:
                object.__setattr__(self, name, np.zeros(np.shape(self.h0)))
        n = np.shape(self.h0)
        spread = self.film_fraction is not None and self.log_friction is not None
        expect = {"h0": n, "h_m": n, "p_con": n, "A": n + (2, 2), "b": n + (2,),
                  "C": n + (2, 2), "d": n + (2,), "friction_factor": n,
                  "pressure_friction": n + (2,), "contact_fraction": n, "thin_friction": n,
                  "thin_area": n,
                  **({"film_fraction": n, "log_friction": n} if spread else {})}
        for name, shape in expect.items():
            try:
                v = np.asarray(getattr(self, name), dtype=float)
            except (TypeError, ValueError):
                raise InputError(f"FlowFactors.{name}: expected numbers, got "
                                 f"{type(getattr(self, name)).__name__}") from None
            if v.shape != shape:
                raise InputError(f"FlowFactors.{name} has shape {v.shape}, expected {shape}")
            if not np.all(np.isfinite(v)):
                raise InputError(f"FlowFactors.{name} contains NaN or inf")
            object.__setattr__(self, name, v)
        if len(n) != 1 or n[0] < 1 or np.any(np.diff(self.h0) <= 0) or self.h0[0] <= 0:
            raise InputError("h0 must be a positive, strictly increasing 1D array [m]")
        if not spread:                                    # no spread known: none
            object.__setattr__(self, "film_fraction", np.ones(n))
            object.__setattr__(self, "log_friction",
                               np.log(np.maximum(self.friction_factor, 1e-300)))

    def __len__(self) -> int:
        return self.h0.size

    @property
    def screening(self) -> bool:
        """True for a statistical model's factors (``meta["screening"]``,
        :mod:`fem_twin.peers`): closed forms with no discretisation error of their own,
        whose C_f carries no error bar (its model error is measured in docs/peers.md)."""
        return bool(self.meta.get("screening", False))

    @classmethod
    def smooth(cls, h0_range=(1e-10, 1e-2)) -> "FlowFactors":
        """Factors of two perfectly smooth surfaces (the smooth limit of eqs 11-16):
        ``h_m = h0``, ``p_con = 0``, ``A = C = I``, ``b = e1``, ``d = 0``, ``s_C = 1``,
        ``2 e1 - b = e1`` at every ``h0``
        [m] (tabulated at the two ends of ``h0_range``; exact in between and above, and
        below down to the 1 nm floor of :meth:`at`).  What a smooth EHL contact uses."""
        h0 = np.asarray(h0_range, float)
        n = h0.size
        return cls(h0=h0, h_m=h0.copy(), p_con=np.zeros(n), A=np.tile(np.eye(2), (n, 1, 1)),
                   b=np.tile([1.0, 0.0], (n, 1)), C=np.tile(np.eye(2), (n, 1, 1)),
                   d=np.zeros((n, 2)), friction_factor=np.ones(n),
                   pressure_friction=np.tile([1.0, 0.0], (n, 1)), contact_fraction=np.zeros(n),
                   meta={"smooth": True})

    def slopes(self, h0, rel_step: float = REL_STEP) -> dict:
        """Derivatives with respect to ``h0`` of ``h_m`` [-], ``p_con`` [Pa/m], ``A`` and
        ``b`` [1/m] at ``h0``: central differences of :meth:`at`'s rules with a relative
        step (the Jacobian of the macro Newton coupling)."""
        x = np.asarray(h0, float)
        eps = rel_step * x
        lo, hi = self.at(x - eps), self.at(x + eps)
        return {name: (getattr(hi, name) - getattr(lo, name))
                / (2 * eps).reshape(x.shape + (1,) * (getattr(hi, name).ndim - x.ndim))
                for name in ("h_m", "p_con", "A", "b")}

    # -- files ---------------------------------------------------------------------------
    def save(self, path) -> Path:
        """Write ``.npz`` (arrays + ``meta`` as JSON) atomically."""
        path = Path(path)
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as f:
                np.savez(f, **{k: getattr(self, k) for k in ARRAYS},
                         meta=np.array(json.dumps(self.meta, sort_keys=True)))
        return path

    @classmethod
    def load(cls, path) -> "FlowFactors":
        """Read a file written by :meth:`save`."""
        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as z:
                missing = [k for k in ARRAYS if k not in z and k not in OPTIONAL]
                if missing:
                    raise InputError(f"missing {missing}")
                return cls(**{k: z[k] for k in ARRAYS if k in z},
                           meta=json.loads(str(z["meta"])))
        except (OSError, EOFError, ValueError, KeyError, zipfile.BadZipFile) as err:
            raise InputError(f"{path}: cannot read flow factors ({err})") from err

    def write_csv(self, path) -> Path:
        """Table with one row per h0, SI units named in the header (h0_m, h_m_m, p_con_Pa;
        the factors are dimensionless), like the other CSVs of a run."""
        cols = {"h0_m": self.h0, "h_m_m": self.h_m, "p_con_Pa": self.p_con,
                "A11": self.A[:, 0, 0], "A12": self.A[:, 0, 1], "A21": self.A[:, 1, 0],
                "A22": self.A[:, 1, 1], "b1": self.b[:, 0], "b2": self.b[:, 1],
                "C11": self.C[:, 0, 0], "C12": self.C[:, 0, 1], "C21": self.C[:, 1, 0],
                "C22": self.C[:, 1, 1], "d1": self.d[:, 0], "d2": self.d[:, 1],
                "sC": self.friction_factor, "fP1": self.pressure_friction[:, 0],
                "fP2": self.pressure_friction[:, 1],
                "contact_fraction": self.contact_fraction, "film_fraction": self.film_fraction,
                "log_sC": self.log_friction, "thin_sC": self.thin_friction,
                "thin_area": self.thin_area}
        return write_csv(path, cols)

    # -- interpolation -------------------------------------------------------------------
    def at(self, h0, *, friction: bool = True, contact: bool = True) -> "LocalFactors":
        """Factors at any separations ``h0`` [m] (e.g. a macro gap field), paper 2.2.2 rules.

        Inside the computed range: monotone cubic (PCHIP) interpolation in ``log h0`` (of
        ``h_m / h0`` for the mean gap, which makes the smooth limit ``h_m = h0`` exact; of
        ``log(p_con + P_CON_FLOOR max p_con)`` for the contact pressure, which falls
        exponentially with h0: see :data:`P_CON_FLOOR`).
        Above ``h0_max``: ``h_m = h0``, ``p_con = 0`` and the factors at ``h0_max``.
        Below ``h0_min`` (not covered by the paper): ``h_m`` and ``p_con`` continue linearly
        with their end slopes, ``h_m`` floored at 1 nm, and the factors are held at ``h0_min``.
        ``friction=False`` leaves out (None) the shear factors :data:`SHEAR` (``C``, ``d``,
        ``friction_factor``, ``pressure_friction``) and the contact fraction, which the
        Reynolds iterations do not need (80 B a node less);
        ``contact=False`` leaves out the nodal ``p_con`` (for a caller that integrates it
        over the elements instead, :mod:`fem_twin.macro.film.contact_load`).
        """
        x = np.asarray(h0, dtype=float)
        if np.any(~np.isfinite(x)) or np.any(x <= 0):
            raise InputError("h0 must be finite and positive [m]")
        flat = x.ravel()
        lo, hi = self.h0[0], self.h0[-1]
        xc = np.log(np.clip(flat, lo, hi))
        out = {}
        names = ("h_m", "A", "b") + (SHEAR if friction else ())
        for name in names:
            v = getattr(self, name)
            if len(self) == 1:
                out[name] = np.repeat(v[:1], flat.size, axis=0)
            else:
                out[name] = self._interpolant(name)(xc)
        out["h_m"] = out["h_m"] * np.exp(xc)      # h_m / h0 is what is interpolated
        above = flat > hi
        out["h_m"][above] = flat[above]
        if friction:
            out["contact_fraction"][above] = 0.0
            out["thin_friction"][above] = 0.0
            out["thin_area"][above] = 0.0
        out["h_m"] = self._extend_below(flat, out["h_m"], "h_m", 1e-9)
        out["p_con"] = self.contact_pressure(flat) if contact else None
        out = {k: None if v is None else v.reshape(x.shape + v.shape[1:])
               for k, v in out.items()}
        return LocalFactors(h0=x, **{**dict.fromkeys(SHEAR), **out})

    def contact_pressure(self, h0) -> np.ndarray:
        """``p_con(h0)`` alone [Pa], with the rules of :meth:`at` (cheaper than ``at``)."""
        x = np.asarray(h0, dtype=float)
        if np.any(~np.isfinite(x)) or np.any(x <= 0):
            raise InputError("h0 must be finite and positive [m]")
        flat = x.ravel()
        lo, hi = self.h0[0], self.h0[-1]
        if len(self) == 1:
            p = np.full(flat.size, self.p_con[0])
        else:
            # from the first of the last samples without contact on, the interpolant is
            # flat at the floor (PCHIP's slope is 0 beside a zero secant): p_con = 0 there,
            # and only the films below are interpolated (a pin face mostly out of contact)
            p = np.zeros(flat.size)
            near = flat < self._contact_onset()
            p[near] = self._interpolant("p_con")(np.log(np.clip(flat[near], lo, hi)))
        p[flat > hi] = 0.0
        return self._extend_below(flat, p, "p_con", 0.0).reshape(x.shape)

    def _contact_onset(self) -> float:
        """The smallest tabulated ``h0`` [m] from which on every ``p_con`` is zero (inf if
        the largest one is in contact)."""
        touching = np.flatnonzero(self.p_con > 0)
        if not touching.size:
            return float(self.h0[0])
        last = touching[-1] + 1
        return float(self.h0[last]) if last < len(self) else np.inf

    def _extend_below(self, flat, values, name, floor):
        """Below ``h0_min``: continue linearly with the end slope, floored."""
        below = flat < self.h0[0]
        if len(self) > 1 and below.any():
            v = getattr(self, name)
            slope = (v[1] - v[0]) / (self.h0[1] - self.h0[0])
            values[below] = np.maximum(v[0] + slope * (flat[below] - self.h0[0]), floor)
        return values

    def __getstate__(self):
        """Pickled without the interpolants (a cache, rebuilt on first use): the factors
        go to worker processes after the main process has read them."""
        return {k: v for k, v in self.__dict__.items() if k != "_pchip"}

    def _interpolant(self, name):
        """The interpolant of ``name`` in ``log h0`` (see :meth:`at`)."""
        cache = self.__dict__.setdefault("_pchip", {})
        if name not in cache:
            x = np.log(self.h0)
            if name == "p_con":
                p = np.maximum(self.p_con, 0.0)      # an error estimate's variant may dip
                floor = max(P_CON_FLOOR * float(p.max()), 1e-300)
                log_p = PchipInterpolator(x, np.log(p + floor))
                cache[name] = lambda xi: np.maximum(np.exp(log_p(xi)) - floor, 0.0)
            else:
                v = getattr(self, name) / (self.h0 if name == "h_m" else 1.0)
                cache[name] = PchipInterpolator(x, v, axis=0)
        return cache[name]

    def variants(self) -> dict:
        """``{kind: FlowFactors}``: these factors with each estimated discretisation error
        added (``"time"``, ``"grid"``, ``"h0"``; :func:`fem_twin.micro.estimate.variants`),
        for the macro scale's error estimate; empty when the micro stage kept none."""
        own = {k: self.meta[k] for k in ("slide_to_roll",) if k in self.meta}
        return {kind: FlowFactors(**{k: np.asarray(v, float) for k, v in arrays.items()},
                                  meta=dict(own))
                for kind, arrays in self.meta.get("variants", {}).items()}

    def smooth_limit_error(self) -> float:
        """Largest deviation from the smooth-surface factors ``A = C = I, b = e1, d = 0``."""
        eye = np.eye(2)
        return float(max(np.abs(self.A - eye).max(), np.abs(self.C - eye).max(),
                         np.abs(self.b - [1, 0]).max(), np.abs(self.d).max(),
                         np.abs(self.friction_factor - 1).max(),
                         np.abs(self.pressure_friction - [1, 0]).max()))


@dataclass(frozen=True, eq=False)
class LocalFactors:
    """Flow factors evaluated at separations ``h0`` of any shape (see :meth:`FlowFactors.at`).

    ``h_m``, ``p_con``, ``contact_fraction``, ``friction_factor`` are shaped like ``h0``;
    ``A``, ``C`` add ``(2, 2)`` and ``b``, ``d``, ``pressure_friction`` add ``(2,)`` as
    trailing axes; the shear factors and ``contact_fraction`` are None when evaluated
    without them (``at(h0, friction=False)``),
    ``p_con`` with ``at(h0, contact=False)``, and ``A``, ``b`` where a caller dropped them
    once the Reynolds matrices were built.
    """

    h0: np.ndarray
    h_m: np.ndarray
    p_con: np.ndarray | None
    A: np.ndarray | None
    b: np.ndarray | None
    C: np.ndarray | None
    d: np.ndarray | None
    friction_factor: np.ndarray | None
    pressure_friction: np.ndarray | None
    contact_fraction: np.ndarray | None
    film_fraction: np.ndarray | None = None
    log_friction: np.ndarray | None = None
    thin_friction: np.ndarray | None = None
    thin_area: np.ndarray | None = None


@arguments(factors=[FlowFactors])
def average(factors) -> FlowFactors:
    """Arithmetic mean over patches at the same ``h0`` (the paper's test average, Fig 4-5).

    Patches sampled at different separations over the same range (adaptive sampling picks
    its own subset per patch) are averaged at the union of their separations, each read
    there by its interpolant (:meth:`FlowFactors.at`, within its ``h0`` error estimate)."""
    factors = list(factors)
    if not factors:
        raise InputError("no flow factors to average")
    h0 = np.unique(np.concatenate([f.h0 for f in factors]))
    for f in factors:
        if not np.allclose(f.h0[[0, -1]], h0[[0, -1]], rtol=1e-12, atol=0):
            raise InputError("flow factors to average must share the same h0 values "
                             "(or at least the same h0 range, when sampled adaptively)")
    kinematics = {f.meta.get("slide_to_roll", 2.0) for f in factors}
    if len(kinematics) > 1:
        raise InputError(f"flow factors to average differ in slide_to_roll {kinematics}")
    local = [f if f.h0.size == h0.size else f.at(h0) for f in factors]
    mean = {k: np.mean([getattr(f, k) for f in local], axis=0) for k in ARRAYS if k != "h0"}
    meta = {"average_of": [{k: v for k, v in f.meta.items() if k != "variants"}
                           for f in factors],
            "method": factors[0].meta.get("method"), "version": factors[0].meta.get("version"),
            "slide_to_roll": kinematics.pop(),
            **({"screening": True} if any(f.screening for f in factors) else {}),
            "error_estimate": combine(f.meta.get("error_estimate") for f in factors),
            "variants": _average_variants(factors)}
    return FlowFactors(h0=h0, **mean, meta=meta)


def _average_variants(factors) -> dict:
    """The variants of a patch average: per kind, the average of the patches' variants (a
    patch without that kind enters as itself), when at least one patch has it."""
    each = [f.variants() for f in factors]
    kinds = sorted({kind for v in each for kind in v})
    out = {}
    for kind in kinds:
        mean = average([v.get(kind, f) for v, f in zip(each, factors)])
        out[kind] = {k: getattr(mean, k).tolist() for k in ARRAYS}
    return out
