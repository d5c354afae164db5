"""A Stribeck curve, its Hersey number (eq 46) and deviations between curves (eq 35)."""

from __future__ import annotations

import csv
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .. import tables as T
from ..checks import arguments, number
from ..errors import InputError, MissingFile
from ..io.figure import save_figure
from ..io.table import write_csv

COLUMNS = ("speed", "hersey", "friction_coefficient", "viscosity", "hydrodynamic_friction",
           "boundary_force", "contact_load_fraction", "h_d", "iterations")
#: the CSV header of each column: its name with the SI unit (:mod:`fem_twin.io.table`)
HEADERS = dict(zip(COLUMNS, ("speed_m_s", "hersey", "friction_coefficient", "viscosity_Pa_s",
                             "hydrodynamic_friction_N", "boundary_force_N",
                             "contact_load_fraction", "h_d_m", "iterations")))
#: the names earlier fem_twin versions wrote, read as today's (the boundary part of F_T was
#: ``boundary_friction``, the case file's coefficient C_f,b): CSV headers and variables
LEGACY = {"boundary_friction_N": "boundary_force_N", "boundary_friction": "boundary_force"}
#: the columns a curve has when its run gives them: a thermal run's temperatures [C] and
#: spots' flash per pascal of boundary shear [K/Pa] (:mod:`fem_twin.macro.laws.thermal`), the
#: boundary law's integrals (:mod:`fem_twin.macro.laws.boundary_laws`): their CSV header, unit in
#: ``results.nc`` and long name
OPTIONAL = {"contact_temperature": ("contact_temperature_C", "degC", "the film's temperature: "
                                    "oil, bulk rise and the face's flash temperature"),
            "asperity_temperature": ("asperity_temperature_C", "degC", "an asperity "
                                     "contact's temperature: the film's and its flash"),
            "asperity_load": ("asperity_load_N", "N", "the asperities' load p_con + p a_r "
                              "along the sliding (the constant law's F_b over C_f,b)"),
            "real_contact_area": ("real_contact_area_m2", "m2", "the real contact area "
                                  "along the sliding"),
            "spot_rise": ("spot_rise_K_Pa", "K/Pa", "an asperity spot's flash per pascal "
                          "of boundary shear"),
            "film_sensitivity": ("cf_film", "1", "C_f's change with half and twice [micro] "
                                 "boundary_film: a model sensitivity, not in cf_err"),
            "friction_error_signed": ("cf_err_signed", "1", "the estimate of C_f minus its "
                                      "converged value, cf_err's parts summed with their "
                                      "signs: the accuracy warning reads it, cf_err bounds "
                                      "it")}
#: the unit and meaning of each variable over (viscosity, speed) in ``results.nc``
#: (:func:`fem_twin.results.stribeck_dataset`; speed and viscosity are its coordinates)
UNITS = {"hersey": ("1", "Hersey number mu_0 U D / F_N (eq 46)"),
         "friction_coefficient": ("1", "C_f (eq 34)"),
         "hydrodynamic_friction": ("N", "hydrodynamic part of F_T (eq 33)"),
         "boundary_force": ("N", "boundary part of F_T (eq 33)"),
         "contact_load_fraction": ("1", "share of the face load (F_N times load_share) "
                                        "carried by p_con"),
         "h_d": ("m", "rigid-body separation h_d"),
         "iterations": ("1", "macro solver iterations"),
         "cf_min": ("1", "lowest C_f of the single-patch sweeps"),
         "cf_max": ("1", "highest C_f of the single-patch sweeps")}


#: log-speed tolerance [-] within which a measured speed counts as a simulated curve's end
#: (a run's own top speed, rescaled by a viscosity ratio that is 1 to rounding)
SPEED_MATCH = 1e-9


@arguments(viscosity="numbers", speed="numbers", diameter="number", load="number")
def hersey_number(viscosity, speed, diameter: float, load: float):
    """H = mu_0 U D / F_N,imp of eq 46 [-] (SI inputs)."""
    return np.asarray(viscosity) * np.asarray(speed) * diameter / load


@arguments(cf="numbers", cf_ref="numbers", boundary_friction="number")
def friction_deviation(cf, cf_ref, boundary_friction: float):
    """C_f,dev = (C_f - C_f,ref) / C_f,b of eq 35 [-]."""
    return (np.asarray(cf) - np.asarray(cf_ref)) / boundary_friction


#: the derived column of the share of C_f that the boundary law sets: its CSV header and
#: its unit and long name in ``results.nc``
BOUNDARY_SHARE = ("boundary_share", "1", "share of F_T the boundary law sets, F_b / F_T: "
                  "C_f's relative sensitivity d ln C_f / d ln (boundary level), the "
                  "calibrated part; the rest, the film friction, is predicted")


@dataclass(frozen=True, eq=False)
class StribeckCurve:
    """C_f versus sliding speed at one viscosity; arrays ordered as computed (fast first).

    speed [m/s], hersey [-], friction_coefficient [-], viscosity mu_0 [Pa s] (scalar),
    hydrodynamic_friction and boundary_force: F_T parts [N], contact_load_fraction:
    share of the face's load (F_N times ``load_share``) carried by p_con, h_d [m],
    iterations of the macro solver;
    friction_error: the estimated discretisation error of C_f [-] (absolute, both scales,
    :mod:`fem_twin.macro.estimate`) and friction_error_parts its parts by name, when the
    sweep estimated them (None otherwise); coarse_friction_coefficient: C_f of the same
    points on the macro grid coarsened by two, four, ..., as ``(levels, points)`` (the
    nested solves' coarse points, finest first; NaN where none was solved), when the sweep
    kept them; the :data:`OPTIONAL` columns where the run gives them (temperatures [C]
    and the spots' flash per shear [K/Pa] of a thermal run, the boundary law's asperity
    load [N] and real contact area [m^2], C_f's sensitivity to the boundary film and the
    signed estimate of its error [-] of an estimating sweep; None otherwise).
    """

    speed: np.ndarray
    hersey: np.ndarray
    friction_coefficient: np.ndarray
    viscosity: float
    hydrodynamic_friction: np.ndarray
    boundary_force: np.ndarray
    contact_load_fraction: np.ndarray
    h_d: np.ndarray
    iterations: np.ndarray
    friction_error: np.ndarray | None = None
    friction_error_parts: dict | None = None
    coarse_friction_coefficient: np.ndarray | None = None
    contact_temperature: np.ndarray | None = None
    asperity_temperature: np.ndarray | None = None
    asperity_load: np.ndarray | None = None
    real_contact_area: np.ndarray | None = None
    spot_rise: np.ndarray | None = None
    film_sensitivity: np.ndarray | None = None
    friction_error_signed: np.ndarray | None = None

    @property
    def boundary_share(self) -> np.ndarray:
        """F_b / F_T [-] at each point (:data:`BOUNDARY_SHARE`; NaN where F_T is 0)."""
        total = self.hydrodynamic_friction + self.boundary_force
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(total != 0, self.boundary_force / total, np.nan)

    def at_hersey(self, hersey):
        """C_f interpolated (monotone cubic, PCHIP, in log H) at Hersey numbers inside this
        curve's range; NaN outside it."""
        from scipy.interpolate import PchipInterpolator
        order = np.argsort(self.hersey)
        x, y = np.log(self.hersey[order]), self.friction_coefficient[order]
        h = np.log(np.asarray(hersey, float))
        inside = (h >= x[0]) & (h <= x[-1])
        if x.size < 2:
            return np.where(inside, y[0], np.nan)
        return np.where(inside, PchipInterpolator(x, y)(np.clip(h, x[0], x[-1])), np.nan)


def joined(curves) -> StribeckCurve:
    """One curve of the points of ``curves`` (pieces of one sweep at one viscosity, in
    order); the coarse levels' C_f padded with NaN where a piece has fewer levels."""
    first = curves[0]
    if len(curves) == 1:
        return first
    if any(c.viscosity != first.viscosity for c in curves):
        raise InputError("joined: the pieces of a curve share one viscosity")
    arrays = {name: np.concatenate([getattr(c, name) for c in curves])
              for name in (*COLUMNS, *OPTIONAL) if name != "viscosity"
              and getattr(first, name) is not None}
    error = None if first.friction_error is None else np.concatenate(
        [c.friction_error for c in curves])
    parts = None if first.friction_error_parts is None else {
        k: np.concatenate([c.friction_error_parts[k] for c in curves])
        for k in first.friction_error_parts}
    coarse = None
    if first.coarse_friction_coefficient is not None:
        levels = max(c.coarse_friction_coefficient.shape[0] for c in curves)
        coarse = np.concatenate([np.pad(c.coarse_friction_coefficient,
                                        ((0, levels - c.coarse_friction_coefficient.shape[0]),
                                         (0, 0)), constant_values=np.nan) for c in curves],
                                axis=1)
    return replace(first, **arrays, friction_error=error, friction_error_parts=parts,
                   coarse_friction_coefficient=coarse)


def parameter_shares(curve: StribeckCurve, law) -> dict:
    """C_f's relative sensitivity to each parameter of the boundary ``law`` (a
    :class:`~fem_twin.macro.laws.boundary_friction.BoundaryLaw`) at each point of
    ``curve``, ``d ln C_f / d ln q`` [-] by name ``share_q``, the law's split of
    :attr:`StribeckCurve.boundary_share` (:meth:`~fem_twin.macro.laws.boundary_laws.Law.shares`):
    C_f,b's is all of it; the shear law splits it between tau_0 (``tau_0 A_r``) and alpha
    (``alpha W``), from the curve's real contact area and asperity load (none without them)."""
    return law.model.shares(law, curve.boundary_share, curve.real_contact_area,
                            curve.asperity_load)


@arguments(path="path", curves=[StribeckCurve])
def write_stribeck_csv(path, curves, band=None, law=None) -> Path:
    """All curves into one CSV (:data:`HEADERS`, SI units), atomically; ``cf_err``, the
    estimated discretisation error of C_f, when a curve has it; ``band``: optional
    ``(cf_min, cf_max)`` per curve (the patch scatter band), two more columns; ``law``:
    the run's boundary law, whose parameters' shares of C_f follow
    (:func:`parameter_shares`)."""
    curves = list(curves)
    columns = {HEADERS[k]: np.concatenate([np.broadcast_to(getattr(c, k), c.speed.shape)
                                           for c in curves]) for k in COLUMNS}
    columns["iterations"] = columns["iterations"].astype(int)
    columns[BOUNDARY_SHARE[0]] = np.concatenate([c.boundary_share for c in curves])
    shares = [parameter_shares(c, law) for c in curves] if law is not None else []
    for name in (shares[0] if shares and all(shares) else {}):
        columns[name] = np.concatenate([s[name] for s in shares])
    if any(c.friction_error is not None for c in curves):
        columns["cf_err"] = np.concatenate([np.full(c.speed.shape, np.nan)
                                            if c.friction_error is None else c.friction_error
                                            for c in curves])
    for name, (header, *_) in OPTIONAL.items():
        if any(getattr(c, name) is not None for c in curves):
            columns[header] = np.concatenate([np.full(c.speed.shape, np.nan)
                                              if getattr(c, name) is None else getattr(c, name)
                                              for c in curves])
    if band is not None:
        columns["cf_min"] = np.concatenate([np.asarray(b[0], float) for b in band])
        columns["cf_max"] = np.concatenate([np.asarray(b[1], float) for b in band])
    return write_csv(path, columns)


@arguments(path="path")
def read_stribeck_csv(path) -> list[StribeckCurve]:
    """Curves written by :func:`write_stribeck_csv` (or with the unit-less headers of
    fem_twin 0.1), one per viscosity."""
    if not Path(path).is_file():
        raise MissingFile(f"{path}: no such Stribeck CSV (fem-twin run writes stribeck.csv)")
    with open(path, newline="") as f:
        rows = [{LEGACY.get(k, k): v for k, v in r.items()} for r in csv.DictReader(f)]
    if rows and set(HEADERS.values()) <= set(rows[0]):
        rows = [{**{k: r[HEADERS[k]] for k in COLUMNS},
                 **({"cf_err": r["cf_err"]} if "cf_err" in r else {}),
                 **{k: r[h] for k, (h, *_) in OPTIONAL.items() if h in r}} for r in rows]
    if not rows or set(COLUMNS) - set(rows[0]):
        raise InputError(f"{path}: not a Stribeck CSV with columns {tuple(HEADERS.values())}")
    try:
        return _curves(rows)
    except (TypeError, ValueError) as err:        # a cut or hand-edited row
        raise InputError(f"{path}: a damaged row ({err}); run fem-twin run again to rewrite "
                         "it") from None


def _curves(rows) -> list[StribeckCurve]:
    """One :class:`StribeckCurve` per viscosity of the CSV ``rows`` (dicts of strings)."""
    out = []
    for mu in dict.fromkeys(float(r["viscosity"]) for r in rows):
        sel = [r for r in rows if float(r["viscosity"]) == mu]
        col = {k: np.array([float(r[k]) for r in sel]) for k in COLUMNS if k != "viscosity"}
        col["iterations"] = col["iterations"].astype(int)
        if "cf_err" in sel[0]:
            col["friction_error"] = np.array([float(r["cf_err"]) for r in sel])
        col.update({k: np.array([float(r[k]) for r in sel]) for k in OPTIONAL if k in sel[0]})
        out.append(StribeckCurve(viscosity=mu, **col))
    return out


@arguments(curves=[StribeckCurve], path="path")
def plot_stribeck(curves, path, *, x: str = "speed", labels=None, reference=None,
                  boundary_friction: float, bands=None, measured=None,
                  diameter: float = T.PIN_DIAMETER, load: float = T.LOAD,
                  speed_label: str = "sliding speed $U$ [m/s]") -> Path:
    """C_f versus sliding speed (``x="speed"``) or Hersey number (``"hersey"``), log x.

    ``reference``: optional measured curve ``(x values, C_f, optional (low, high) band)``;
    ``boundary_friction``: C_f,b of eq 32, drawn as the boundary-friction limit; ``bands``: optional
    ``(cf_min, cf_max)`` per curve, drawn as a shaded band (the patch scatter, Figure 13);
    ``measured``: optional :class:`MeasuredCurve` (or None) per curve, drawn on top in the
    curve's colour; a curve's ``friction_error`` is drawn as error bars (capped, distinct
    from the shaded scatter band) (on the Hersey axis with ``diameter`` [m] and ``load`` [N] of eq
    46). ``speed_label``: the speed axis (a ball-on-disk sweep is over entrainment speeds).
    """
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for i, c in enumerate(curves):
        label = labels[i] if labels else f"$\\mu_0$ = {c.viscosity:g} Pa s"
        line, = ax.plot(getattr(c, x), c.friction_coefficient, "o-", ms=3, label=label)
        if c.friction_error is not None:
            ax.errorbar(getattr(c, x), c.friction_coefficient, yerr=c.friction_error,
                        fmt="none", ecolor=line.get_color(), elinewidth=1.2, capsize=2.5,
                        label="estimated discretisation error" if i == 0 else None)
        if bands is not None and bands[i] is not None:
            ax.fill_between(getattr(c, x), *bands[i], color=line.get_color(), alpha=0.2, lw=0,
                            label="patch scatter" if i == 0 else None)
        m = measured[i] if measured is not None else None
        if m is not None:
            mx = m.speed if x == "speed" else hersey_number(c.viscosity, m.speed, diameter, load)
            ax.plot(mx, m.friction_coefficient, "s", mfc="none", color=line.get_color(),
                    label=f"measured, {label}")
    if reference is not None:
        ax.plot(reference[0], reference[1], "k--", label="measured")
        if len(reference) > 2 and reference[2] is not None:
            ax.fill_between(reference[0], *reference[2], color="0.8", label="scatter")
    ax.axhline(boundary_friction, color="0.4", lw=1.0, ls=":",
               label=f"boundary friction $C_{{f,b}}$ = {boundary_friction:g} (eq 32)")
    ax.set_ylim(0, 1.15 * boundary_friction)
    ax.set_xscale("log")
    ax.set_xlabel(speed_label if x == "speed" else
                  "Hersey number $H = \\mu_0 U D / F_N$ [-] (eq 46)")
    ax.set_ylabel("friction coefficient $C_f$ [-]")
    ax.legend(fontsize="small", loc="upper right")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)


def plot_temperatures(curves, path, *, labels=None,
                      speed_label: str = "sliding speed $U$ [m/s]") -> Path:
    """A thermal run's temperatures [C] against speed, log x: the film's
    (``contact_temperature``, solid) and an asperity contact's (dashed), per curve."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for i, c in enumerate(curves):
        label = labels[i] if labels else f"$\\mu_0$ = {c.viscosity:g} Pa s"
        line, = ax.plot(c.speed, c.contact_temperature, "o-", ms=3, label=f"film, {label}")
        ax.plot(c.speed, c.asperity_temperature, "--", color=line.get_color(),
                label="asperity contacts" if i == 0 else None)
    ax.set_xscale("log")
    ax.set_xlabel(speed_label)
    ax.set_ylabel("contact temperature [°C]")
    ax.legend(fontsize="small")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)


@dataclass(frozen=True, eq=False)
class MeasuredCurve:
    """A measured Stribeck curve: speed [m/s], C_f, optional scatter band (low, high), and
    the normal ``load`` [N] and oil ``viscosity`` mu_0 [Pa s] it was measured at when the
    file says (None: the case's)."""

    speed: np.ndarray
    friction_coefficient: np.ndarray
    low: np.ndarray | None = None
    high: np.ndarray | None = None
    load: float | None = None
    viscosity: float | None = None


@arguments(path="path")
def read_measured_csv(path, unit: str = "m/s") -> MeasuredCurve:
    """CSV with a header: ``speed`` [m/s, or rpm with ``unit="rpm"``, converted by the
    caller] and ``friction_coefficient`` (or ``cf``), and optionally ``cf_min``/``cf_max``
    (the scatter band of a test set) and ``load_N`` and ``viscosity_Pa_s`` (the test's
    load and oil, each one value throughout the file)."""
    if not Path(path).is_file():
        raise MissingFile(f"{path}: no such measured curve (a CSV with speed and "
                          "friction_coefficient)")
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            rows = list(csv.DictReader(f))
    except (UnicodeDecodeError, csv.Error) as err:
        raise InputError(f"{path}: not a CSV text file ({err})") from err
    if not rows:
        raise InputError(f"{path}: empty measured curve")
    cols = {k for k in rows[0] if k is not None}
    cf_key = "friction_coefficient" if "friction_coefficient" in cols else "cf"
    if "speed" not in cols or cf_key not in cols:
        raise InputError(f"{path}: needs columns 'speed' [m/s] and 'friction_coefficient' "
                         f"(found {sorted(cols)})")

    def col(k):
        try:
            values = np.array([float(r[k]) for r in rows])
        except (ValueError, TypeError) as err:     # TypeError: a row shorter than the header
            raise InputError(f"{path}: column {k!r} is not numeric in every row: {err}") \
                from err
        if not np.all(np.isfinite(values)):
            raise InputError(f"{path}: column {k!r} holds a non-finite value")
        return values

    speed = col("speed")
    if np.any(~(speed > 0)) or (unit == "m/s" and speed.max() > 100):
        raise InputError(f"{path}: speeds must be positive and in m/s (max {speed.max()}; "
                         "for rpm use --rpm)")
    band = ("cf_min" in cols and "cf_max" in cols)
    cf = col(cf_key)
    low, high = (col("cf_min"), col("cf_max")) if band else (cf, cf)
    if np.any(low < 0) or np.any(high > 1):
        raise InputError(f"{path}: friction coefficients must lie in [0, 1] (found "
                         f"{min(low.min(), cf.min()):.3g} to {max(high.max(), cf.max()):.3g})")
    if np.any(low > cf) or np.any(cf > high):
        raise InputError(f"{path}: cf_min <= friction_coefficient <= cf_max in every row")
    test = {}
    for key, header, quantity in (("load", "load_N", "load"),
                                  ("viscosity", "viscosity_Pa_s", "viscosity")):
        if header in cols:
            values = col(header)
            if np.ptp(values) > 0:
                raise InputError(f"{path}: column {header!r} must hold one value (one test per "
                                 f"file), found {values.min():g} to {values.max():g}")
            test[key] = number(f"{path}: {header}", float(values[0]), quantity)
    return MeasuredCurve(speed, cf, low if band else None, high if band else None, **test)


@arguments(curve=StribeckCurve, measured=MeasuredCurve, boundary_friction="number")
def deviation_from_measured(curve: StribeckCurve, measured: MeasuredCurve,
                            boundary_friction: float):
    """C_f,dev (eq 35) of the simulated curve against the measured one, at the measured
    speeds inside the simulated range (PCHIP in log speed); NaN outside it."""
    from scipy.interpolate import PchipInterpolator
    order = np.argsort(curve.speed)
    x = np.log(curve.speed[order])
    u = np.log(measured.speed)
    inside = (u >= x[0] - SPEED_MATCH) & (u <= x[-1] + SPEED_MATCH)
    sim = PchipInterpolator(x, curve.friction_coefficient[order])(np.clip(u, x[0], x[-1]))
    deviation = friction_deviation(sim, measured.friction_coefficient, boundary_friction)
    return np.where(inside, deviation, np.nan)
