"""Fitting the twin's unknowns to measured Stribeck curves, with 95 % intervals.

Parameters by their case-file keys (none re-runs the micro stage): a boundary law's
(:func:`fem_twin.macro.laws.boundary_laws.fitted_parameters`; the law owns them,
:meth:`~fem_twin.macro.laws.boundary_laws.Law.fit_force`), e.g. ``boundary_friction``
(C_f,b of eq 32); ``temperature``, one oil temperature per curve through the case's Walther
law (the curve at ``mu_S`` gives the one at ``mu`` at speeds ``U mu / mu_S``: the Hersey
collapse, eq 46); ``load_share``, the pin face's share of the load (swept at
:data:`LOAD_SHARES`); ``bulk_resistance``, the thermal twin's R_b [K/W] (swept at
:data:`RESISTANCES`); swept parameters are interpolated by PCHIP per speed.

Least squares on C_f,dev (eq 35) at the measured speeds (PCHIP in log speed), weighted by
``sigma = (cf_max - cf_min) / 1.693`` where the CSV gives its scatter, else equal weights
with the HC3 covariance (:func:`.fit_statistics.covariance`); intervals
``t_{0.975, n - p}`` times its diagonal's root."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import PchipInterpolator

from ..errors import InputError, NotConverged
from ..macro.laws.boundary_friction import BoundaryLaw
from ..macro.laws.boundary_laws import LAWS, fitted_law, fitted_parameters
from ..macro.laws.viscosity import WaltherLaw
from .curve import SPEED_MATCH, MeasuredCurve, StribeckCurve
from .fit_statistics import fit_summary
from .identify import check_pair

#: the parameters :func:`fit_curves` fits besides the boundary laws' (case-file keys)
OWN = ("temperature", "load_share", "bulk_resistance")


def parameters() -> tuple:
    """The parameters :func:`fit_curves` can fit (case-file keys), in the order of a fit's
    unknowns: the default boundary law's (eq 32's C_f,b), the fit's own (:data:`OWN`),
    then the other registered laws' (:data:`~fem_twin.macro.laws.boundary_laws.LAWS`)."""
    first = LAWS[BoundaryLaw().law]
    return (*first.fitted, *OWN, *(name for name in fitted_parameters()
                                   if name not in first.fitted))


#: :func:`parameters` at import: what the command line offers
PARAMETERS = parameters()
#: the face's shares of the imposed load swept for a ``load_share`` fit (its bounds)
LOAD_SHARES = (0.5, 0.625, 0.75, 0.875, 1.0)
#: the rig's thermal resistances [K/W] swept for a ``bulk_resistance`` fit (its bounds)
RESISTANCES = (0.0, 1.0, 2.0, 4.0)
#: expected range of three normal samples in standard deviations (d2 of n = 3)
RANGE_OF_THREE = 1.693


@dataclass(frozen=True)
class Readings:
    """What a boundary law's fit reads of one simulated curve at the measured speeds
    (:meth:`~fem_twin.macro.laws.boundary_laws.Law.fit_force`): the ``speed`` [m/s], ``read(name)``
    the curve's column ``name`` there (None where the curve has none), the simulated
    curves' C_f,b ``boundary_friction``, the law's section ``base`` whose unfitted values
    the fit keeps, and ``film_temperature()`` [C] of the points at the fitted oil."""

    speed: np.ndarray
    read: Callable
    boundary_friction: float
    base: BoundaryLaw
    film_temperature: Callable


@dataclass(frozen=True)
class FitModel:
    """C_f of simulated curves at other C_f,b, oil temperatures and load shares (module
    docstring).  ``curves``: a StribeckCurve per measured curve, swept at ``load_share`` of
    the imposed ``load`` [N]; ``law``: the lubricant's viscosity-temperature law (None
    without temperatures); ``share_curves``: ``((share, StribeckCurve), ...)`` swept at one
    viscosity, ascending, that bracket ``load_share`` (empty: the share is not a parameter);
    ``resistance_curves``: per curve, ``((R_b, StribeckCurve), ...)`` ascending around the
    curves' own ``bulk_resistance`` [K/W] (empty: not a parameter); ``loads``: each
    curve's imposed load [N] (empty: ``load`` for all); ``boundary``: the case's boundary
    law (its ``[boundary]`` section; None: eq 32's constant law at ``boundary_friction``),
    from which a fit of a law's parameters starts and whose unfitted values it keeps
    (:meth:`~fem_twin.macro.laws.boundary_laws.Law.start`: the shear law from a constant case is
    tau_0 = 0 and alpha = ``boundary_friction``).
    """

    curves: tuple
    boundary_friction: float      # C_f,b of the simulated curves
    load: float                   # F_N,imp [N]
    law: WaltherLaw | None
    load_share: float = 1.0
    share_curves: tuple = ()
    bulk_resistance: float = 0.0
    resistance_curves: tuple = ()
    boundary: BoundaryLaw | None = None
    loads: tuple = ()

    @property
    def section(self) -> BoundaryLaw:
        """The case's ``[boundary]`` section, eq 32's constant law where it gives none."""
        return self.boundary or BoundaryLaw()

    def friction(self, k: int, speed, viscosity: float, values: dict | None = None,
                 share: float | None = None, resistance: float | None = None):
        """C_f of curve ``k`` at ``speed`` [m/s] for mu_0 [Pa s], a boundary law's fitted
        ``values`` (case-file keys of one law's
        :attr:`~fem_twin.macro.laws.boundary_laws.Law.fitted`; None or empty: the curves' own
        boundary force), the face's ``share`` of the load and the rig's thermal
        ``resistance`` [K/W] (None: the curves' own); and the mask of speeds whose Hersey
        number lies inside the simulated range (ends held outside)."""
        load = self.loads[k] if self.loads else self.load
        at = lambda c: self._at(c, speed, viscosity, values, load)  # noqa: E731
        cf, inside = at(self.curves[k])
        for value, own, swept in ((share, self.load_share, self.share_curves),
                                  (resistance, self.bulk_resistance,
                                   self.resistance_curves[k] if self.resistance_curves
                                   else ())):
            if value is None or value == own or not swept:
                continue
            values_ = [at(c) for _, c in swept]
            grid = PchipInterpolator([s for s, _ in swept], np.stack([v[0] for v in values_]),
                                     axis=0)
            cf = cf + grid(value) - grid(own)
            inside = inside & np.all([v[1] for v in values_], axis=0)
        return cf, inside

    def reader(self, c: StribeckCurve, speed, viscosity: float):
        """``(at, inside)``: ``at(values)`` reads a column of curve ``c`` at ``speed`` [m/s]
        for the oil of ``viscosity`` [Pa s] (PCHIP in log speed at the Hersey-shifted
        speeds, held at the ends), ``inside`` the mask of speeds within the curve's."""
        order = np.argsort(c.speed)
        x = np.log(c.speed[order])
        u = np.log(np.asarray(speed, float) * viscosity / c.viscosity)
        inside = (u >= x[0] - SPEED_MATCH) & (u <= x[-1] + SPEED_MATCH)
        return (lambda a: PchipInterpolator(x, a[order])(np.clip(u, x[0], x[-1])), inside)

    def _at(self, c: StribeckCurve, speed, viscosity: float, values: dict | None,
            load: float):
        at, inside = self.reader(c, speed, viscosity)
        hd = at(c.hydrodynamic_friction)
        if not values:                     # the curves' own boundary force, as simulated
            return (hd + self.boundary_friction * at(c.boundary_force)
                    / self.boundary_friction) / load, inside
        law = fitted_law(values)
        readings = Readings(
            speed, lambda name: None if getattr(c, name) is None else at(getattr(c, name)),
            self.boundary_friction, law.start(self.section, self.boundary_friction),
            lambda: self._film_temperature(c, at, viscosity))
        return (hd + law.fit_force(readings, values)) / load, inside

    def _film_temperature(self, c: StribeckCurve, at, viscosity: float):
        """The film temperature [C] of curve ``c``'s points read at the oil of ``viscosity``:
        the curve's own (the thermal model's) moved by the two oils' difference, or the
        oil's (isothermal); the reference temperature where the case gives no Walther law."""
        oil = (lambda mu: float(self.law.temperature(mu))) if self.law is not None else None
        if c.contact_temperature is not None and np.all(np.isfinite(c.contact_temperature)):
            shift = oil(viscosity) - oil(c.viscosity) if oil else 0.0
            return at(c.contact_temperature) + shift
        if oil is None:
            return self.section.reference_temperature
        return oil(viscosity)


def check_parameters(params) -> None:
    """Refuse an empty list, a name outside :func:`parameters`, and a set the data cannot
    identify: the parameters of two boundary laws (each replaces the other)."""
    unknown = set(params) - set(parameters())
    if unknown or not params:
        raise InputError(f"unknown fit parameter(s) {sorted(unknown)}; choose from "
                         f"{list(parameters())}")
    fitted_law(params)


def boundary_values(values: dict) -> dict:
    """The boundary law's fitted parameters among ``values`` (by name)."""
    law = fitted_law(values)
    return {} if law is None else {k: v for k, v in values.items() if k in law.fitted}


def check_loads(params, loads) -> None:
    """Refuse tau_0 with alpha from curves at fewer than two ``loads`` [N]: along a curve
    the real contact area and the asperity load grow together, so one load does not
    separate them."""
    if {"shear_strength", "pressure_coefficient"} <= set(params) and len(set(loads)) < 2:
        raise InputError("shear_strength and pressure_coefficient need measured curves at two "
                         "or more loads (a load_N column in each CSV): along a curve the "
                         "real contact area and the asperity load grow together; or fit one "
                         "of them (the other keeps its [boundary] value)")


def fit_curves(model: FitModel, measured, params, *, start_temperatures,
               verbose: bool = False) -> dict:
    """Fit ``params`` (a subset of :data:`PARAMETERS`) to the ``measured`` curves
    (:class:`MeasuredCurve`, one per ``model.curves``); ``start_temperatures`` [C] start the
    temperature of each curve; without ``temperature`` they are the known temperatures, or,
    when None, each simulated curve keeps its own viscosity (``model.law`` may be None).
    Returns ``{name: {"value", "low", "high"}}`` (:func:`interval`; ``temperature_K`` and
    its ``viscosity_K`` per curve K from 1) with the residuals and the fit's statistics.
    ``verbose``: a line per iteration (scipy's).  Raises :class:`~fem_twin.errors.InputError`
    when no parameter set fits (:func:`check_misfit`)."""
    _check_model(model, measured, params, start_temperatures)
    names, x0, lower, upper = _unknowns(model, params, len(measured), start_temperatures)

    def unpack(x):
        """The boundary law's values, the viscosity [Pa s] of each curve, the face's load
        share and R_b."""
        v = dict(zip(names, x))
        temps = [v.get(f"temperature_{k + 1}") for k in range(len(measured))]
        if temps[0] is None:                          # known temperatures, or the curves'
            mus = ([c.viscosity for c in model.curves] if start_temperatures is None
                   else [float(model.law.viscosity(t)) for t in start_temperatures])
        else:
            mus = [float(model.law.viscosity(t)) for t in temps]
        return boundary_values(v), mus, v.get("load_share"), v.get("bulk_resistance")

    measured, dropped = _inside(model, measured, *unpack(x0))
    sigma = [_sigma(m) for m in measured]
    weighted = all(s is not None for s in sigma)
    identified = check_pair(model, measured, params, unpack(x0)[1], sigma)

    def residuals(x):
        values, mus, share, resistance = unpack(x)
        out = []
        for k, m in enumerate(measured):
            cf, _ = model.friction(k, m.speed, mus[k], values, share, resistance)
            r = (cf - m.friction_coefficient) / model.boundary_friction
            out.append(r / (sigma[k] / model.boundary_friction) if weighted else r)
        return np.concatenate(out)

    n = sum(m.speed.size for m in measured)
    if n <= x0.size:
        raise InputError(f"{n} measured points cannot fit {x0.size} parameters")
    from scipy import optimize  # imported here: the CLI reads PARAMETERS
    # solved over each unknown's range mapped to [0, 1]: the difference steps then suit
    # C_f,b, a temperature [C] and tau_0 [Pa] alike (tau_0 starts at 0)
    low, span = np.array(lower), np.array(upper) - np.array(lower)
    sol = optimize.least_squares(lambda z: residuals(low + z * span), (x0 - low) / span,
                                 bounds=(0.0, 1.0), x_scale="jac", verbose=2 if verbose else 0)
    if not sol.success:
        raise NotConverged(f"fit did not converge: {sol.message}", [float(sol.cost)])
    sol.x, sol.jac = low + sol.x * span, sol.jac / span
    out = fit_summary(model, measured, names, sol, weighted, unpack, (lower, upper))
    out["fit"].update(points_not_counted=dropped, **identified)
    out["fit"]["warnings"] += [f"curve {k + 1}: {n} measured point(s) outside the simulated "
                               "speeds not counted" for k, n in enumerate(dropped) if n]
    check_misfit(out, names, sol.x, lower, upper)
    return out


def _unknowns(model, params, n_curves, start_temperatures):
    """Names, start values and bounds of the unknowns, in the order of :func:`parameters`:
    the boundary law's (:meth:`~fem_twin.macro.laws.boundary_laws.Law.unknowns`: C_f,b in [1e-4,
    1]), a temperature per curve in [-30, 250] C, the load share over
    :attr:`FitModel.share_curves`, R_b over :attr:`FitModel.resistance_curves`."""
    law = fitted_law(params)
    boundary = {} if law is None else {
        row[0]: row for row in law.unknowns(model.section, model.boundary_friction)}
    rows = []
    for name in parameters():
        if name not in params:
            continue
        if name == "temperature":
            rows += [(f"temperature_{k + 1}", float(t), -30.0, 250.0)
                     for k, t in zip(range(n_curves), start_temperatures)]
        elif name == "load_share":
            lo, hi = model.share_curves[0][0], model.share_curves[-1][0]
            rows.append(("load_share", min(max(model.load_share, lo), hi), lo, hi))
        elif name == "bulk_resistance":
            lo, hi = model.resistance_curves[0][0][0], model.resistance_curves[0][-1][0]
            rows.append(("bulk_resistance", min(max(model.bulk_resistance, lo), hi), lo, hi))
        else:
            rows.append(boundary[name])
    names, x0, lower, upper = zip(*rows)
    return list(names), np.array(x0, float), list(lower), list(upper)


#: a fit is refused when its rms C_f,dev exceeds this share of C_f,b without measured
#: scatter (the paper's repeated tests scatter by about +-10 %)
MISFIT_RMS = 0.05
#: ... or, with the measured scatter as weights, when chi^2 is this improbable
MISFIT_P = 1e-3


def check_misfit(result: dict, names, x, lower, upper) -> None:
    """Refuse a fit that no parameter set achieves: C_f,b or a temperature pinned at its
    bound, or residuals beyond the measured scatter (chi^2 p-value below
    :data:`MISFIT_P`), or, without scatter, an rms C_f,dev above :data:`MISFIT_RMS`."""
    f = result["fit"]
    worst = max(((abs(d), r["curve"], u, d) for r in result["residuals"]
                 for u, d in zip(r["speed_m_s"], r["cf_dev"])))
    where = (f"rms C_f,dev {f['rms_cf_dev']:.1%} of C_f,b, largest {worst[3]:+.1%} at "
             f"{worst[2]:.3g} m/s on curve {worst[1]}")
    free = {"load_share", "bulk_resistance"} | {
        name for law in LAWS.values() for name in law.fitted if name not in law.limits}
    pinned = [n for n, v, lo, hi in zip(names, x, lower, upper)
              if n not in free and min(v - lo, hi - v) <= 1e-6 * (hi - lo)]
    if f["weights"] == "equal":
        bad = f["rms_cf_dev"] > MISFIT_RMS
    else:
        from scipy import stats
        bad = stats.chi2.sf(f["chi2"], f["degrees_of_freedom"]) < MISFIT_P
    if pinned or bad:
        raise InputError(f"no parameter set fits the measured curve(s): {where}"
                         + (f"; {', '.join(pinned)} at the bound of its range" if pinned
                            else "") + "; was it measured at the case's load, in m/s, with "
                         "the case's lubricant?")


def _inside(model: FitModel, measured, values, mus, share, resistance) -> tuple:
    """The ``measured`` curves cut to the points inside the simulated curves' Hersey range
    at the start values (C_f there would be held at the ends), and how many each lost;
    a curve with none inside is refused."""
    kept, dropped = [], []
    for k, m in enumerate(measured):
        inside = model.friction(k, m.speed, mus[k], values, share, resistance)[1]
        if not inside.any():
            raise InputError(f"measured curve {k + 1}: all {m.speed.size} points lie outside "
                             "the simulated speeds; sweep its speeds, or leave it out")
        cut = lambda a: None if a is None else np.asarray(a)[inside]  # noqa: E731
        kept.append(MeasuredCurve(m.speed[inside], m.friction_coefficient[inside],
                                  cut(m.low), cut(m.high)))
        dropped.append(int((~inside).sum()))
    return kept, dropped


def _check_model(model: FitModel, measured, params, start_temperatures) -> None:
    """Refuse ``params`` the ``model``'s curves cannot fit to ``measured``, before any
    least squares."""
    check_parameters(params)
    if len(measured) != len(model.curves):
        raise InputError(f"{len(measured)} measured curves for {len(model.curves)} simulated")
    if "temperature" in params and start_temperatures is None:
        raise InputError("fitting the temperature needs start temperatures [C]")
    if "load_share" in params and len(model.share_curves) < 2:
        raise InputError("fitting the load share needs sweeps at two or more load shares "
                         "(FitModel.share_curves)")
    if "bulk_resistance" in params and len(model.resistance_curves) != len(model.curves):
        raise InputError("fitting the thermal resistance needs every curve swept at two or "
                         "more resistances (FitModel.resistance_curves)")
    _check_columns(model, params)
    check_loads(params, model.loads or (model.load,))


def _check_columns(model: FitModel, params) -> None:
    """Refuse a boundary law's fit on curves without the columns the law reads
    (:attr:`~fem_twin.macro.laws.boundary_laws.Law.columns`: the shear law's integrals, absent
    from a run of an older fem_twin) or, for a temperature term, without a temperature that
    varies: the spots' flash of the thermal model, or, isothermal, oils at two temperatures
    (a Walther law)."""
    law = fitted_law(params)
    if law is None:
        return
    for name in law.columns(params, model.law is not None):
        if any(getattr(c, name) is None for c in model.curves):
            raise InputError(f"fitting {', '.join(p for p in params if p in law.fitted)} "
                             f"needs each simulated curve's {name} (" + (
                                 "a run with [thermal] model = \"flash\"), or curves at "
                                 "two oil temperatures" if name == "spot_rise" else
                                 "run the case again with this fem_twin)"))


def _sigma(m: MeasuredCurve):
    if m.low is None or m.high is None:
        return None
    s = (np.asarray(m.high) - np.asarray(m.low)) / RANGE_OF_THREE
    return np.maximum(s, 1e-3 * np.abs(m.friction_coefficient).max())
