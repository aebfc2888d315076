#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Instructions (callgrind, deterministic, independent of the machine's load) of the same three runs
# as dem_lammps_cost.sh -- table, constant, native -- with PAIRS pairs; the difference per contact
# is the cost of the draw (table - constant) and of the coupling's records (constant - native).
#   bench/dem_lammps_instructions.sh BUILD_DIR TABLE [PAIRS=200]
set -euo pipefail
build=$(realpath "$1") table=$(realpath "$2") pairs=${3:-200}
src=$(cd "$(dirname "$0")/.." && pwd)
lmp=$build/src/dem/asperity-lammps
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
for mode in table constant native; do
  case $mode in
    table) args=(-var table "$table") ;;
    constant) args=(-var table "$table" -var constant 0.95) ;;
    native) args=(-var table none -var constant 0.95 -var native 1) ;;
  esac
  for p in "$pairs" $((2 * pairs)); do
    valgrind --tool=callgrind --callgrind-out-file=cg.out "$lmp" -in "$src/examples/dem/two-spheres.in" -screen none \
      -log none -var pairs "$p" -var log none -var out /dev/null "${args[@]}" 2> cg.err
    echo "$mode $p $(callgrind_annotate cg.out 2>/dev/null | awk '/PROGRAM TOTALS/ {gsub(",", "", $1); print $1}')"
  done
done | tee ir
# the slope between PAIRS and 2 PAIRS: instructions per pair (one contact of ~1000 steps, two atoms)
awk -v lo="$pairs" -v hi=$((2 * pairs)) '{ir[$1 " " $2] = $3} END {
  split("table constant native", modes, " ")
  for (m = 1; m <= 3; ++m) {
    s[modes[m]] = (ir[modes[m] " " hi] - ir[modes[m] " " lo]) / (hi - lo)
    printf "%-8s %.4g instructions per pair (one contact of 1000 steps, 2935 steps in all)\n", modes[m], s[modes[m]]
  }
  printf "table - constant: %.0f instructions per contact (the draw); constant / native: %.3f\n", s["table"] - s["constant"], s["constant"] / s["native"] }' ir
