"""The asperity contact pressure on the macro grid: the nodal values that carry the flow
factors' ``p_con(h0)`` (eq 11) into the load balance (eq 28), the elastic deformation
(eqs 20-22) and the boundary friction (eq 32).

``p_con`` falls by orders of magnitude over a few tens of nanometres of ``h0``, about what
``h0`` changes across one pixel of a crowned face, so read at the nodes (the paper,
``"nodal"``) it misjudges the load the pixels around a node carry.  ``"gauss"`` (the
default) gives each node the Galerkin load over the Q1 film, lumped:

    p_i = int p_con(h0_h(x)) phi_i(x) dx / int phi_i(x) dx,

with ``h0_h`` the bilinear interpolant of the nodal separations, by the Gauss rule of
:data:`GAUSS_ORDER` points a pixel side; ``sum_i a_i p_i`` is then the contact load of the
whole film (docs/accuracy.md, "The contact pressure on the macro grid")."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import scipy.sparse as sp

from ...micro.flow_factors import REL_STEP
from ...numerics.assembly import CORNERS, at_points, grid_stencil
from ...numerics.graded_mesh import Mesh

#: the rules of ``MacroSettings.contact_quadrature``
RULES = ("gauss", "nodal")
#: the Gauss rule's order, its points per pixel side: p_con varies by a factor of about 5
#: over a pixel at 128^2 in the mixed regime; 3 points integrate its exponential-like
#: profile there to 1e-4
GAUSS_ORDER = 3


#: pixels evaluated at a time: bounds the transients (the film and p_con at the Gauss
#: points, 72 B a pixel each) to a block of the grid
BLOCK = 1 << 16


class ContactLoad:
    """The ``"gauss"`` rule on one node grid ``shape`` (ny, nx): :meth:`pressure` and its
    derivative :meth:`derivative` (the Newton coupling's Jacobian).  Pixels are taken a
    block of rows at a time, their corners by slicing (:data:`fem_twin.numerics.assembly.CORNERS`),
    so nothing is kept per pixel."""

    def __init__(self, shape, order: int = GAUSS_ORDER, area=None):
        ny, nx = shape
        self.shape, self.n = (ny, nx), ny * nx
        self.area = area            # a graded mesh's element areas (ny - 1, nx - 1) [m^2]
        x, w = np.polynomial.legendre.leggauss(order)
        x, w = (x + 1) / 2, w / 2                                         # on [0, 1]
        s, t = (v.ravel() for v in np.meshgrid(x, x))                     # s: x1, t: x2
        self.phi = np.stack([(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t])  # (4, nq)
        self.wphi = self.phi * np.outer(w, w).ravel()
        corner_mass = self.wphi.sum(1)
        self.mass = np.zeros(self.shape)
        for r0, r1 in self._blocks():
            self._to_nodes(self.mass, np.broadcast_to(corner_mass[:, None, None],
                                                      (4, r1 - r0, nx - 1)), r0)

    def _blocks(self):
        """``(r0, r1)``: the pixel rows of each block."""
        rows = max(1, BLOCK // (self.shape[1] - 1))
        return [(r0, min(r0 + rows, self.shape[0] - 1))
                for r0 in range(0, self.shape[0] - 1, rows)]

    def _to_nodes(self, out, per_pixel, r0) -> None:
        """Add ``(4, rows, nx - 1)`` contributions of the pixels' corners onto the nodes."""
        rows, nx = per_pixel.shape[1], self.shape[1]
        per_pixel = self._weighted(per_pixel, r0)
        for (a, b), values in zip(CORNERS, per_pixel):
            out[r0 + a:r0 + a + rows, b:nx - 1 + b] += values

    def _weighted(self, per_pixel, r0) -> np.ndarray:
        """``(..., rows, nx - 1)`` pixel values times their area (a graded mesh's)."""
        if self.area is None:
            return per_pixel
        return per_pixel * self.area[r0:r0 + per_pixel.shape[-2]]

    def at_gauss(self, h0, r0, r1) -> np.ndarray:
        """The bilinear interpolant of the nodal ``h0`` at the Gauss points of the pixel rows
        ``r0 .. r1 - 1``, ``(nq, rows, nx - 1)``."""
        return at_points(self.phi, h0, r0, r1)

    def pressure(self, factors, h0) -> np.ndarray:
        """Nodal contact pressure [Pa] of the film ``h0`` (ny, nx) [m] (module docstring)."""
        out = np.zeros(self.shape)
        for r0, r1 in self._blocks():
            p = factors.contact_pressure(self.at_gauss(h0, r0, r1))
            self._to_nodes(out, (self.wphi @ p.reshape(p.shape[0], -1)).reshape(
                4, *p.shape[1:]), r0)
        return out / self.mass

    def derivative(self, factors, h0, free=None) -> sp.csr_matrix:
        """``d p_i / d h0_j`` [Pa/m], ``(n, n)`` on the 3 x 3 stencil; columns of the nodes
        not ``free`` (floored separations, which do not move) are zero."""
        stencil = grid_stencil(self.shape)
        S = np.zeros((*self.shape, 3, 3))
        for r0, r1 in self._blocks():
            hq = self.at_gauss(h0, r0, r1)
            eps = REL_STEP * hq
            slope = (factors.contact_pressure(hq + eps)
                     - factors.contact_pressure(hq - eps)) / (2 * eps)        # (nq, rows, nx-1)
            stencil.add_elements(S, self._weighted(
                np.einsum("aq,bq,qrc->abrc", self.wphi, self.phi, slope), r0), r0)
        D = sp.diags(1 / self.mass.ravel()) @ stencil.csr(S)
        return D if free is None else D @ sp.diags(np.ravel(free).astype(float))


@lru_cache(maxsize=4)
def contact_load(shape, mesh: Mesh | None = None) -> ContactLoad:
    """The (cached) :class:`ContactLoad` of a grid, or of a graded ``Mesh``."""
    if mesh is None:
        return ContactLoad(tuple(shape))
    h1, h2 = mesh.sizes
    return ContactLoad(mesh.shape, area=h2[:, None] * h1[None, :])


def nodal_contact_pressure(factors, h0, rule: str, mesh: Mesh | None = None) -> np.ndarray:
    """The nodal contact pressure [Pa] of the film ``h0`` [m] by ``rule`` (:data:`RULES`)
    on the grid or a graded ``Mesh``."""
    if rule == "nodal":
        return factors.contact_pressure(h0)
    return contact_load(np.shape(h0), mesh).pressure(factors, h0)
