#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Figure of docs/science-beyond.md "Bounces of rough bodies": eps and spin against impact speed for several bodies.

Usage: scripts/plot_body_bounces.py OUT.png LABEL=report.json [LABEL=report.json ...]
Each report.json is written by `rough_bodies bounce` or `validate-geometry` (body bounce runs:
bounce.body.eps_by_speed). Needs gnuplot (pngcairo).
"""
import json
import subprocess
import sys


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out, runs = sys.argv[1], []
    for arg in sys.argv[2:]:
        label, path = arg.rsplit("=", 1)
        with open(path) as f:
            j = json.load(f)
        runs.append((label, j["bounce"]["body"]["eps_by_speed"], j["bounce"]["beta"], j["bounce"]["variants"][0]))
    colours = ["#0072B2", "#D55E00", "#009E73", "#CC79A7"]
    s = []
    for k, (label, bins, _, _) in enumerate(runs):
        s.append(f"$d{k} << EOD")
        for b in bins:
            if b["n"] >= 5 and b["eps_mean"] is not None:
                u = 0.5 * (b["range"][0] + b["range"][1])
                s.append(f'{u} {b["eps_mean"]} {b["eps_mean_se"]} {b["eps_q10"]} {b["eps_q90"]} {b["spin_mean_rad_s"]}')
        s.append("EOD")
    s += ["set encoding utf8", "set terminal pngcairo size 1000,900 enhanced font 'sans,12'", f"set output '{out}'",
          "set multiplot layout 2,1", "set grid", "set key top right", "set xlabel 'impact speed u = -V_z [m/s]'",
          "set ylabel '{/Symbol e} = -V''_z/V_z'", "set yrange [-0.2:2.5]",
          "set title 'Bounce sequences from u = 1 m/s, {/Symbol W} = 0: mean {/Symbol e} {/Symbol \\261} se, band 10%-90%'"]
    plot = []
    for k, (label, *_r) in enumerate(runs):
        c = colours[k % 4]
        plot.append(f"$d{k} using 1:4:5 with filledcurves fs transparent solid 0.15 lc rgb '{c}' notitle")
        plot.append(f"$d{k} using 1:2:3 with yerrorlines pt 7 ps 0.7 lc rgb '{c}' title '{label}'")
    s.append("plot " + ", \\\n  ".join(plot))
    s += ["set title 'mean spin |{/Symbol W}| before the impact'", "set ylabel '|{/Symbol W}| [rad/s]'", "set logscale y",
          "set yrange [*:*]", "set format y '10^{%L}'"]
    plot = []
    for k, (label, *_r) in enumerate(runs):
        plot.append(f"$d{k} using 1:6 with linespoints pt 7 ps 0.7 lc rgb '{colours[k % 4]}' title '{label}'")
    s.append("plot " + ", \\\n  ".join(plot))
    s += ["unset multiplot", "unset output"]
    subprocess.run(["gnuplot"], input="\n".join(s) + "\n", text=True, check=True)


if __name__ == "__main__":
    main()
