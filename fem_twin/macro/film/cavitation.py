"""Cavitation models of the homogenised Reynolds equation: their contract and registry
(``MacroSettings(complementarity=...)``, ``solve_reynolds(..., complementarity=...)``).

JFO cavitation (eq 18) couples ``p = p_hd - p_cav`` and the cavity fraction ``theta`` by
``p theta = 0``, ``p >= 0``, ``theta >= 0``, in one unknown per node, ``phi``.  A model
provides ``solve(K, B, dirichlet, p_boundary, scale, *, phi0, tol, max_iter, inexact[,
settle])``, the interior's ``K p + B (1 - theta) = 0`` with ``p = p_boundary``, ``theta = 0``
at the Dirichlet nodes, returning ``(phi, iterations, residual history)`` (``settle`` where
the class's ``settles`` is true); ``split(phi, scale) -> (p, theta)`` and
``unknown(p, theta, scale)`` (warm starts); and ``derivatives(phi, scale)``,
``(dp/dphi, d(1 - theta)/dphi)`` for the Newton coupling's Jacobian (:mod:`.newton`).
Adding one: ARCHITECTURE.md, "Adding a cavitation model"."""

from __future__ import annotations

import numpy as np

from ...checks import registered
from .fbns import solve_complementarity_fb
from .switch import solve_complementarity


class PThetaSwitch:
    """``p = max(phi, 0)``, ``theta = max(-phi, 0) / scale``: ``p theta = 0`` exact, the
    residual piecewise linear in ``phi``, solved by semismooth Newton (primal-dual active
    set, :func:`fem_twin.macro.film.switch.solve_complementarity`)."""

    name = "switch"
    settles = True

    @staticmethod
    def solve(K, B, dirichlet, p_boundary, scale, **options):
        return solve_complementarity(K, B, dirichlet, p_boundary, scale, **options)

    @staticmethod
    def split(phi, scale):
        phi = np.asarray(phi, float)
        return np.maximum(phi, 0), np.maximum(-phi, 0) / scale

    @staticmethod
    def unknown(p, theta, scale):
        return np.where(theta > 0, -theta * scale, np.maximum(p, 0))

    @staticmethod
    def derivatives(phi, scale):
        pressurised = np.asarray(phi) > 0
        return pressurised * 1.0, np.where(pressurised, 0.0, 1.0 / scale)


class FischerBurmeister(PThetaSwitch):
    """The paper's Fischer-Burmeister-Newton-Schur solver (:mod:`.fbns`): the same
    complementarity in the same unknown (``phi = p`` or ``-scale theta``), so it splits and
    linearises as the switch; it differs in the inner solve (5-7x slower, same solution)."""

    name = "fb"
    settles = False

    @staticmethod
    def solve(K, B, dirichlet, p_boundary, scale, **options):
        return solve_complementarity_fb(K, B, dirichlet, p_boundary, scale, **options)


#: the cavitation models by name (``complementarity`` in the settings)
MODELS = {model.name: model() for model in (PThetaSwitch, FischerBurmeister)}


def cavitation_model(name: str):
    """The registered model called ``name`` (:data:`MODELS`)."""
    return registered("complementarity", MODELS, name)
