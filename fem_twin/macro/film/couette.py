"""The Couette term of eq 17, ``div(q (1 - theta))``, on the dual cells of the node grid.

Every face between neighbouring nodes ``a -> b`` carries the liquid flux
``width * q_f * s_up`` (``s = 1 - theta``) out of ``a``'s dual cell into ``b``'s, so mass is
conserved face by face.  The liquid fraction is always the upstream node's: in a cavity the
equation is pure transport of ``s h``, and only an upwind ``s`` keeps theta in [0, 1] and
monotone.  The face value of ``q = rho h_m u_m b``: ``"central"`` (default),
``q_f = (q_a + q_b) / 2`` (Ausas, Jai and Buscaglia, J. Tribol. 131, 2009, 031702), second
order in full film and ``q_f s_up`` constant along the flow in a cavity (docs/accuracy.md);
``"upwind"``, ``q_f = q_up``, the paper's first-order flux (a numerical diffusion
``|q| dx / 2``).  As face matrices, per direction ``k``: ``outflow = D_k ((J_k q_k) *
(U_k s))`` with ``D`` the signed face widths, ``J`` the face coefficient and ``U`` the
upwind pick, so the Newton coupling gets both derivatives (:meth:`Couette.matrix`,
:meth:`Couette.q_derivatives`)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.sparse as sp

from ...errors import InputError
from ...numerics.assembly import grid_stencil
from ...numerics.graded_mesh import Mesh

#: the Couette schemes (``MacroSettings.couette``, ``solve_reynolds(couette=...)``)
SCHEMES = ("central", "upwind")


@dataclass(frozen=True, eq=False)
class Couette:
    """The Couette outflow of every dual cell at fixed upwinding.

    ``parts``: per direction ``(D, q_f, J, U)``, with ``D`` (n x faces) the signed face
    widths [m], ``q_f`` the face values of the Couette coefficient [m^2/s], ``J`` (faces x
    n) their derivative in the nodal coefficient, and ``U`` (faces x n) the upwind pick.
    """

    parts: tuple

    def matrix(self) -> sp.csr_matrix:
        """``B`` with ``B @ (1 - theta)`` the net outflow of each dual cell [m^3/s]."""
        return sum(D @ sp.diags(q_f) @ U for D, q_f, J, U in self.parts).tocsr()

    def q_derivatives(self, s) -> tuple:
        """Per direction, the derivative of the outflow with respect to ``q_k`` at the
        liquid fraction ``s = 1 - theta`` (upwinding fixed)."""
        return tuple((D @ sp.diags(U @ s) @ J).tocsr() for D, q_f, J, U in self.parts)

    def size(self) -> np.ndarray:
        """Each node's Couette flux magnitude ``sum |D| |q_f|`` [m^3/s] (residual scales)."""
        return sum(abs(D) @ np.abs(q_f) for D, q_f, J, U in self.parts)


def couette(q1, q2, spacing, scheme: str = "central") -> Couette:
    """The :class:`Couette` term of the nodal coefficient ``(q1, q2)`` (ny, nx) [m^2/s] on a
    non-periodic grid of spacing ``(dx1, dx2)`` [m] or a graded ``Mesh``."""
    q1, q2 = _checked(q1, q2, scheme)
    parts = []
    for k, q in enumerate((q1, q2)):
        D, mean, a, b = _faces(q1.shape, spacing if isinstance(spacing, Mesh)
                               else tuple(float(v) for v in spacing), k)
        q = q.ravel()
        forward = mean @ q >= 0
        U = _pick(np.where(forward, a, b), q.size)
        J = mean if scheme == "central" else U
        parts.append((D, J @ q, J, U))
    return Couette(tuple(parts))


def couette_matrix(q1, q2, spacing, scheme: str = "central") -> sp.csr_matrix:
    """``B`` with ``B @ (1 - theta)`` the net Couette outflow of each node's dual cell
    [m^3/s], :meth:`Couette.matrix` added face by face into the grid's 3 x 3 stencil
    (:func:`fem_twin.numerics.assembly.grid_stencil`, the pattern of the Poiseuille matrix, zeros
    where no face couples): no face matrices kept (which a grid would keep: 180 B a node),
    no sort of triplets, and one pattern for every coefficient and flow direction (the
    Newton steps map it into their matrix once per grid)."""
    q1, q2 = _checked(q1, q2, scheme)
    stencil = grid_stencil(q1.shape)
    S = np.zeros((*q1.shape, 3, 3))
    for k, q in enumerate((q1, q2)):
        width = face_width(spacing, k)
        q_a, q_b = (q[:, :-1], q[:, 1:]) if k == 0 else (q[:-1, :], q[1:, :])
        forward = q_a + q_b >= 0
        flux = width * ((q_a + q_b) / 2 if scheme == "central" else np.where(forward, q_a, q_b))
        from_a, from_b = np.where(forward, flux, 0.0), np.where(forward, 0.0, flux)
        # node a's row gains the flux from the upstream node, b's loses it: (row, column
        # offset) of a -> a and a -> b, then b -> a and b -> b
        ahead = (1, 2) if k == 0 else (2, 1)
        behind = (1, 0) if k == 0 else (0, 1)
        rows_a = (slice(None), slice(0, -1)) if k == 0 else (slice(0, -1), slice(None))
        rows_b = (slice(None), slice(1, None)) if k == 0 else (slice(1, None), slice(None))
        S[(*rows_a, 1, 1)] += from_a
        S[(*rows_a, *ahead)] += from_b
        S[(*rows_b, *behind)] -= from_a
        S[(*rows_b, 1, 1)] -= from_b
    return stencil.csr(S)


def _checked(q1, q2, scheme):
    if scheme not in SCHEMES:
        raise InputError(f"couette scheme must be one of {SCHEMES}, got {scheme!r}")
    return np.asarray(q1, float), np.asarray(q2, float)


def _face_nodes(shape, spacing, k):
    """The two nodes ``a -> b`` of each face along direction ``k`` (0: x1, columns; 1: x2,
    rows) and the faces' width [m]."""
    ny, nx = shape
    idx = np.arange(ny * nx).reshape(ny, nx)
    a, b = (idx[:, :-1], idx[:, 1:]) if k == 0 else (idx[:-1, :], idx[1:, :])
    width = face_width(spacing, k)
    return a.ravel(), b.ravel(), (width if np.ndim(width) == 0
                                  else np.broadcast_to(width, a.shape).ravel())


def face_width(spacing, k):
    """The width [m] of the faces along direction ``k`` (0: x1, 1: x2) between two nodes:
    the grid's other pitch, or on a graded ``Mesh`` the dual cell's width of
    each face's row (``(ny, 1)``, k = 0) or column (``(1, nx)``, k = 1)."""
    if isinstance(spacing, Mesh):
        w1, w2 = spacing.widths
        return w2[:, None] if k == 0 else w1[None, :]
    return float(spacing[1] if k == 0 else spacing[0])


@lru_cache(maxsize=16)
def _faces(shape, spacing, k):
    """Faces along direction ``k`` of a grid (:func:`_face_nodes`): the signed width matrix
    ``D`` (n x faces), the face-mean matrix (faces x n) and the two nodes ``a -> b`` of
    each face."""
    a, b, width = _face_nodes(shape, spacing, k)
    nf, n, f = a.size, shape[0] * shape[1], np.arange(a.size)
    D = sp.csr_matrix((np.r_[np.broadcast_to(width, nf), -np.broadcast_to(width, nf)],
                       (np.r_[a, b], np.r_[f, f])), shape=(n, nf))
    mean = sp.csr_matrix((np.full(2 * nf, 0.5), (np.r_[f, f], np.r_[a, b])), shape=(nf, n))
    return D, mean, a, b


def _pick(nodes, n) -> sp.csr_matrix:
    """The (len(nodes) x n) matrix that reads ``nodes`` of a nodal vector."""
    return sp.csr_matrix((np.ones(nodes.size), nodes, np.arange(nodes.size + 1)),
                         shape=(nodes.size, n))
