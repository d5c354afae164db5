"""
Friction on the pin
===================

The force on the pin against eq 31, on two cases with an answer that is not the twin's.

    python examples/10_friction_on_the_pin.py [OUT] [--quick]

Left: cosine ridges across the sliding direction, on the pin at rest or, the same gap, on
the moving disk. The force on the pin is the same in both (the second is the first seen
from the disk), ``h_m (4 <1/h> - 3 <h^-2>^2 / <h^-3>)`` in units of ``mu U / h_m``; the
twin's friction factor s_C meets it on either body, while eq 31's ``1 - 3 d1`` depends on
which body is rough.

Right: a 5 mm plane slider (inlet film twice the outlet's) with 0.3 um ridges on the pin,
resolved on the grid (``solve_reynolds`` on the rough gap; friction integrated as the wall
shear plus the pressure on the pin's surface), against the twin with the flow factors of
one ridge at the same load. As the ridges shorten the resolved friction converges to the
twin's; eq 31 stays far below.  docs/model.md ("Friction on the pin") has the derivation.
Ends in ``OUT/friction_on_the_pin.png``; about 10 s on 2 cores (``--quick``: fewer
separations and ridge counts).
"""

import argparse
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin import Topography
from fem_twin.macro import Lubricant, MacroSettings, solve_mixed, solve_reynolds
from fem_twin.micro import homogenise

CELL, AMP = 80e-6, 0.08e-6                      # striated cell [m], ridge amplitude [m]
SLIDER, RATIO, RIDGE = 5e-3, 2.0, 0.3e-6        # slider length, inlet/outlet film, ridge
MU, U, ROWS, WIDE = 0.01, 0.01, 21, 20          # oil, speed, a strip 20x wider than long


def striated(h0, body, n=64):
    """Flow factors of the ridges on ``body`` ("pin" or "disk") at separations ``h0``."""
    dx = CELL / n
    z = np.tile(AMP * np.cos(2 * np.pi * np.arange(n) / n), (4, 1))
    flat = Topography(np.zeros_like(z), (dx, dx))
    rough = Topography(z if body == "pin" else -z, (dx, dx))
    pair = (rough, flat) if body == "pin" else (flat, rough)
    return homogenise(*pair, h0, steps=8, error_estimate=False)


def closed_form(h0):
    """The force on the pin per mu U / h_m for h = h0 - a cos (fine quadrature)."""
    h = h0[:, None] - AMP * np.cos(2 * np.pi * np.arange(2048) / 2048)
    return h.mean(1) * (4 * np.mean(1 / h, 1) - 3 * np.mean(h ** -2, 1) ** 2 / np.mean(h ** -3, 1))


def strip(h_x):
    nx = len(h_x)
    return np.tile(h_x, (ROWS, 1)), (SLIDER / (nx - 1), WIDE * SLIDER / (ROWS - 1))


def integral(field, dx):
    return np.trapezoid(np.trapezoid(field, dx=dx[0], axis=1), dx=dx[1])


def resolved(h_o, n_ridges):
    """Friction and load of the slider with its ridges resolved (16 nodes a ridge)."""
    x = np.linspace(0, SLIDER, 16 * n_ridges + 1)
    wedge = h_o * (1 + (RATIO - 1) * (1 - x / SLIDER))
    ridge = RIDGE * np.cos(2 * np.pi * x * n_ridges / SLIDER)
    h, dx = strip(wedge - ridge)
    r = solve_reynolds(h, dx, U, MU, tol=1e-12)
    slope = np.gradient(np.tile(ridge - wedge, (ROWS, 1)), dx[0], axis=1)
    shear = (MU * U / h * (1 - r.cavity_fraction)
             - h / 2 * np.gradient(r.pressure, dx[0], axis=1) + r.pressure * slope)
    return integral(shear, dx), integral(r.pressure, dx)


def twin(h_o, load):
    """The twin's friction of the slider at ``load``, the force on the pin and eq 31."""
    n = 64
    z = np.tile(RIDGE * np.cos(2 * np.pi * np.arange(n) / n), (4, 1))
    dx = SLIDER / 50 / n
    ff = homogenise(Topography(z, (dx, dx)), Topography(np.zeros_like(z), (dx, dx)),
                    np.geomspace(0.95 * h_o, 1.05 * RATIO * h_o, 24), steps=4,
                    e_reduced=4e12, error_estimate=False)
    gap, dx = strip(h_o * (1 + (RATIO - 1) * (1 - np.linspace(0, SLIDER, 201) / SLIDER)))
    out = {}
    for law in ("pin", "paper"):
        settings = MacroSettings(e_reduced=4e12, ambient_pressure=0.0, cavitation_pressure=0.0,
                                 tol=1e-8, friction=law)
        res = solve_mixed(gap, dx, ff, load=load, speed=U, settings=settings,
                          lubricant=Lubricant(MU, roelands_alpha=0.0, dh_c2=1.0))
        out[law] = integral(res.shear_stress, dx)
    return out


def main(out="out/friction_on_the_pin", quick=False):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    h0 = np.geomspace(0.1e-6, 0.4e-6, 4 if quick else 8)
    left.plot(h0 * 1e6, closed_form(h0), "k-", lw=3, alpha=0.3, label="force, closed form")
    for body, marker in (("pin", "o"), ("disk", "s")):
        ff = striated(h0, body)
        left.plot(h0 * 1e6, ff.friction_factor, marker, mfc="none",
                  label=f"twin s_C, ridges on the {body}")
        left.plot(h0 * 1e6, 1 - 3 * ff.d[:, 0], marker + "--", label=f"eq 31, ridges on the {body}")
    left.set(xlabel="separation h0 [um]", ylabel="Couette friction / (mu U / h_m)",
             title="(a) striated ridges, 0.08 um")
    left.legend(fontsize="small")
    for h_o, colour in ((1e-6, "C0"), (0.45e-6, "C3")):
        counts = (10, 50) if quick else (10, 25, 50, 100, 200)
        rows = [resolved(h_o, n) for n in counts]
        model = twin(h_o, rows[-1][1])
        for law, style in (("pin", "-"), ("paper", ":")):
            right.axhline(model[law] * 1e3, color=colour, ls=style,
                          label=f"twin, {'force on the pin' if law == 'pin' else 'eq 31'}, "
                                f"outlet {h_o * 1e6:.2g} um")
        right.plot(counts, [f * 1e3 for f, _ in rows], "o-", color=colour,
                   label=f"resolved, outlet {h_o * 1e6:.2g} um")
        print(f"outlet film {h_o * 1e6:.2g} um: resolved {rows[-1][0]:.5g} N at "
              f"{counts[-1]} ridges, twin {model['pin']:.5g} N "
              f"({model['pin'] / rows[-1][0] - 1:+.2%}), eq 31 {model['paper']:.5g} N")
    right.set(xscale="log", xlabel="ridges on the 5 mm slider", ylabel="friction [mN]",
              title="(b) resolved rough slider against the twin")
    right.legend(fontsize="x-small")
    path = out / "friction_on_the_pin.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default="out/friction_on_the_pin")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    main(args.out, args.quick)
