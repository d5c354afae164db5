"""An operating point's assembled problem: the point, its grid's operators and the disk's
motion.

:func:`macro_problem` builds, from an :class:`~fem_twin.macro.point.OperatingPoint`, the
:class:`Problem` that both couplings (:mod:`.partitioned` and :mod:`.newton`) solve, which
holds the point itself; :meth:`Problem.coefficients` evaluates eq 17's homogenised
Poiseuille and Couette coefficients with Roelands (eq 23) and Dowson-Higginson (eq 24) at a
pressure and a separation field.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cached_property, partial

import numpy as np
import scipy.fft as fft
import scipy.sparse as sp

from ...contact.elastic import ElasticOperator, elastic_operator
from ...micro.flow_factors import FlowFactors
from ...micro.rolling import at_slide_to_roll
from ...numerics.graded_mesh import Mesh, MeshElastic
from ..film.contact_load import nodal_contact_pressure
from ..film.reynolds import OPEN_GAP, fe_poiseuille, trapezoid_weights
from ..film.reynolds_fv import fvm_poiseuille
from ..laws.kinematics import disk_velocity, in_grid_frame, rotations

#: Pressures above this [Pa] (transients of the iteration, far beyond the hardness) are
#: clipped before eqs 23-24 are evaluated (both couplings), so that the Roelands
#: exponential stays finite.
MAX_COEFFICIENT_PRESSURE = 1e10

#: the Poiseuille term of eq 17 by discretisation (``MacroSettings.method``)
POISEUILLE = {"fe": fe_poiseuille, "fvm": fvm_poiseuille}


@dataclass(frozen=True, eq=False)
class Problem:
    """One operating point's problem (SI units): the ``point``
    (:class:`~fem_twin.macro.point.OperatingPoint`: gap, grid, load, speeds, lubricant,
    settings, face), its flow ``factors`` at its slide-to-roll ratio, and what its grid
    assembles once."""

    point: object              # the OperatingPoint (fem_twin.macro.point), checked
    factors: FlowFactors       # the point's, at its slide-to-roll ratio
    poiseuille: Callable[[np.ndarray, np.ndarray | None], sp.csr_matrix]  # (g, A) -> K
    elastic: ElasticOperator | MeshElastic  # eqs 20-22 on the padded grid
    area: np.ndarray           # trapezoid weights [m^2]
    interior: np.ndarray       # flat indices of the interior nodes
    velocity: np.ndarray | None = None  # the disk's velocity / u_r (ny, nx, 2); None: e1

    @cached_property
    def turn(self) -> tuple | None:
        """``(cos phi, sin phi, |v|)`` of the disk's velocity at each node, computed once
        (:func:`.kinematics.rotations`); None for uniform sliding."""
        return None if self.velocity is None else rotations(self.velocity)

    @property
    def shape(self):
        return self.point.gap.shape

    @property
    def mesh(self) -> Mesh | None:
        """The graded mesh, None on a grid."""
        spacing = self.point.spacing
        return spacing if isinstance(spacing, Mesh) else None

    @property
    def boundary(self) -> np.ndarray:
        """(ny, nx) bool: the Dirichlet nodes (all but ``interior``)."""
        mask = np.ones(self.shape, bool)
        mask.ravel()[self.interior] = False
        return mask

    def coefficients(self, p, h0):
        """Eq 17's coefficients at the film pressure ``p`` (relative to p_cav) [Pa] and the
        separation ``h0`` [m]: ``(loc, mu, rho, g, q)`` with ``loc`` the flow factors at
        ``h0`` (its ``p_con`` by ``settings.contact_quadrature``, :mod:`.contact_load`; without
        the shear factors, which :func:`.result.mixed_result` evaluates once),
        ``g = rho h_m^3 / (12 mu)`` [m^3/(Pa s)] and ``q = rho h_m u_m`` [m^2/s], with
        ``loc``'s tensors in the grid frame and ``u_m`` the local speed on a rotating
        disk (:mod:`.kinematics`)."""
        rule = self.point.settings.contact_quadrature
        loc = in_grid_frame(self.factors.at(h0, friction=False, contact=rule == "nodal"),
                            self.turn)
        if rule != "nodal":
            loc = replace(loc, p_con=nodal_contact_pressure(self.factors, h0, rule,
                                                            self.mesh))
        p_coef = np.minimum(p, MAX_COEFFICIENT_PRESSURE)
        mu = self.point.lubricant.viscosity_at(p_coef)
        rho = self.point.lubricant.density_ratio(p_coef)
        g = rho * loc.h_m ** 3 / (12 * mu)
        q = rho * loc.h_m * self.point.u_m
        if self.turn is not None:
            q = q * self.turn[2]
        return loc, mu, rho, g, q

    def kernel(self):
        """The influence kernel on the padded grid (real space, [m/Pa])."""
        ny, nx = self.shape if self.mesh is None else self.mesh.grid_shape
        cache = self.__dict__.setdefault("_kernel", [])
        if not cache:
            cache.append(fft.irfft2(self.elastic.kernel_hat, s=(2 * ny, 2 * nx)))
        return cache[0]

    def dense_elastic(self, nodes) -> np.ndarray:
        """``E[nodes, nodes]``: deformation at node i per pressure at node j [m/Pa]; on a
        graded mesh node j's pressure is its hat function on the grid
        (:meth:`~fem_twin.numerics.graded_mesh.Mesh.to_grid`), summed over its grid nodes."""
        if self.mesh is None:
            ny, nx = self.shape
            r, c = np.divmod(nodes, nx)
            return self.kernel()[(r[:, None] - r[None, :]) % (2 * ny),
                                 (c[:, None] - c[None, :]) % (2 * nx)]
        ny, nx = self.mesh.grid_shape
        kernel = self.kernel()
        r, c = np.divmod(self.mesh.grid_nodes[nodes], nx)
        E = kernel[(r[:, None] - r[None, :]) % (2 * ny), (c[:, None] - c[None, :]) % (2 * nx)]
        hats = self.mesh.prolongation[:, nodes]
        spread = np.flatnonzero(np.diff(hats.indptr) > 1)    # nodes beside a coarse element
        if spread.size:
            hats = hats[:, spread].tocoo()                       # (grid node, column, weight)
            rf, cf = np.divmod(hats.row, nx)
            parts = kernel[(r[:, None] - rf[None, :]) % (2 * ny),
                           (c[:, None] - cf[None, :]) % (2 * nx)] * hats.data
            E[:, spread] = parts @ sp.csr_matrix(
                (np.ones(hats.nnz), (np.arange(hats.nnz), hats.col)),
                shape=(hats.nnz, spread.size)).toarray()
        return E

    @cached_property
    def cells(self) -> np.ndarray:
        """Each node's area in cells of the FFT grid, (n,) (1 on a grid)."""
        if self.mesh is None:
            return np.ones(self.point.gap.size)
        return self.mesh.area.ravel() / (self.mesh.pitch[0] * self.mesh.pitch[1])


def macro_problem(point, factors=None, velocity=None) -> Problem:
    """The :class:`Problem` of the operating ``point`` (an
    :class:`~fem_twin.macro.point.OperatingPoint`, checked): Dirichlet nodes (ambient
    pressure) on the grid's edge and wherever the rigid gap opens beyond ``OPEN_GAP``
    (around the pin face: the oil bath over the holder), the non-periodic FFT half-space of
    eqs 20-22 and the Poiseuille operator of ``settings.method``; ``factors``: the point's
    at its slide-to-roll ratio (None: carried there, :func:`fem_twin.micro.at_slide_to_roll`),
    ``velocity``: the disk's (None: :func:`.kinematics.disk_velocity` of the point's face
    and track radius)."""
    gap, dx, settings = point.gap, point.spacing, point.settings
    if factors is None:
        factors = at_slide_to_roll(point.factors, point.slide_to_roll)
    if velocity is None:
        velocity = disk_velocity(point.face, dx, settings.track_radius)
    boundary = gap > OPEN_GAP
    boundary[[0, -1], :] = boundary[:, [0, -1]] = True
    return Problem(point, factors, partial(_poiseuille, POISEUILLE[settings.method], dx),
                   _elastic(gap.shape, dx, settings.e_reduced),
                   trapezoid_weights(gap.shape, dx), np.flatnonzero(~boundary.ravel()),
                   velocity)


def _poiseuille(assemble, dx, g, A):
    return assemble(g, dx, A)


def _elastic(shape, dx, e_reduced):
    """The half-space on the grid, or through its grid on a graded mesh."""
    if isinstance(dx, Mesh):
        return MeshElastic(dx, elastic_operator(dx.grid_shape, dx.pitch, e_reduced))
    return elastic_operator(shape, dx, e_reduced)
