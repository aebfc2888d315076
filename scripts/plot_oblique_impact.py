#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Figure of docs/science-beyond.md "Oblique impacts against published data": a 5 mm Al2O3 sphere on glass at 3.9 m/s.

Usage: scripts/plot_oblique_impact.py [BUILD_DIR [OUT.png]]
       (defaults build/release and docs/figures/oblique-impact-kharaz.png)

Points: the digitised measurements of Kharaz, Gorham & Salman (2001) and Chung & Ooi's (2011) test-4
plots in tests/data/ (provenance in their headers). Curves: solve_impact of each tangential law at
the experiment's inputs (e_n = 0.98, mu = 0.092, R = 2.5 mm, no spin, contact at the pole), as
printed by BUILD_DIR/tests/test_oblique_impact (test CurvesForTheFigure, which also checks that the
three Coulomb rules and Walton with beta0 = 0 give one curve). Needs gnuplot (pngcairo).
"""
import csv
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LAWS = [  # name in the test's table, key title, colour, dash (drawn in this order: Coulomb on top)
    ("kinematic_eps_t_1", "kinematic {/Symbol e}_t = 1 (the paper's law)", "#D55E00", 1),
    ("coulomb_mu_0.276", "Coulomb 3{/Symbol m} = 0.276 (wrong input)", "#999999", 1),
    ("walton_mu_0.092_beta0_0.4", "Walton {/Symbol m} = 0.092, {/Symbol b}_0 = 0.4", "#009E73", 2),
    ("coulomb_mu_0.092", "Coulomb {/Symbol m} = 0.092: Newton, Poisson, Stronge; Walton {/Symbol b}_0 = 0", "#0072B2", 1),
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


def block(name, rows):
    return [f"${name} << EOD"] + [" ".join(str(x) for x in r) for r in rows] + ["EOD"]


def points(rows, series, quantity, absolute=False):
    return [(float(r["incidence_deg"]), abs(float(r["value"])) if absolute else float(r["value"]))
            for r in rows if r.get("series", series) == series and r["quantity"] == quantity]


def panel(title, ylabel, yrange, column, data, key, law_titles):
    s = [f"set title '{title}'", f"set ylabel '{ylabel}'", f"set yrange [{yrange}]",
         "set key " + key + (" Left reverse" if key != "off" else ""), "set arrow 1 from 32.52, graph 0 to 32.52, graph 1 nohead dt 3 lc rgb '#555555'"]
    plot = [f"$c{k} using 1:{column} with lines lw 2 dt {d} lc rgb '{c}' " + (f'title "{t}"' if law_titles else "notitle")
            for k, (_, t, c, d) in enumerate(LAWS)]
    plot += data
    return s + ["plot " + ", \\\n  ".join(plot)]


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "release")
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "docs", "figures", "oblique-impact-kharaz.png")
    table = curves(build)
    kh, co = read_csv("kharaz2001_alumina_on_glass.csv"), read_csv("chung_ooi2011_test4.csv")
    s = []
    for k, (name, *_rest) in enumerate(LAWS):
        s += block(f"c{k}", table[name])
    s += block("khr", points(kh, "kharaz2001", "theta_r")) + block("khe", points(kh, "kharaz2001", "e_t"))
    s += block("khw", points(kh, "kharaz2001", "omega"))
    s += block("coc", points(co, "experiment", "theta_contact")) + block("coe", points(co, "experiment", "e_t"))
    s += block("cow", points(co, "experiment", "omega", True))
    s += block("dmc", points(co, "dem_al_oxide", "theta_contact")) + block("dme", points(co, "dem_al_oxide", "e_t"))
    s += block("dmw", points(co, "dem_al_oxide", "omega", True))
    kh_style = "with points pt 7 ps 1.3 lc rgb 'black' title 'Kharaz et al. 2001 (Lethe digitisation)'"
    co_style = "with points pt 6 ps 1.6 lw 1.5 lc rgb 'black' title 'same, re-plotted by Chung \\& Ooi (Kratos digitisation)'"
    dm_style = "with linespoints pt 4 ps 0.9 dt 2 lc rgb '#CC79A7' title 'Chung \\& Ooi DEM reference, Al_2O_3 (Hertz-Mindlin)'"
    s += ["set encoding utf8", "set terminal pngcairo size 1500,1150 enhanced font 'sans,11'", f"set output '{out}'",
          "set multiplot layout 2,2 title '5 mm Al_2O_3 sphere on soda-lime glass, 3.9 m/s, no spin: rigid impulse laws "
          "(solve\\_impact at the pole, e_n = 0.98) against measurements; dotted: rolling/sliding transition 32.5{/Symbol \\260}'",
          "set grid", "set xrange [0:90]", "set xlabel 'incidence angle from the normal [deg]'"]
    s += panel("rebound angle of the centre of mass, atan(V''_t / V''_n)", "rebound angle [deg]", "0:90", 4,
               [f"$khr {kh_style}"], "top left", True)
    s += panel("rebound angle of the contact point, atan(u''_t / V''_n)", "contact rebound angle [deg]", "-30:90", 5,
               [f"$dmc {dm_style}", f"$coc {co_style}"], "top left", False)
    s += panel("tangential coefficient e_t = V''_t / V_t", "e_t", "0.4:1.05", 2,
               [f"$dme {dm_style}", f"$khe {kh_style}", f"$coe {co_style}"], "bottom right", False)
    s += panel("spin after the impact", "|{/Symbol W}''| [rad/s]", "0:800", 3,
               [f"$dmw notitle {dm_style.split(' title ')[0]}", f"$khw {kh_style.split(' title ')[0]} notitle",
                f"$cow {co_style.split(' title ')[0]} notitle"], "off", False)
    s.append("unset multiplot")
    subprocess.run(["gnuplot"], input="\n".join(s) + "\n", text=True, check=True)
    print(out)


if __name__ == "__main__":
    main()
