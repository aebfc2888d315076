#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The cost of drawing eps per contact in LAMMPS (docs/dem-coupling.md, bench/RESULTS.md):
# examples/dem/two-spheres.in with PAIRS head-on pairs (one contact each, 1000 steps long), run
# REPS times in turn with
#   table:    pair_style asperity/hooke, eps drawn per contact from TABLE (no log)
#   constant: pair_style asperity/hooke with one eps = 0.95 (the same code, no draw)
#   native:   LAMMPS's own gran/hooke/history with that eps (the reference contact model)
# and prints LAMMPS's loop time and Pair time per run, their medians, and the ratios.
#   bench/dem_lammps_cost.sh BUILD_DIR TABLE [PAIRS=10000] [REPS=5]
set -euo pipefail
build=$(realpath "$1") table=$(realpath "$2") pairs=${3:-10000} reps=${4:-5}
src=$(cd "$(dirname "$0")/.." && pwd)
lmp=$build/src/dem/asperity-lammps
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
echo "# $(date -u '+%F %T') UTC, $(nproc) cores, load: $(cut -d' ' -f1-3 /proc/loadavg), pairs=$pairs reps=$reps"
for r in $(seq "$reps"); do
  for mode in table constant native; do
    case $mode in
      table) args=(-var table "$table") ;;
      constant) args=(-var table "$table" -var constant 0.95) ;;
      native) args=(-var table none -var constant 0.95 -var native 1) ;;
    esac
    "$lmp" -in "$src/examples/dem/two-spheres.in" -screen none -log run.log -var pairs "$pairs" -var log none \
      -var out /dev/null "${args[@]}"
    loop=$(awk '/^Loop time of/ {print $4}' run.log)
    pair=$(awk '$1 == "Pair" && $2 == "|" {print $5}' run.log)
    echo "$mode $loop $pair" | tee -a times
  done
done
for mode in table constant native; do
  loop=$(awk -v m=$mode '$1 == m {print $2}' times | median)
  pair=$(awk -v m=$mode '$1 == m {print $3}' times | median)
  spread=$(awk -v m=$mode '$1 == m {if (n++ == 0 || $2 < lo) lo = $2; if ($2 > hi) hi = $2} END {print hi - lo}' times)
  eval "loop_$mode=$loop pair_$mode=$pair spread_$mode=$spread"
  printf '%-8s median loop %.3f s, median Pair %.3f s, loop spread (max - min) %.3f s\n' "$mode" "$loop" "$pair" "$spread"
done
# A difference of two medians is reported as a time only where it exceeds both runs' spread (max - min
# over the REPS runs); otherwise it is below what these runs resolve, and said so -- never a negative time.
awk -v t="$loop_table" -v c="$loop_constant" -v n="$loop_native" -v pt="$pair_table" -v pc="$pair_constant" \
    -v pn="$pair_native" -v st="$spread_table" -v sc="$spread_constant" -v sn="$spread_native" -v k="$pairs" '
function diff(name, a, b, sa, sb,   s) {
  s = sa > sb ? sa : sb
  if (a - b > s && a - b > 0) return sprintf("%s %.2f us", name, (a - b) / k * 1e6)
  return sprintf("%s below the run-to-run spread (%.2f us)", name, s / k * 1e6)
}
BEGIN {
  printf "loop: table/constant %.3f, constant/native %.3f; Pair: table/constant %.3f, constant/native %.3f\n", t/c, c/n, pt/pc, pc/pn
  printf "per contact (1000 steps each): %s of loop time, %s\n", diff("table - constant", t, c, st, sc), diff("constant - native", c, n, sc, sn) }'
echo "# load after: $(cut -d' ' -f1-3 /proc/loadavg)"
