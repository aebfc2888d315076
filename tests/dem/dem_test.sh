#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The LAMMPS coupling's tests (ctest -L dem; docs/dem-coupling.md). Each case runs asperity-lammps
# on the examples in a fresh directory and checks the output with dem_check.
#   dem_test.sh CASE LMP VG CHECK SRC WORK
# (c_example needs only a C compiler: it runs the header's C example as docs/dem-coupling.md shows it.)
# LMP = "" (asperity-lammps not built: no liblammps-dev) -> exit 77, which ctest reports as skipped.
set -euo pipefail
case_=$1 lmp=$2 vg=$3 check=$4 src=$5 work=$6
if [ "$case_" = c_example ]; then  # the C example's commands of docs/dem-coupling.md section 8, as written there
  mkdir -p "$work/c_example" && cd "$src"
  cc -std=c99 -O2 -I include examples/bouncing_ball.c -lm -o "$work/c_example/bouncing_ball"
  "$work/c_example/bouncing_ball" tests/fuzz/corpus/cor_table/format1.csv | tail -1 | tee "$work/c_example/summary"
  grep -q "^# 10000 rebounds at 0.990454 m/s: mean achieved eps 0.797818, max |achieved - drawn| 3.68e-04" "$work/c_example/summary"
  exit
fi
if [ -z "$lmp" ]; then
  echo "SKIPPED: asperity-lammps is not built (Debian's liblammps-dev + lammps are not installed: apt-get install lammps liblammps-dev, then configure again)"
  exit 77
fi
ex=$src/examples/dem
table=$work/table/rough-sphere.csv
fresh() { rm -rf "$work/$1" && mkdir -p "$work/$1" && cd "$work/$1"; }
lammps() { "$lmp" -in "$1" -screen none -log lammps.log "${@:2}"; }

case $case_ in
  table)  # the restitution table, written by the product from the example scene
    rm -rf "$work/table"
    "$vg" -q --no-plots --scene "$ex/rough-sphere.toml" --out "$work/table"
    head -1 "$table" ;;
  headon)  # 10^4 head-on collisions at 1 m/s: achieved eps ~ the table's law at 1 m/s
    fresh headon
    lammps "$ex/two-spheres.in" -var table "$table" -var pairs 10000
    "$check" headon "$table" contacts.log final.dump 1.0 accept ;;
  wrong_damping)  # the same with every gamma_n 1 % too large: must be rejected
    fresh wrong_damping
    lammps "$ex/two-spheres.in" -var table "$table" -var pairs 10000 -var scale 1.01
    "$check" headon "$table" contacts.log final.dump 1.0 reject ;;
  bounce)  # 225 balls x 50 impacts on the plate: residuals ~ Eq. 2 at the Sec. V rates
    fresh bounce
    lammps "$ex/bouncing-ball.in" -var table "$table" -var balls 225 -var impacts 50
    "$check" bounce "$table" impacts.log ;;
  ranks)  # the same contacts, eps and final velocities on 1 and 2 MPI ranks (each pair split over both)
    fresh ranks
    # one start for both (create_atoms numbers atoms by rank): written by a first run
    lammps "$ex/two-spheres.in" -var table "$table" -var pairs 400 -var log zero.log -var out zero.dump -var start save
    lammps "$ex/two-spheres.in" -var table "$table" -var start load -var log one.log -var out one.dump
    mpirun --allow-run-as-root --oversubscribe -np 2 "$lmp" -in "$ex/two-spheres.in" -screen none -log two.lammps \
      -var table "$table" -var start load -var px 2 -var log two.log -var out two.dump
    grep -v "^#" one.log | sort > one.sorted && cat two.log two.log.1 | grep -v "^#" | sort > two.sorted
    grep -c pair one.sorted
    cmp one.sorted two.sorted && cmp one.dump two.dump && echo "ranks: 1 and 2 ranks gave the same contacts, eps and velocities" ;;
  migrate)  # pairs drifting at 20 m/s across the rank boundary in mid-contact (kn 1e5: a 0.2 ms contact);
    # the contact records travel with their atoms: the same draws and velocities on 1 and 2 ranks
    fresh migrate
    common=(-var table "$table" -var pairs 100 -var drift 20 -var xb p -var kn 1e5)
    lammps "$ex/two-spheres.in" "${common[@]}" -var log zero.log -var out zero.dump -var start save
    lammps "$ex/two-spheres.in" "${common[@]}" -var start load -var log one.log -var out one.dump
    mpirun --allow-run-as-root --oversubscribe -np 2 "$lmp" -in "$ex/two-spheres.in" -screen none -log two.lammps \
      "${common[@]}" -var start load -var px 2 -var log two.log -var out two.dump
    grep -v "^#" one.log | sort > one.sorted && cat two.log two.log.1 | grep -v "^#" | sort > two.sorted
    test "$(wc -l < one.sorted)" = 100
    cmp one.sorted two.sorted && cmp one.dump two.dump && echo "migrate: 100 contacts crossed ranks; the same draws and velocities on 1 and 2 ranks" ;;
  bad_input)  # refusals name the key and the value, exit 1, and write no log
    fresh bad_input
    printf '# asperity-cor-table format=1 speeds=1 probabilities=2\nspeed_m_s,p=0,p=1\n1,0.9,0.8\n' > bad.csv
    refused() {  # refused EXPECTED_MESSAGE lammps-args...
      local want=$1; shift
      if "$lmp" -log none "$@" > out.txt 2>&1; then echo "accepted: $*"; return 1; fi
      grep -F -- "$want" out.txt || { cat out.txt; return 1; }
    }
    refused "pair_style asperity/hooke: table: line 3: '0.8': quantiles must not decrease along a row" \
      -in "$ex/two-spheres.in" -var table bad.csv -var log none
    refused "fix asperity/wall/hooke: table: line 3: '0.8': quantiles must not decrease along a row" \
      -in "$ex/bouncing-ball.in" -var table bad.csv -var log none
    refused "constant '1.5': eps must lie in [0, 1]" -in "$ex/two-spheres.in" -var table "$table" -var constant 1.5 -var log none
    touch taken.log
    refused "log 'taken.log': cannot create it" -in "$ex/two-spheres.in" -var table "$table" -var log taken.log
    test ! -s taken.log && echo "bad_input: 4 refusals" ;;
  native)  # with one eps for every contact, the coupling's force is LAMMPS's own gran/hooke/history
    fresh native
    lammps "$ex/two-spheres.in" -var table none -var constant 0.95 -var pairs 100 -var log none -var out asperity.dump
    lammps "$ex/two-spheres.in" -var table none -var constant 0.95 -var pairs 100 -var native 1 -var out native.dump
    paste <(sed -n '/ITEM: ATOMS/,$p' asperity.dump | tail -n +2) <(sed -n '/ITEM: ATOMS/,$p' native.dump | tail -n +2) |
      awk '$1 != $4 {print "atom order differs"; exit 1}
           {d = $3 - $6; d = d < 0 ? -d : d; m = d > m ? d : m; if ($2 == 2) e += 2 * $3; n += $2 == 2}
           END {printf "native: %d pairs, max |vx(asperity) - vx(gran/hooke/history)| = %.3g m/s (bound 1e-12), mean eps %.8f (0.95)\n", n, m, e / n
                exit !(n == 100 && m < 1e-12 && e / n > 0.9499 && e / n < 0.9501)}' ;;
  bench)  # the cost scripts of docs/dem-coupling.md section 5, at a tiny size (the figures there come from the full size)
    fresh bench
    build=$(dirname "$(dirname "$(dirname "$lmp")")")
    "$src/bench/dem_lammps_cost.sh" "$build" "$table" 20 1 | tee cost.out
    grep -q "^per contact (1000 steps each): table - constant" cost.out
    ;;
  bench_ir)  # the callgrind script of docs/dem-coupling.md section 5, at 2 and 4 pairs (~1-2 min)
    if ! command -v valgrind > /dev/null; then
      echo "SKIPPED: valgrind is not installed (bench/dem_lammps_instructions.sh needs callgrind)"
      exit 77
    fi
    fresh bench_ir
    build=$(dirname "$(dirname "$(dirname "$lmp")")")
    "$src/bench/dem_lammps_instructions.sh" "$build" "$table" 2 | tee ir.out
    grep -Eq "^table - constant: -?[0-9]+ instructions per contact" ir.out ;;
  examples)  # the commands of docs/dem-coupling.md, as written there (in a copy of examples/dem)
    fresh examples
    cp "$ex"/two-spheres.in "$ex"/bouncing-ball.in "$table" .
    "$lmp" -in two-spheres.in -var table rough-sphere.csv
    "$lmp" -in bouncing-ball.in -var table rough-sphere.csv
    test "$(grep -c pair contacts.log)" = 1 && test "$(grep -c wall impacts.log)" = 50
    echo "examples: 1 pair contact, 50 impacts" ;;
  *) echo "unknown case $case_" >&2; exit 2 ;;
esac
