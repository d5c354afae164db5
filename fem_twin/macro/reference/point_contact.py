"""Concentrated (ball-on-disk) contacts: Hertz, Moes parameters, Hamrock-Dowson films.

A sphere of radius ``R`` on a flat, reduced modulus ``E'`` (eq 22), load ``F``, entrainment
speed ``u_m``, lubricant ``mu_0`` and pressure-viscosity coefficient ``alpha``: Hertz
``a = (3 F R / (2 E'))^(1/3)``, ``p_H = 3 F / (2 pi a^2)``; Hamrock and Dowson's (1977)
``U = mu_0 u_m / (E' R)``, ``W = F / (E' R^2)``, ``G = alpha E'`` and central and minimum
films ``h_c / R = 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 e^(-0.73 k))``,
``h_min / R = 3.63 U^0.68 G^0.49 W^-0.073 (1 - e^(-0.68 k))``; Moes'
``M = W (2U)^(-3/4)``, ``L = G (2U)^(1/4)``.  An elliptical contact (``radius_y = R_y > R_x``,
entrainment along x) takes Hamrock and Brewe's (1983) ``k = 1.0339 (R_y/R_x)^0.636`` and
``E = 1.0003 + 0.5968 R_x/R_y``, ``a = (6 E F R' / (pi k E'))^(1/3)``, ``b = k a``.

In :func:`fem_twin.macro.solve_mixed` a rolling contact at entrainment speed ``u_m`` is
given as ``speed = 2 u_m`` for a stationary ball, or with ``entrainment=u_m`` (eq 17 sees
only ``u_m``; the shear of eq 31 sees the sliding speed)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...numerics.graded_mesh import point_contact_mesh

#: a ball's macro domain in its Hertz half-widths a and b = k a: the inlet, the exit
#: constriction and the side lobes
EXTENT = ((-4.0, 2.0), (-3.0, 3.0))


@dataclass(frozen=True)
class PointContact:
    """A smooth circular EHL contact (SI units)."""

    radius: float              # R [m]
    load: float                # F [N]
    e_reduced: float           # E' [Pa]
    viscosity: float           # mu_0 [Pa s]
    alpha: float               # pressure-viscosity coefficient [1/Pa]
    entrainment: float         # u_m [m/s]
    radius_y: float | None = None   # R_y [m] across the entrainment (None: a sphere)

    def __post_init__(self):
        for name in ("radius", "load", "e_reduced", "viscosity", "entrainment"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"PointContact.{name} must be positive and finite, got {v}")
        if not (np.isfinite(self.alpha) and self.alpha >= 0):
            raise InputError(f"PointContact.alpha must be >= 0 [1/Pa], got {self.alpha}")
        if self.radius_y is not None and not (np.isfinite(self.radius_y)
                                              and self.radius_y >= self.radius):
            raise InputError("PointContact.radius_y must be at least the radius R_x [m], got "
                             f"{self.radius_y}")

    @property
    def ellipticity(self) -> float:
        """k = b/a (Hamrock-Brewe; 1 for a sphere)."""
        if self.radius_y is None or self.radius_y == self.radius:
            return 1.0
        return 1.0339 * (self.radius_y / self.radius) ** 0.636

    @classmethod
    def from_moes(cls, M: float, L: float, *, radius=12.5e-3, e_reduced=110e9,
                  viscosity=0.25, alpha=22e-9) -> "PointContact":
        """The contact with Moes parameters ``M, L`` for the given R, E', mu_0 and alpha
        (``u_m`` from ``L``, then ``F`` from ``M``)."""
        G = alpha * e_reduced
        if not (M > 0 and L > 0 and G > 0):
            raise InputError("M, L and alpha E' must be positive")
        U = (L / G) ** 4 / 2
        W = M * (2 * U) ** 0.75
        return cls(radius, W * e_reduced * radius ** 2, e_reduced, viscosity, alpha,
                   U * e_reduced * radius / viscosity)

    @property
    def hertz_radius(self) -> float:
        """a [m], the contact's half-width along the entrainment."""
        if self.ellipticity == 1.0:
            return (3 * self.load * self.radius / (2 * self.e_reduced)) ** (1 / 3)
        k, rx, ry = self.ellipticity, self.radius, self.radius_y
        r = 1 / (1 / rx + 1 / ry)
        e = 1.0003 + 0.5968 * rx / ry
        return (6 * e * self.load * r / (np.pi * k * self.e_reduced)) ** (1 / 3)

    @property
    def hertz_pressure(self) -> float:
        """p_H [Pa]."""
        return 3 * self.load / (2 * np.pi * self.ellipticity * self.hertz_radius ** 2)

    @property
    def groups(self) -> tuple:
        """Hamrock-Dowson ``(U, W, G)``."""
        E, R = self.e_reduced, self.radius
        return (self.viscosity * self.entrainment / (E * R), self.load / (E * R ** 2),
                self.alpha * E)

    @property
    def moes(self) -> tuple:
        """``(M, L)``."""
        U, W, G = self.groups
        return W * (2 * U) ** -0.75, G * (2 * U) ** 0.25

    def hamrock_dowson(self) -> tuple:
        """``(h_c, h_min)`` [m] of the Hamrock-Dowson fits (k = 1)."""
        U, W, G = self.groups
        k = self.ellipticity
        h_c = 2.69 * U ** 0.67 * G ** 0.53 * W ** -0.067 * (1 - 0.61 * np.exp(-0.73 * k))
        h_min = 3.63 * U ** 0.68 * G ** 0.49 * W ** -0.073 * (1 - np.exp(-0.68 * k))
        return h_c * self.radius, h_min * self.radius

    def grid(self, n: int, extent=EXTENT):
        """The rigid gap ``x1^2/(2R_x) + x2^2/(2R_y)`` [m] on ``n x n`` nodes over ``extent``
        (in the Hertz half-widths a and b = k a, x1 the entrainment direction), its spacing
        and node coordinates.  ``n - 1`` divisible by the extents' lengths puts a node on
        the centre."""
        a = self.hertz_radius
        x1 = np.linspace(*extent[0], n) * a
        x2 = np.linspace(*extent[1], n) * a * self.ellipticity
        gap = x1[None, :] ** 2 / (2 * self.radius) + x2[:, None] ** 2 / (
            2 * (self.radius_y or self.radius))
        return gap, (x1[1] - x1[0], x2[1] - x2[0]), x1, x2


    def mesh(self, n: int, extent=EXTENT):
        """:meth:`grid`'s ``(gap, spacing, x1, x2)`` on the mesh graded over that grid
        (:func:`~fem_twin.numerics.graded_mesh.point_contact_mesh`): ``spacing`` is the
        :class:`~fem_twin.numerics.graded_mesh.Mesh`, whose grid is ``n x n``."""
        a = self.hertz_radius
        mesh = point_contact_mesh(n, extent, (a, a * self.ellipticity))
        x1, x2 = (c + e[0] * w for c, e, w in zip(mesh.coordinates, extent,
                                                   (a, a * self.ellipticity)))
        gap = x1[None, :] ** 2 / (2 * self.radius) + x2[:, None] ** 2 / (
            2 * (self.radius_y or self.radius))
        return gap, mesh, x1, x2


def film_thickness(result, x1, x2) -> tuple:
    """``(h_c, h_min)`` [m] of a solved point contact: the film at the centre (bilinear
    interpolation of ``result.h0`` at x = 0) and its minimum over the grid."""
    from scipy.interpolate import RegularGridInterpolator
    h = RegularGridInterpolator((x2, x1), result.h0)([[0.0, 0.0]])[0]
    return float(h), float(result.h0.min())


def film_against_hamrock_dowson(contact: PointContact, result, x1, x2) -> dict:
    """The film of a solved point (``result`` on the grid ``x1, x2`` of ``contact.grid``)
    beside the Hamrock-Dowson films of the smooth ball at the same viscosity and entrainment
    speed: ``h_c_m``, ``h_min_m``, ``hamrock_dowson_h_c_m``, ``hamrock_dowson_h_min_m`` [m]."""
    h_c, h_min = film_thickness(result, x1, x2)
    hd_c, hd_min = contact.hamrock_dowson()
    return {"entrainment_m_s": contact.entrainment, "h_c_m": h_c, "h_min_m": h_min,
            "hamrock_dowson_h_c_m": float(hd_c), "hamrock_dowson_h_min_m": float(hd_min)}
