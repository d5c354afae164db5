"""C_f split into what the twin predicts and what it calibrates: the film's friction and
the boundary law's (``boundary_share``), per curve, with the patch band (docs/model.md,
"What is predicted, what is calibrated")."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..checks import arguments
from ..io.figure import save_figure
from .curve import StribeckCurve


@arguments(curves=[StribeckCurve], path="path")
def plot_parts(curves, path, *, labels=None, bands=None,
               speed_label: str = "sliding speed $U$ [m/s]") -> Path:
    """One panel per curve: C_f (line, with its error bars and the patch ``bands``
    ``(cf_min, cf_max)`` shaded) stacked from its film part ``C_f (1 - boundary_share)``
    (predicted) and its boundary part ``C_f boundary_share`` (calibrated), log speed."""
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(curves), figsize=(4.2 * len(curves), 3.8), sharey=True,
                             squeeze=False)
    for i, (c, ax) in enumerate(zip(curves, axes[0])):
        order = np.argsort(c.speed)
        u, cf = c.speed[order], c.friction_coefficient[order]
        share = np.nan_to_num(c.boundary_share[order])
        ax.fill_between(u, 0, cf * (1 - share), color="tab:blue", alpha=0.5, lw=0,
                        label="film (predicted)")
        ax.fill_between(u, cf * (1 - share), cf, color="tab:orange", alpha=0.5, lw=0,
                        label="boundary (calibrated)")
        ax.plot(u, cf, "k-", lw=1.2, label="$C_f$")
        if c.friction_error is not None:
            ax.errorbar(u, cf, yerr=c.friction_error[order], fmt="none", ecolor="k",
                        capsize=2, lw=0.8)
        if bands is not None and bands[i] is not None:
            low, high = (np.asarray(b)[order] for b in bands[i])
            ax.plot(u, low, "k:", lw=0.8, label="patch scatter")
            ax.plot(u, high, "k:", lw=0.8)
        ax.set_xscale("log")
        ax.set_xlabel(speed_label)
        ax.set_title(labels[i] if labels else f"$\\mu_0$ = {c.viscosity:g} Pa s",
                     fontsize="small")
        ax.grid(True, which="both", alpha=0.3)
    axes[0, 0].set_ylabel("friction coefficient $C_f$ [-]")
    axes[0, 0].legend(fontsize="x-small", loc="upper right")
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)
