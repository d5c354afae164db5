"""
Dry contact against Hertz
=========================

Dry contact on the regular grid against Hertz: a 10 mm sphere on a flat at 150 N, the
pressure along the centre line with and without the hardness cap (the paper's H).

    python examples/02_hertz_contact.py [OUT.png] [--quick]

``--quick``: 64 x 64 grid instead of 256 x 256 (the gallery's smoke test).
"""

import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin import contact

args = [a for a in sys.argv[1:] if a != "--quick"]
out = Path(args[0] if args else "hertz_contact.png")
n = 64 if "--quick" in sys.argv else 256
R, load = 10e-3, 150.0
e_red = contact.reduced_modulus(210e9, 0.3, 210e9, 0.3)                 # eq 22
a = (3 * load * R / (4 * (e_red / 2))) ** (1 / 3)       # Hertz radius, E* = E' / 2
p0 = 3 * load / (2 * np.pi * a ** 2)
x = (np.arange(n) - n / 2 + 0.5) * (4 * a / n)                           # domain 4a wide
x1, x2 = np.meshgrid(x, x)
shape = (x1 ** 2 + x2 ** 2) / (2 * R)
fig, ax = plt.subplots(figsize=(7, 4))
r = np.linspace(-2 * a, 2 * a, 400)
ax.plot(r * 1e6, p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0, None)) * 1e-9, "k-",
        label=f"Hertz, a = {a * 1e6:.0f} µm")
for hardness, style in ((np.inf, "o"), (1.2e9, "s")):
    res = contact.solve(shape, (x[1] - x[0],) * 2, e_red, load=load, hardness=hardness)
    row = res.pressure[n // 2]
    hertz = p0 * np.sqrt(np.clip(1 - (x1 ** 2 + x2 ** 2) / a ** 2, 0, None))
    err = np.linalg.norm(res.pressure - hertz) / np.linalg.norm(hertz)
    label = ("elastic" if np.isinf(hardness) else f"hardness {hardness * 1e-9:g} GPa")
    print(f"{label}: load {res.load:.3f} N, peak {res.pressure.max() / p0:.3f} p0, "
          f"L2 distance to Hertz {err:.3f}")
    ax.plot(x * 1e6, row * 1e-9, style, ms=3, mfc="none", label=f"fem_twin, {label}")
ax.set_xlabel("$x_1$ [µm]")
ax.set_ylabel("contact pressure [GPa]")
ax.legend()
ax.grid(True, alpha=0.3)
fig.tight_layout()
fig.savefig(out, dpi=120)
print(f"wrote {out}")
