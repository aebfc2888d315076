#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Marginal instructions per drop by phase between two callgrind runs that differ only in the number
# of spheres (bench/RESULTS.md, "Drop engine, issue 30"): inclusive cost of each phase's function in
# run B minus run A, divided by the drops B has more. Usage: callgrind_phases.py A.out B.out DROPS.
import re, subprocess, sys
def incl(path):
    out = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", path], capture_output=True, text=True).stdout
    rows = []
    for line in out.splitlines():
        m = re.match(r"\s*([\d,]+)\s+(?:\([^)]*\)\s+)?(.*)", line)
        if m and m.group(1)[0].isdigit():
            rows.append((int(m.group(1).replace(",", "")), m.group(2)))
    return rows
def total(rows, pat, excl=None):
    s = 0
    for v, name in rows:
        if re.search(pat, name) and not (excl and re.search(excl, name)):
            s = max(s, v) if pat.startswith("^max:") else s + v
    return s
phases = [  # (label, regex on the function name); inclusive, so disjoint patterns only
    ("drop loop (query_drops, incl.)", r"query_drops<"),
    ("  draw", r"draw_(avx2|avx512|scalar|sse2)\(|draw_drops_isa|draw_batch"),
    ("  grid lowest (batched)", r"Grid::(lowest|lowest_winners)\(std::span"),
    ("  contacts", r"contacts_(avx2|avx512|scalar|sse2)\("),
    ("sphere generation", r"make_rough_sphere\("),
    ("index build", r"make_contact_query\("),
    ("cross-check", r"cross_check_sphere\("),
    ("small_sphere_wave (incl.)", r"small_sphere_wave\("),
    ("analysis (analyse_stream)", r"analyse_stream\("),
    ("PROGRAM", r"PROGRAM TOTALS"),
]
a, b, drops = incl(sys.argv[1]), incl(sys.argv[2]), int(sys.argv[3])
for label, pat in phases:
    fa = [v for v, n in a if re.search(pat, n)]; fb = [v for v, n in b if re.search(pat, n)]
    va, vb = (max(fa) if fa else 0), (max(fb) if fb else 0)
    print(f"{label:40s} {(vb - va) / drops:9.1f}")
