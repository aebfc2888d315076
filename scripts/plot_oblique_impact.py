#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Figure of docs/science-beyond.md "Oblique impacts against published data": a 5 mm Al2O3 sphere on glass at 3.9 m/s.

Usage: scripts/plot_oblique_impact.py [BUILD_DIR [OUT.png]]
       (defaults build/release and docs/figures/oblique-impact-kharaz.png)

Points: the digitised measurements of Kharaz, Gorham & Salman (2001) and Chung & Ooi's (2011) test-4
plots in tests/data/ (provenance in their headers). Curves: solve_impact of each tangential law at
the experiment's inputs (e_n = 0.98, mu = 0.092, R = 2.5 mm, no spin, contact at the pole), as
printed by BUILD_DIR/tests/test_oblique_impact (test CurvesForTheFigure, which also checks that the
three Coulomb rules and Walton with beta0 = 0 give one curve). Needs matplotlib (scripts/setup --python).
"""
import csv
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LAWS = [  # name in the test's table, key title, colour, dash (drawn in this order: Coulomb on top)
    ("kinematic_eps_t_1", "kinematic ε_t = 1 (the paper's law)", "#D55E00", 1),
    ("coulomb_mu_0.276", "Coulomb 3μ = 0.276 (wrong input)", "#999999", 1),
    ("walton_mu_0.092_beta0_0.4", "Walton μ = 0.092, β_0 = 0.4", "#009E73", 2),
    ("coulomb_mu_0.092", "Coulomb μ = 0.092: Newton, Poisson, Stronge; Walton β_0 = 0", "#0072B2", 1),
]


def read_csv(name):
    with open(os.path.join(ROOT, "tests", "data", name)) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def curves(build):
    exe = os.path.join(build, "tests", "test_oblique_impact")
    out = subprocess.run([exe, "--gtest_filter=ObliqueImpact.CurvesForTheFigure"], check=True, capture_output=True,
                         text=True, env=dict(os.environ, ASPERITY_OBLIQUE_CURVES="1")).stdout
    rows = [line.split(",") for line in out.splitlines() if line.startswith("curve,") and not line.startswith("curve,law")]
    table = {}
    for _, law, a, et, om, tr, tc in rows:
        table.setdefault(law, []).append((float(a), float(et), float(om), float(tr), float(tc)))
    return table


def points(rows, series, quantity, absolute=False):
    pts = [(float(r["incidence_deg"]), abs(float(r["value"])) if absolute else float(r["value"]))
           for r in rows if r.get("series", series) == series and r["quantity"] == quantity]
    return [p[0] for p in pts], [p[1] for p in pts]


def main():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    build = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "release")
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "docs", "figures", "oblique-impact-kharaz.png")
    table = curves(build)
    kh, co = read_csv("kharaz2001_alumina_on_glass.csv"), read_csv("chung_ooi2011_test4.csv")
    kh_style = dict(marker="o", ms=6, ls="none", color="black", label="Kharaz et al. 2001 (Lethe digitisation)")
    co_style = dict(marker="o", ms=8, ls="none", mfc="none", mew=1.5, color="black",
                    label="same, re-plotted by Chung & Ooi (Kratos digitisation)")
    dm_style = dict(marker="s", ms=4, ls="--", color="#CC79A7", label="Chung & Ooi DEM reference, Al$_2$O$_3$ (Hertz-Mindlin)")
    fig, axes = plt.subplots(2, 2, figsize=(15, 11.5))
    panels = [  # title, y label, y range, column of the curves' table, measured series, legend
        ("rebound angle of the centre of mass, atan(V''_t / V''_n)", "rebound angle [deg]", (0, 90), 2,
         [(points(kh, "kharaz2001", "theta_r"), kh_style)], "upper left"),
        ("rebound angle of the contact point, atan(u''_t / V''_n)", "contact rebound angle [deg]", (-30, 90), 3,
         [(points(co, "dem_al_oxide", "theta_contact"), dm_style), (points(co, "experiment", "theta_contact"), co_style)],
         "upper left"),
        ("tangential coefficient e_t = V''_t / V_t", "e_t", (0.4, 1.05), 0,
         [(points(co, "dem_al_oxide", "e_t"), dm_style), (points(kh, "kharaz2001", "e_t"), kh_style),
          (points(co, "experiment", "e_t"), co_style)], "lower right"),
        ("spin after the impact", "|Ω''| [rad/s]", (0, 800), 1,
         [(points(co, "dem_al_oxide", "omega", True), dm_style), (points(kh, "kharaz2001", "omega"), kh_style),
          (points(co, "experiment", "omega", True), co_style)], None),
    ]
    for ax, (title, ylabel, ylim, column, measured, legend) in zip(axes.flat, panels):
        for name, label, colour, dash in LAWS:
            rows = table[name]
            ax.plot([r[0] for r in rows], [r[1 + column] for r in rows], lw=2, color=colour,
                    ls="-" if dash == 1 else "--", label=label)
        for (x, y), style in measured:
            ax.plot(x, y, **style)
        ax.axvline(32.52, ls=":", color="#555555")
        ax.set(title=title, ylabel=ylabel, ylim=ylim, xlim=(0, 90), xlabel="incidence angle from the normal [deg]")
        ax.grid(True, alpha=0.4)
        if legend:
            ax.legend(loc=legend, fontsize=9)
    fig.suptitle("5 mm Al$_2$O$_3$ sphere on soda-lime glass, 3.9 m/s, no spin: rigid impulse laws (solve_impact at the "
                 "pole, e_n = 0.98) against measurements; dotted: rolling/sliding transition 32.5°")
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    print(out)


if __name__ == "__main__":
    main()
