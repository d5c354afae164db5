"""The statistical mixed-lubrication model as a peer of the cell problems: Patir and Cheng's
average flow and shear factors with Greenwood and Tripp's asperity contact, as a
:class:`~fem_twin.micro.FlowFactors` the macro scale takes as it is.

In the twin's terms (pin = surface 1 at ``u_m (1 - SRR/2)``, disk = surface 2), with the
nominal separation ``h = h0`` and the Gaussian mean gap ``h_m = h_T``
(Patir and Cheng 1978, eq 19):

    A = diag(phi_x, phi_y) (h / h_T)^3,     b = e1 - (SRR / 2) (sigma / h_T) phi_s e1,
    s_C = (h_T / h) (phi_f - phi_fs),       pressure friction = C_11 = phi_fp h / h_T,

``phi_s = V1 Phi_s(gamma_1) - V2 Phi_s(gamma_2)`` and ``phi_fs`` alike (V_i = sigma_i^2 /
sigma^2), ``d1 = SRR (1 - s_C) / 6`` (eq 31's law gives the same shear), and ``p_con``,
``contact_fraction`` Greenwood-Tripp's.  The friction is Patir and Cheng's mean wall shear
on the pin, which leaves out the film pressure on the pin's asperity flanks (the twin's
default law counts it: docs/model.md, "Friction on the pin").  Below the fits' smallest
``H = h / sigma`` the flow and shear factors are held at their end (recorded in
``meta["held_below_m"]``); ``h_m`` and the contact follow their closed forms.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy import special

from ..checks import QUANTITIES, arguments, plausible
from ..errors import InputError
from ..micro.flow_factors import FlowFactors
from ..topography import Topography
from ..topography.statistics import roughness_statistics
from . import patir_cheng as pc
from .greenwood_tripp import Summits, contact_fraction, contact_pressure

#: a body whose rms height is below this share of the pair's is taken as smooth (no gamma)
SMOOTH_SHARE = 1e-3
#: contact pressures and areas below this share of the largest are zero: they carry no load,
#: and their tails would span 300 decades (denormal slopes in the interpolants)
NO_LOAD = 1e-12
#: the separations tabulated by default [m]: 1 nm to 10 um, 80 a decade (any pair's range of
#: H = h / sigma, and one grid for every patch, so that their factors average)
DEFAULT_H0 = np.geomspace(1e-9, 1e-5, 321)


@dataclass(frozen=True)
class PairStatistics:
    """What the statistical model reads from a patch pair (SI units): the composite rms
    ``sigma`` [m] and Peklenik number ``gamma`` [-], each body's variance ``shares``
    (pin, disk) [-] and ``gammas`` (None for a smooth body), and the composite ``summits``
    (McCool's, from the equivalent isotropic moments).  A gamma the cell bounds (a
    correlation longer than half the cell) or outside Patir and Cheng's tables is taken at
    its bound or the tables' edge (1/9, 9), and ``notes`` say which."""

    sigma: float
    gamma: float
    shares: tuple[float, float]
    gammas: tuple[float | None, float | None]
    summits: Summits
    notes: tuple[str, ...] = ()

    @classmethod
    def from_cells(cls, pin: Topography, disk: Topography) -> "PairStatistics":
        """From the periodic cells the cell problems take (``disk`` flipped over ``pin``,
        the gap ``h0 + disk - pin``)."""
        if pin.shape != disk.shape or not np.allclose(pin.spacing, disk.spacing):
            raise InputError("pin and disk cells must share one grid")
        pair = roughness_statistics(Topography(pin.heights - disk.heights, pin.spacing))
        bodies = [roughness_statistics(t) if t.rms_height() > SMOOTH_SHARE * pair.sigma
                  else None for t in (pin, disk)]
        var = np.array([0.0 if b is None else b.sigma ** 2 for b in bodies])
        shares = tuple(float(v) for v in var / var.sum())
        notes = []
        gammas = [_gamma(b, name, notes) if b is not None else None
                  for b, name in ((pair, "pair"), *zip(bodies, ("pin", "disk")))]
        return cls(sigma=pair.sigma, gamma=gammas[0], shares=shares, gammas=tuple(gammas[1:]),
                   summits=Summits.from_moments(*pair.moments), notes=tuple(notes))

    def smallest_H(self) -> float:
        """The largest of the fits' smallest ``H`` over the gammas in use [-]."""
        return max(pc.SHEAR_MIN_H, pc.pressure_flow_range(self.gamma),
                   pc.pressure_flow_range(1 / self.gamma))

    def per_body(self, fit, H) -> np.ndarray:
        """``V1 fit(H, gamma_1) - V2 fit(H, gamma_2)`` (Phi_s or Phi_fs of the pair)."""
        out = np.zeros_like(H)
        for sign, share, gamma in zip((1, -1), self.shares, self.gammas):
            if gamma is not None:
                out = out + sign * share * fit(H, gamma)
        return out


def _gamma(stats, name: str, notes: list) -> float:
    """``stats.gamma`` within Patir and Cheng's tables, with a note where it is a bound
    or clipped."""
    gamma = float(np.clip(stats.gamma, pc.GAMMAS[0], pc.GAMMAS[-1]))
    if stats.gamma_bound != "exact":
        notes.append(f"{name}: gamma {stats.gamma:.3g} is only a bound ({stats.gamma_bound}: "
                     "a correlation length longer than half the cell)")
    if gamma != stats.gamma:
        notes.append(f"{name}: gamma {stats.gamma:.3g} taken at the tables' edge {gamma:.3g}")
    return gamma


@arguments(h="numbers", sigma="number")
def mean_gap(h, sigma: float) -> np.ndarray:
    """``h_T`` [m]: the mean of ``max(h + delta, 0)`` over Gaussian heights delta of rms
    ``sigma`` [m] at nominal separation ``h`` [m] (Patir and Cheng 1978, eq 19)."""
    plausible("mean_gap: sigma, the composite rms roughness [m]", sigma, "separation")
    farthest = QUANTITIES["separation"][1]
    if np.any(np.abs(np.asarray(h, float)) > farthest):
        raise InputError(f"mean_gap: h [m] reaches {np.max(np.abs(h)):g} m: implausible; "
                         f"separations within +-{farthest:g} m (0.1 um is 1e-7)")
    H = np.asarray(h, float) / sigma
    return sigma * (H * special.ndtr(H) + np.exp(-H ** 2 / 2) / np.sqrt(2 * np.pi))


@arguments(pin=Topography, disk=Topography, e_reduced="number", h0="numbers",
           slide_to_roll="number")
def average_flow_factors(pin: Topography, disk: Topography, e_reduced: float, h0=None, *,
                         slide_to_roll: float = 2.0) -> FlowFactors:
    """Patir-Cheng / Greenwood-Tripp :class:`FlowFactors` of a patch pair at ``h0`` [m]
    (default :data:`DEFAULT_H0`), ``e_reduced`` E' [Pa], ``slide_to_roll`` SRR."""
    plausible("average_flow_factors: e_reduced [Pa]", e_reduced, "reduced_modulus")
    plausible("average_flow_factors: slide_to_roll", slide_to_roll, "slide_to_roll")
    if h0 is not None and np.ndim(h0) > 1:
        raise InputError(f"average_flow_factors: h0 [m]: expected a list of separations, got "
                         f"shape {np.shape(h0)}")
    if h0 is not None:
        plausible("average_flow_factors: h0 [m]", h0, "separation")
    stats = PairStatistics.from_cells(pin, disk)
    sigma = stats.sigma
    h = DEFAULT_H0 if h0 is None else np.asarray(h0, float)
    lo = stats.smallest_H()
    H = np.maximum(h / sigma, lo)                       # the fits held at their end
    h_t = mean_gap(h, sigma)
    ratio = h / h_t
    phi_x, phi_y = pc.pressure_flow(H, stats.gamma), pc.pressure_flow_across(H, stats.gamma)
    phi_s = stats.per_body(pc.shear_flow, H)
    s_c = (pc.couette_stress(H) - stats.per_body(pc.shear_stress, H)) / ratio
    fp_x = pc.pressure_stress(H, stats.gamma) * ratio
    fp_y = pc.pressure_stress(H, 1 / stats.gamma) * ratio
    zero = np.zeros_like(h)
    A = np.zeros((h.size, 2, 2))
    A[:, 0, 0], A[:, 1, 1] = phi_x * ratio ** 3, phi_y * ratio ** 3
    C = np.zeros((h.size, 2, 2))
    C[:, 0, 0], C[:, 1, 1] = fp_x, fp_y
    meta = {"method": "average-flow", "model": "Patir-Cheng + Greenwood-Tripp", "screening": True,
            "sigma_m": sigma, "gamma": stats.gamma, "shares": list(stats.shares),
            "gammas": list(stats.gammas), "summits": asdict(stats.summits),
            "notes": list(stats.notes),
            "held_below_m": lo * sigma, "slide_to_roll": slide_to_roll}
    p_con = contact_pressure(h, stats.summits, e_reduced)
    area = contact_fraction(h, stats.summits)
    for tail in (p_con, area):
        tail[tail < NO_LOAD * tail.max()] = 0.0
    return FlowFactors(
        h0=h, h_m=h_t, p_con=p_con, A=A,
        b=np.stack([1 - slide_to_roll / 2 * sigma * phi_s / h_t, zero], axis=1), C=C,
        d=np.stack([slide_to_roll * (1 - s_c) / 6, zero], axis=1), friction_factor=s_c,
        pressure_friction=np.stack([fp_x, zero], axis=1),
        contact_fraction=area, meta=meta)
