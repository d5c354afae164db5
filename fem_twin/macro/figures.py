"""Pictures of operating points: pressure, cavity fraction and contact pressure on the pin
face (the fields of eqs 17-30), one row per point, as PNG."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.figure import save_figure
from ..numerics.graded_mesh import Mesh
from .laws.kinematics import node_lines

#: (field, colour-bar label, scale to the plotted unit)
PANELS = (("pressure_gauge", "hydrodynamic pressure $p - p_{amb}$ [MPa]", 1e-6),
          ("cavity_fraction", r"cavity fraction $\theta$ [-]", 1.0),
          ("contact_pressure", "contact pressure $p_{con}$ [MPa]", 1e-6))


def plot_point_fields(results, path, titles=None) -> Path:
    """One row per :class:`~fem_twin.macro.MixedResult`: the three fields on the pin face
    (the holder is blank), x1 (sliding) to the right, in mm; written atomically."""
    import matplotlib.pyplot as plt
    results = list(results)
    fig, ax = plt.subplots(len(results), 3, figsize=(12, 3.4 * len(results)),
                           squeeze=False, constrained_layout=True)
    for row, res in enumerate(results):
        x1, x2 = (1e3 * v for v in node_lines(res.spacing, res.pressure.shape))
        p_amb = res.meta.get("settings", {}).get("ambient_pressure", 0.0)
        fields = {"pressure_gauge": res.pressure - p_amb,
                  "cavity_fraction": res.cavity_fraction,
                  "contact_pressure": res.contact_pressure}
        for col, (name, label, scale) in enumerate(PANELS):
            shown = np.where(res.face, fields[name] * scale, np.nan)
            im = _draw(ax[row, col], x1, x2, shown, isinstance(res.spacing, Mesh))
            fig.colorbar(im, ax=ax[row, col], shrink=0.85, label=label)
            ax[row, col].set_xlabel("$x_1$ (sliding) [mm]")
            ax[row, col].set_ylabel("$x_2$ [mm]")
        title = titles[row] if titles else f"U = {res.speed:g} m/s"
        ax[row, 0].set_title(title, loc="left", fontsize="medium")
    return save_figure(fig, path, dpi=100)


def _draw(ax, x1, x2, field, graded: bool):
    """A nodal field [plotted unit] over the node lines ``x1, x2`` [mm]: a raster on a
    grid, the mesh's own quadrilaterals (bilinear shading) on a graded mesh."""
    if graded:
        return ax.pcolormesh(x1, x2, field, shading="gouraud", cmap="viridis")
    pitch1, pitch2 = x1[1] - x1[0], x2[1] - x2[0]
    extent = (0, x1.size * pitch1, 0, x2.size * pitch2)
    return ax.imshow(field, origin="lower", extent=extent, cmap="viridis")
