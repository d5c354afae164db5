"""
The ball on a graded film mesh
==============================

A point contact's film solved on a graded tensor-product Q1 mesh
(:func:`fem_twin.numerics.graded_mesh.point_contact_mesh`: the FFT grid's pitch over the
Hertz zone, doubling outward), with the elastic deformation on the uniform FFT grid under
it; the pressure crosses to the grid as the mesh's bilinear interpolant, which keeps the
load.  The smooth contact of Mourier et al. (2006) on the mesh graded over a grid of ``n``
nodes a side beside the uniform grid itself: the same central and minimum films with a
third of the nodes outside the Hertz zone.

    python examples/18_graded_ball_mesh.py [OUT_DIR] [--quick]

Writes ``OUT_DIR/graded_ball_mesh.png`` (the mesh over the pressure and over the film)
and prints both meshes' films, nodes and times.  ``--quick``: n = 97 (about 15 s);
the full size n = 193 (about 1.5 min on 2 cores).  The bundled rough ball's convergence
on both meshes: docs/accuracy.md, "The ball on a graded mesh".
"""

import sys
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin.macro import Lubricant, MacroSettings, solve_mixed
from fem_twin.macro.reference.point_contact import PointContact, film_thickness
from fem_twin.micro import FlowFactors

args = [a for a in sys.argv[1:] if a != "--quick"]
quick = "--quick" in sys.argv
out = Path(args[0] if args else "graded_ball_mesh")
out.mkdir(parents=True, exist_ok=True)
n = 97 if quick else 193
mourier = PointContact(12.5e-3, 15.0, 110e9, 0.25, 22e-9, 0.09)


def solve(build):
    gap, spacing, x1, x2 = build(n)
    t = time.perf_counter()
    res = solve_mixed(gap, spacing, FlowFactors.smooth(), load=mourier.load,
                      speed=2 * mourier.entrainment,
                      lubricant=Lubricant(mourier.viscosity, roelands_alpha=mourier.alpha),
                      settings=MacroSettings(e_reduced=mourier.e_reduced, ambient_pressure=0.0,
                                             cavitation_pressure=0.0))
    return res, x1, x2, time.perf_counter() - t


results = {}
for name, build in (("uniform", mourier.grid), ("graded", mourier.mesh)):
    res, x1, x2, seconds = solve(build)
    h_c, h_min = film_thickness(res, x1, x2)
    results[name] = (res, x1, x2)
    print(f"{name} mesh over the {n}^2 grid: {res.pressure.size} nodes, h_c {h_c * 1e9:.2f} nm, "
          f"h_min {h_min * 1e9:.2f} nm, load {res.normal_load:.6g} N, {seconds:.1f} s")

res, x1, x2 = results["graded"]
a = mourier.hertz_radius
X1, X2 = np.meshgrid(x1 / a, x2 / a)
fig, axes = plt.subplots(1, 2, figsize=(12, 5), constrained_layout=True)
for ax, field, label, top in ((axes[0], res.pressure * 1e-6, "pressure [MPa]", None),
                              (axes[1], res.h0 * 1e9, "film $h_0$ [nm]", 600)):
    im = ax.pcolormesh(X1, X2, field, shading="gouraud", cmap="viridis", vmax=top)
    ax.plot(X1, X2, color="w", lw=0.25)                # the mesh's lines
    ax.plot(X1.T, X2.T, color="w", lw=0.25)
    fig.colorbar(im, ax=ax, label=label, shrink=0.85)
    ax.set_aspect("equal")
    ax.set_xlabel("$x_1 / a$ (entrainment)")
    ax.set_ylabel("$x_2 / a$")
axes[0].set_title(f"graded mesh over a {n}$^2$ grid: {res.pressure.size} nodes "
                  f"({res.pressure.size / n ** 2:.0%} of the grid)", loc="left",
                  fontsize="medium")
fig.savefig(out / "graded_ball_mesh.png", dpi=110)
print(f"wrote {out / 'graded_ball_mesh.png'}")
