"""Plots of flow factors (paper Figures 4-5) and VTU/PVD of the cell fields for ParaView."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.figure import save_figure
from ..io.mesh import grid_mesh, write_pvd, write_vtu
from .flow_factors import FlowFactors
from .homogenisation import check_patches
from .sliding import (
    CellSettings,
    cell_solver,
    sliding_cells,
    sliding_contacts,
    sliding_pass,
    sliding_squeeze,
)


def plot_flow_factors(factors, path, labels=None) -> Path:
    """Figures 4-5: h_m, p_con, A11 of each patch pair (and their average if given last),
    and all components of A and b of the last entry, versus h0 [um]; beside them the
    friction on the pin: the Couette friction factor s_C against eq 31's ``1 - 3 d1``, and
    the Poiseuille friction ``2 - b1`` against eq 31's C11.  Written atomically."""
    import matplotlib.pyplot as plt

    factors = [factors] if isinstance(factors, FlowFactors) else list(factors)
    labels = labels or [f.meta.get("patch_id") or f"patch {i + 1}" for i, f in enumerate(factors)]
    fig, ax = plt.subplots(2, 3, figsize=(15, 8), constrained_layout=True)
    for f, label in zip(factors, labels):
        x = f.h0 * 1e6
        ax[0, 0].plot(x, (f.h_m - f.h0) * 1e9, label=label)
        ax[0, 1].semilogy(x, np.where(f.p_con > 0, f.p_con * 1e-6, np.nan), ".-", label=label)
        ax[1, 0].plot(x, f.A[:, 0, 0], label=label)
        line, = ax[0, 2].plot(x, f.friction_factor, label=label)
        ax[0, 2].plot(x, 1 - 3 * f.d[:, 0], ":", color=line.get_color())
        line, = ax[1, 2].plot(x, f.pressure_friction[:, 0], label=label)
        ax[1, 2].plot(x, f.C[:, 0, 0], ":", color=line.get_color())
    last = factors[-1]
    x = last.h0 * 1e6
    for (i, j), style in zip([(0, 0), (0, 1), (1, 0), (1, 1)], ["-", "--", ":", "-."]):
        ax[1, 1].plot(x, last.A[:, i, j], style, label=f"$A_{{{i + 1}{j + 1}}}$")
    ax[1, 1].plot(x, last.b[:, 0], "-", marker=".", markevery=10, label="$b_1$")
    ax[1, 1].plot(x, last.b[:, 1], "--", marker=".", markevery=10, label="$b_2$")
    names = [("$h_m - h_0$ [nm]", "(a) mean gap above $h_0$, eq 12"),
             ("$p_{con}$ [MPa]", "(b) contact pressure, eq 11"),
             ("$A_{11}$ [-]", "(c) pressure flow factor, eq 13"),
             ("factor [-]", f"(d) A and b of {labels[-1]}"),
             ("$s_C$ [-]", "(e) Couette friction on the pin (dotted: eq 31, $1 - 3 d_1$)"),
             ("$2 - b_1$ [-]", "(f) Poiseuille friction on the pin (dotted: eq 31, $C_{11}$)")]
    sq = composite_sq(last)
    panels = [ax[0, 0], ax[0, 1], ax[1, 0], ax[1, 1], ax[0, 2], ax[1, 2]]
    for a, (ylabel, title) in zip(panels, names):
        a.set_xlabel("$h_0$ [µm]")
        a.set_ylabel(ylabel)
        a.set_title(title)
        a.grid(True, alpha=0.3)
        a.legend(fontsize="small")
        if sq:                                    # the separation in roughness units
            top = a.secondary_xaxis("top", functions=(lambda u: u * 1e-6 / sq,
                                                      lambda r: r * sq * 1e6))
            top.set_xlabel(f"$h_0 / S_q$ [-] ($S_q$ = {sq * 1e9:.0f} nm)", fontsize="small")
    return save_figure(fig, path, dpi=120)


def composite_sq(factors: FlowFactors) -> float | None:
    """Sq of the patch pair, sqrt(Sq_pin^2 + Sq_disk^2) [m] (Table 5), from the metadata;
    the mean over the patches of an average; None if unknown."""
    meta = factors.meta
    if "sq" in meta:
        return meta["sq"]
    members = [m.get("sq") for m in meta.get("average_of", [])]
    return float(np.mean(members)) if members and all(members) else None


def cell_fields(pin, disk, h0: float, *, n_steps: int = 32, method: str = "fe",
                moving: str = "both", time_derivative: str = "exact",
                first_step: str = "steady", **materials) -> list[dict]:
    """Per time step: pin and disk heights, gap, asperity pressure, squeeze term ``tau`` of
    eq 8 and chi_1..3 (grid fields, SI units).

    ``materials`` are ``e_reduced``, ``hardness``, ``gap_floor`` as in :func:`homogenise`.
    """
    settings = CellSettings(steps=n_steps, method=method, moving=moving, first_step=first_step,
                            time_derivative=time_derivative, **materials)
    z_low, z_up, spacing = check_patches(pin, disk)
    sliding = sliding_pass(z_low, z_up, spacing, settings)
    solver = cell_solver(z_low.shape, spacing, method)
    contacts = sliding_contacts(sliding.shapes, spacing, settings, h0)
    squeezes = sliding_squeeze(contacts, sliding, spacing, settings)
    cells = sliding_cells(contacts, squeezes, solver, settings, sliding.couette)
    out = []
    for r, m, tau, cell in zip(contacts, sliding.moving, squeezes, cells):
        out.append({"pin": -m if moving == "lower" else z_low,
                    "disk": z_up if moving == "lower" else m,
                    "gap": r.gap, "asperity_pressure": r.pressure,
                    "squeeze": np.zeros_like(r.gap) if tau is None else tau,
                    "chi_1": cell.chi[0], "chi_2": cell.chi[1], "chi_3": cell.chi[2]})
    return out


def write_cell_fields(folder, pin, disk, h0: float, **kwargs) -> Path:
    """VTU per time step and a PVD time series of :func:`cell_fields` (SI units)."""
    folder = Path(folder)
    steps = cell_fields(pin, disk, h0, **kwargs)
    _, _, spacing = check_patches(pin, disk)
    gm = grid_mesh(pin.shape, spacing, periodic=True)
    name = f"cell_h0_{h0 * 1e9:.0f}nm"
    entries = [(n / len(steps), write_vtu(folder / f"{name}_{n:03d}.vtu", gm, fields))
               for n, fields in enumerate(steps)]
    return write_pvd(folder / f"{name}.pvd", entries)   # time in periods T_r
