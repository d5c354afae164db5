"""The record of one evaluation of the coupled macro problem (eqs 17-30) at a state: what
the couplings compute and the converged point (:func:`.result.mixed_result`) reads.

Both couplings produce an :class:`Evaluation`; the partitioned ones
(:mod:`.partitioned`) add what their updates need (:class:`PartitionedEvaluation`), the
monolithic Newton coupling (:mod:`.newton`) its residuals and operators
(:class:`NewtonEvaluation`).  Fields are SI: pressures [Pa] above ``p_cav`` for ``p``,
absolute for ``p_con``; lengths [m]; loads [N].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ...micro.flow_factors import LocalFactors


@dataclass(frozen=True, eq=False)
class Evaluation:
    """``p``: film pressure ``p_hd - p_cav``; ``theta``: cavity fraction; ``h0``: local
    separation (eq 19, floored); ``loc``: the flow factors there; ``mu``, ``rho``: viscosity
    [Pa s] and density ratio (eqs 23-24); ``p_con``: the contact pressure in the load and
    the deformation; ``F``: the load carried (eq 28), ``F_hd`` its film part."""

    p: np.ndarray
    theta: np.ndarray
    h0: np.ndarray
    loc: LocalFactors
    mu: np.ndarray
    rho: np.ndarray
    p_con: np.ndarray
    F: float
    F_hd: float


@dataclass(frozen=True, eq=False)
class PartitionedEvaluation(Evaluation):
    """... and for the partitioned couplings' updates: ``p_prev``, the pressure the
    coefficients were taken at; ``p_con_target``, ``p_con(h0)`` (eq 26's target);
    ``h_el_new``, the elastic deformation of this pressure (eqs 20-22)."""

    p_prev: np.ndarray
    p_con_target: np.ndarray
    h_el_new: np.ndarray


@dataclass(frozen=True, eq=False)
class NewtonEvaluation(Evaluation):
    """... and for the Newton coupling: ``phi``, the cavitation unknown; ``touching``, nodes
    at the gap floor; ``g``, ``q``: the Poiseuille and Couette coefficients; ``K``, ``B``
    their operators and ``couette`` the flux (:mod:`.couette`); the residuals ``R`` (mass,
    interior), ``G`` (deformation), ``L`` (load) and ``size``, each node's flux size."""

    phi: np.ndarray
    touching: np.ndarray
    g: np.ndarray
    q: np.ndarray
    K: sp.spmatrix
    B: sp.spmatrix
    couette: object
    R: np.ndarray
    size: np.ndarray
    G: np.ndarray
    L: float
