"""3D views of the virtual geometry (the paper's Figures 2 and 6) with pyvista, off-screen.

pyvista kills its process (segfault) when no OpenGL backend exists, so callers render in a
child process with :func:`render_views`, which returns the images it made and a note saying
why there are none (on Debian, off-screen rendering needs ``libegl1 libegl-mesa0
libgl1-mesa-dri``).  ``python -m fem_twin.io.render VTU PNG`` renders one view.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np


def render_pair(vtu, png, *, title: str = "") -> Path:
    """Lower (pin) and upper (disk) surface of a geometry VTU written by ``fem-twin run``
    (point fields ``x3_low``, ``x3_up`` [m], optional ``pin_face``), heights exaggerated so
    the relief shows at the lateral scale; only the pin face of a macro pin is drawn."""
    import pyvista as pv
    pv.OFF_SCREEN = True
    mesh = pv.read(vtu)
    low, up = np.asarray(mesh["x3_low"]), np.asarray(mesh["x3_up"])
    face = (np.asarray(mesh["pin_face"]) > 0.5 if "pin_face" in mesh.point_data
            else np.ones(low.shape, bool))
    extent = max(np.ptp(mesh.points[:, 0]), np.ptp(mesh.points[:, 1]))
    relief = max(np.ptp(low[face]), np.ptp(up[face]), 1e-12)
    scale = 0.2 * extent / relief
    lift = 0.35 * extent                                    # disk drawn above the pin
    surfaces = []
    for name, z, offset in (("x3_low", low, 0.0), ("x3_up", up, lift)):
        s = mesh.copy()
        s.points[:, 2] = (z - z[face].mean()) * scale + offset
        s[f"{name} [um]"] = z * 1e6
        if "pin_face" in mesh.point_data:
            s = s.threshold(0.5, scalars="pin_face", all_scalars=True)
        surfaces.append(s)
    p = pv.Plotter(off_screen=True, window_size=(1000, 760))
    for s, name, cmap in zip(surfaces, ("x3_low", "x3_up"), ("viridis", "cividis")):
        p.add_mesh(s, scalars=f"{name} [um]", cmap=cmap, scalar_bar_args={
            "title": f"{'pin' if name == 'x3_low' else 'disk'} {name} [um]",
            "vertical": False, "width": 0.36, "position_y": 0.03,
            "position_x": 0.05 if name == "x3_low" else 0.58})
    p.add_text(f"{title}\nlower: pin, upper: disk; heights x{scale:.3g}, "
               f"width {extent * 1e3:.3g} mm", font_size=10)
    p.camera_position = "iso"
    p.camera.zoom(1.1)
    png = Path(png)
    p.screenshot(str(png))
    p.close()
    return png


def render_views(jobs, timeout: float = 180.0) -> tuple[list[Path], str | None]:
    """Render ``jobs`` [(vtu, png, title)] each in a child process; return the PNGs made and,
    if any failed, a note why (no OpenGL backend, a crash, a timeout)."""
    made, notes = [], []
    for vtu, png, title in jobs:
        try:
            proc = subprocess.run([sys.executable, "-m", "fem_twin.io.render", str(vtu),
                                   str(png), title], capture_output=True, text=True,
                                  timeout=timeout)
        except subprocess.TimeoutExpired:
            notes.append(f"{Path(vtu).name}: rendering timed out after {timeout:g} s")
            continue
        if proc.returncode == 0 and Path(png).is_file():
            made.append(Path(png))
        else:
            why = (proc.stderr.strip().splitlines() or [f"exit code {proc.returncode}"])[-1]
            notes.append(f"{Path(vtu).name}: no 3D view ({why}); off-screen rendering needs an "
                         "OpenGL backend (Debian: libegl1 libegl-mesa0 libgl1-mesa-dri)")
    return made, "; ".join(notes) or None


if __name__ == "__main__":
    render_pair(sys.argv[1], sys.argv[2], title=sys.argv[3] if len(sys.argv) > 3 else "")
