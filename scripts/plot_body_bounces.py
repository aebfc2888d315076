#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Figure of docs/science-beyond.md "Bounces of rough bodies": eps and spin against impact speed for several bodies.

Usage: scripts/plot_body_bounces.py OUT.png LABEL=report.json [LABEL=report.json ...]
Each report.json is written by `rough_bodies bounce` or `validate-geometry` (body bounce runs:
bounce.body.eps_by_speed). Needs matplotlib and numpy (scripts/setup --python installs them).
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = ["#0072B2", "#D55E00", "#009E73", "#CC79A7"]


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out, runs = sys.argv[1], []
    for arg in sys.argv[2:]:
        label, path = arg.rsplit("=", 1)
        with open(path) as f:
            j = json.load(f)
        bins = [b for b in j["bounce"]["body"]["eps_by_speed"] if b["n"] >= 5 and b["eps_mean"] is not None]
        runs.append((label, bins))
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 9), sharex=True)
    for k, (label, bins) in enumerate(runs):
        c = COLOURS[k % 4]
        u = [0.5 * (b["range"][0] + b["range"][1]) for b in bins]
        top.fill_between(u, [b["eps_q10"] for b in bins], [b["eps_q90"] for b in bins], color=c, alpha=0.15, lw=0)
        top.errorbar(u, [b["eps_mean"] for b in bins], yerr=[b["eps_mean_se"] for b in bins], fmt="o-", ms=3, color=c,
                     label=label)
        bottom.plot(u, [b["spin_mean_rad_s"] for b in bins], "o-", ms=3, color=c, label=label)
    top.set(title="Bounce sequences from u = 1 m/s, Ω = 0: mean ε ± se, band 10%-90%", ylabel="ε = -V'_z/V_z",
            ylim=(-0.2, 2.5))
    bottom.set(title="mean spin |Ω| before the impact", ylabel="|Ω| [rad/s]", yscale="log",
               xlabel="impact speed u = -V_z [m/s]")
    for ax in (top, bottom):
        ax.grid(True, alpha=0.4)
        ax.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    print(out)


if __name__ == "__main__":
    main()
