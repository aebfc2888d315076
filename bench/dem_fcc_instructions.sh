#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The coupling's cost in a dense packing (issue 40 item 7; bench/RESULTS.md): bench/dem_fcc.in runs an
# FCC packing (every sphere in contact with its 12 neighbours) first with pair_style asperity/hooke
# (constant eps: no draw) and then, in the same process, with LAMMPS's gran/hooke/history from the
# same start; callgrind counts the instructions of each style's compute() (inclusive: with its contact
# records, searches and sweeps) and prints them per atom-step (atoms x (steps + 1): the setup calls
# compute once more), their ratio, and the two final kinetic energies (equal: the same dynamics).
#   bench/dem_fcc_instructions.sh BUILD_DIR [N=6 (4 N^3 atoms)] [STEPS=100]
set -euo pipefail
build=$(realpath "$1") n=${2:-6} steps=${3:-100}
src=$(cd "$(dirname "$0")/.." && pwd)
lmp=$build/src/dem/asperity-lammps
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
valgrind --tool=callgrind --callgrind-out-file=cg.out "$lmp" -in "$src/bench/dem_fcc.in" -var n "$n" -var steps "$steps" \
  -screen none -log run.log 2> cg.err
grep '^dem_fcc:' run.log
callgrind_annotate --inclusive=yes cg.out 2>/dev/null |
  awk -v atoms=$((4 * n * n * n)) -v steps="$steps" '
    /PairHooke::compute\(int, int\)/ {gsub(",", "", $1); a = $1}
    /PairGranHookeHistory::compute\(int, int\)/ {gsub(",", "", $1); g = $1}
    END {
      if (!(a > 0 && g > 0)) {print "dem_fcc: compute() of a style not found in the profile"; exit 1}
      k = atoms * (steps + 1)
      printf "dem_fcc: %d atoms, %d steps: asperity/hooke %.0f, gran/hooke/history %.0f instructions per atom-step; ratio %.3f\n", atoms, steps, a / k, g / k, a / g }'
