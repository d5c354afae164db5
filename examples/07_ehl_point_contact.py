"""
EHL point contacts against Hamrock-Dowson
=========================================

The smooth ball-on-disk EHL contact: films against Hamrock-Dowson over a Moes range, and
the centre-line film of Mourier et al. (2006) against their interferometry and the EHL-FBNS
simulation of Hansen et al. (2022), with a grid study of the central film.

    python examples/07_ehl_point_contact.py [OUT_DIR] [--quick]

Writes ``OUT_DIR/ehl_films.png`` and ``OUT_DIR/ehl_moes.csv`` and prints a table with the
iterations and the time of every point.  ``--quick``: 49^2 grids, M <= 100, no grid study.
The full run (97^2 over M = 10-1000, grids up to 385^2) takes about 15 min on 2 cores.
"""

import sys
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fem_twin.io.table import write_csv
from fem_twin.macro import Lubricant, MacroSettings, MixedNotConverged, solve_mixed
from fem_twin.macro.reference.point_contact import PointContact, film_thickness
from fem_twin.micro import FlowFactors

args = [a for a in sys.argv[1:] if a != "--quick"]
quick = "--quick" in sys.argv
out = Path(args[0] if args else "ehl_point_contact")
out.mkdir(parents=True, exist_ok=True)
EHL = Path(sys.argv[0]).resolve().parents[2] / "shared" / "references" / "ehl" / "Mourier_2006"


def solve(contact, n):
    gap, spacing, x1, x2 = contact.grid(n)
    t = time.perf_counter()
    res = solve_mixed(gap, spacing, FlowFactors.smooth(), load=contact.load,
                      speed=2 * contact.entrainment,       # rolling: U = 2 u_m (eq 17)
                      lubricant=Lubricant(contact.viscosity, roelands_alpha=contact.alpha),
                      settings=MacroSettings(e_reduced=contact.e_reduced, ambient_pressure=0.0,
                                             cavitation_pressure=0.0))
    return res, x1, x2, time.perf_counter() - t


# -- Moes range against Hamrock-Dowson -------------------------------------------------------
n_moes = 49 if quick else 97
rows = []
print(f"{'M':>6} {'L':>4} {'h_c/HD':>7} {'h_min/HD':>8} {'iterations':>10} {'time [s]':>8}")
for M in (10, 100) if quick else (10, 100, 1000):
    for L in (5, 10, 20):
        contact = PointContact.from_moes(M, L)
        hd_c, hd_min = contact.hamrock_dowson()
        try:
            res, x1, x2, seconds = solve(contact, 193 if M >= 1000 else n_moes)
        except MixedNotConverged as err:
            print(f"{M:6} {L:4} did not converge: {err.message}")
            continue
        h_c, h_min = film_thickness(res, x1, x2)
        rows.append((M, L, h_c / hd_c, h_min / hd_min, res.iterations, seconds))
        print(f"{M:6} {L:4} {h_c / hd_c:7.3f} {h_min / hd_min:8.3f} {res.iterations:10d} "
              f"{seconds:8.1f}")
write_csv(out / "ehl_moes.csv", dict(zip(("M", "L", "h_c_over_HD", "h_min_over_HD", "iterations",
                                          "seconds_s"), zip(*rows))))

# -- the measured contact, and a grid study of its central film ----------------------------
mourier = PointContact(12.5e-3, 15.0, 110e9, 0.25, 22e-9, 0.09)
grids = (49, 97) if quick else (97, 193, 385)
films = []
fig, (ax_m, ax_p) = plt.subplots(1, 2, figsize=(12, 4.5))
for n in grids:
    res, x1, x2, seconds = solve(mourier, n)
    films.append(film_thickness(res, x1, x2)[0])
    j = np.argmin(np.abs(x2))
    ax_p.plot(x1 * 1e6, res.h0[j] * 1e9, label=f"fem_twin {n}$^2$ ({seconds:.0f} s)")
    print(f"Mourier contact {n}^2: h_c {films[-1] * 1e9:.1f} nm, {res.iterations} iterations, "
          f"{seconds:.1f} s")
if len(films) == 3:
    d1, d2 = films[0] - films[1], films[1] - films[2]
    order = np.log2(abs(d1 / d2))
    print(f"observed order of h_c: {order:.2f}; Richardson estimate of the finest grid's "
          f"error: {abs(d2) / (2 ** order - 1) * 1e9:.1f} nm")
hd_c, hd_min = mourier.hamrock_dowson()
ax_p.axhline(hd_c * 1e9, color="k", ls="--", label="Hamrock-Dowson $h_c$")
if EHL.is_dir():
    for k in range(1, 6):
        exp = np.genfromtxt(EHL / f"mourier_ssr0_exp_{k}.csv", delimiter=",", names=True)
        ax_p.plot(exp["x"], exp["gap_height_exp"], "k.", ms=3,
                  label="measured (Mourier 2006)" if k == 1 else None)
    sim = np.genfromtxt(EHL / "mourier_ssr0_sim_1_h.csv", delimiter=",", names=True)
    ax_p.plot(sim["x"], sim["gap_height_sim"], "g:", label="EHL-FBNS (Hansen 2022)")
ax_p.set_xlim(-200, 200)
ax_p.set_ylim(0, 500)
ax_p.set_xlabel("$x_1$ [µm]")
ax_p.set_ylabel("film on the centre line [nm]")
ax_p.legend(fontsize=7)
data = np.array(rows)
for col, marker, name in ((2, "o", "$h_c$"), (3, "s", "$h_{min}$")):
    ax_m.scatter(data[:, 0] * (1 + 0.03 * (data[:, 1] - 10)), data[:, col], marker=marker,
                 label=name)
ax_m.axhspan(0.9, 1.1, color="0.9", zorder=0, label="Hamrock-Dowson ± 10 %")
ax_m.set_xscale("log")
ax_m.set_xlabel("Moes M (L = 5, 10, 20 left to right)")
ax_m.set_ylabel("fem_twin / Hamrock-Dowson")
ax_m.legend(fontsize=7)
fig.tight_layout()
fig.savefig(out / "ehl_films.png", dpi=110)
print(f"wrote {out / 'ehl_films.png'}")
