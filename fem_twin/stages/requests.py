"""A case's sweep requests (:class:`~fem_twin.stribeck.request.SweepRequest`), built in one
place for every command (run, traction, fit, calibrate, compare), and the macro settings
and thermal model they carry."""

from __future__ import annotations

from dataclasses import fields, replace

from ..case import Case
from ..io.layout import RunLayout
from ..macro import MacroSettings
from ..macro.estimate import SPHERE_ORDER
from ..macro.laws.thermal import ContactThermal
from ..macro.laws.viscosity import WaltherLaw
from ..micro import FlowFactors
from ..stribeck.request import RollingSliding, Sliding, SweepRequest
from .geometry import hersey_length, macro_geometry
from .provenance import stage_keys


def sweep_request(case: Case, out: RunLayout, *, factors: FlowFactors | None = None,
                  factors_key: str | None = None, **changes) -> SweepRequest:
    """The sweep of ``case``'s first viscosity over its speeds on the macro gap kept in
    ``out``, with the run's flow factors (``out``'s, keyed by the micro stage) or
    ``factors`` (keyed by ``factors_key``, else by their bits), checkpointed in
    ``out.points``; ``changes``: fields set otherwise (:func:`dataclasses.replace`)."""
    gap, spacing, face, origin = macro_geometry(case, out)
    if factors is None:
        factors, factors_key = FlowFactors.load(out.flow_factors), stage_keys(case)["micro"]
    request = SweepRequest(
        gap, spacing, factors, case.sweep.speeds, load=case.tribometer.load,
        load_share=case.tribometer.load_share,
        lubricant=case.lubricant.lubricants()[0], motion=motion(case),
        oil_temperature=oil_temperature(case),
        hersey_length=hersey_length(case), face=face, origin=origin,
        settings=macro_settings(case), thermal=contact_thermal(case),
        factors_key=factors_key, checkpoint=out.points)
    return replace(request, **changes)


def per_viscosity(case: Case, request: SweepRequest) -> list[SweepRequest]:
    """``request`` at each of the case's viscosities (``[lubricant] viscosities``), at its
    oil temperature (``[lubricant] temperatures``)."""
    return [replace(request, lubricant=lub, oil_temperature=oil_temperature(case, k))
            for k, lub in enumerate(case.lubricant.lubricants())]


def oil_temperature(case: Case, k: int = 0) -> float | None:
    """The oil temperature [C] of viscosity ``k`` where an isothermal twin's boundary law
    reads it (a temperature term, ``[thermal] model = "none"``), else None: the thermal
    model finds its own, and a point without the term does not depend on it (its
    checkpoints' key stays)."""
    if case.thermal.model != "none" or not case.boundary.temperature_coefficient:
        return None
    return float(case.lubricant.temperatures[k])


def motion(case: Case) -> Sliding | RollingSliding:
    """The contact's motion: a pin sliding, or a ball at ``[tribometer] slide_to_roll``."""
    tr = case.tribometer
    return RollingSliding(tr.slide_to_roll) if tr.ball else Sliding()


def macro_settings(case: Case, method: str | None = None) -> MacroSettings:
    """The macro solver settings of a case (``method`` overrides ``[macro] method``), the
    fields another section sets filled from it (:meth:`~fem_twin.case.sections.Case.filled`).

    A ball's contact cavitates at the ambient pressure: the 0.2 bar between p_amb and p_cav
    of Table 6 is nothing beside its GPa, and the thin pressurised layer it forces along
    the sides of the outlet cavity makes the Newton coupling cycle between two states.
    Its smooth sphere converges at second order on the macro grid, which the C_f error
    estimate assumes unless ``[macro] grid_order`` says otherwise."""
    own = {f.name: getattr(case.macro, f.name) for f in fields(MacroSettings)}
    settings = MacroSettings(**{**own, **({"method": method} if method else {})})
    settings = case.filled(settings)
    if case.tribometer.ball:
        settings = replace(settings, cavitation_pressure=settings.ambient_pressure,
                           grid_order=settings.grid_order or SPHERE_ORDER)
    return settings


def contact_thermal(case: Case) -> ContactThermal | None:
    """The run's thermal model (``[thermal]``, the Walther law of ``[lubricant]``),
    or None for the isothermal twin (``model = "none"``)."""
    if case.thermal.model == "none":
        return None
    lb = case.lubricant
    return ContactThermal(case.thermal, WaltherLaw.through(lb.temperatures, lb.viscosities,
                                                           lb.density))
