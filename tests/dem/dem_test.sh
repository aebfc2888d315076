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
  table)  # the restitution table, written by the product from the example scene; and an independent
    # one-speed table at 0.62 m/s (between the rows 0.6031 and 0.6614; its own seed) for dem.headon
    rm -rf "$work/table"
    "$vg" -q --no-plots --scene "$ex/rough-sphere.toml" --out "$work/table"
    # (4x10^5 drops, 2001 probabilities: its own sampling noise well below the table's)
    sed -e 's/^speeds = \[.*/speeds = [0.62]/' -e 's/^file = .*/file = "ref-0.62.csv"/' -e 's/^seed = 7/seed = 8/' \
      -e 's/^name = .*/name = "ref-0.62"/' -e 's/^drops = 100000/drops = 400000/' -e 's/^probabilities = 501/probabilities = 2001/' \
      "$ex/rough-sphere.toml" > "$work/ref-0.62.toml"
    grep -q '^speeds = \[0.62\]' "$work/ref-0.62.toml" && grep -q '^seed = 8' "$work/ref-0.62.toml" && grep -q '^drops = 400000' "$work/ref-0.62.toml"
    "$vg" -q --no-plots --scene "$work/ref-0.62.toml" --out "$work/table"
    head -1 "$table" "$work/table/ref-0.62.csv" ;;
  headon)  # 10^4 head-on collisions at 0.62 m/s, between two rows of the table they draw from, checked
    # against the independent one-speed table at 0.62 m/s, read by dem_check's own parser
    fresh headon
    lammps "$ex/two-spheres.in" -var table "$table" -var pairs 10000 -var speed 0.62
    "$check" headon_ref "$work/table/ref-0.62.csv" contacts.log final.dump 0.62 accept 100000 400000
    # a wrong input it must refuse: the reference at another speed than the run's
    if "$check" headon_ref "$work/table/ref-0.62.csv" contacts.log final.dump 1.0 accept 100000 400000; then
      echo "headon: a reference at 0.62 m/s was accepted for a run at 1 m/s"; exit 1
    fi ;;
  wrong_damping)  # every gamma_n 1 % too large, 4000 pairs at 1 m/s: must be rejected
    fresh wrong_damping
    lammps "$ex/two-spheres.in" -var table "$table" -var pairs 4000 -var scale 1.01
    "$check" headon "$table" contacts.log final.dump 1.0 reject ;;
  bounce)  # 225 balls x 50 impacts on the plate: residuals ~ Eq. 2 at the Sec. V rates
    fresh bounce
    lammps "$ex/bouncing-ball.in" -var table "$table" -var balls 225 -var impacts 50
    "$check" bounce "$table" impacts.log ;;
  bounce_swapped)  # the same from a table whose 0.3162 and 0.3468 m/s rows are swapped: must be rejected
    fresh bounce_swapped
    awk -F, '$1 == "0.3162" {a = $0; next} $1 == "0.3468" {print "0.3162" substr($0, index($0, ",")); print "0.3468" substr(a, index(a, ",")); next} {print}' \
      "$table" > swapped.csv
    test "$(wc -l < swapped.csv)" = "$(wc -l < "$table")" && ! cmp -s swapped.csv "$table"
    lammps "$ex/bouncing-ball.in" -var table swapped.csv -var balls 225 -var impacts 50
    "$check" bounce "$table" impacts.log reject ;;
  ranks)  # the same contacts, eps and final velocities on 1 and 2 MPI ranks (each pair split over both)
    fresh ranks
    # one start for both (create_atoms numbers atoms by rank): written by a first run
    lammps "$ex/two-spheres.in" -var table "$table" -var pairs 400 -var log zero.log -var out zero.dump -var start save
    lammps "$ex/two-spheres.in" -var table "$table" -var start load -var log one.log -var out one.dump
    mpirun --allow-run-as-root --oversubscribe -np 2 "$lmp" -in "$ex/two-spheres.in" -screen none -log two.lammps \
      -var table "$table" -var start load -var px 2 -var log two.log -var out two.dump -var procs 1
    grep -v "^#" one.log | sort > one.sorted && cat two.log two.log.1 | grep -v "^#" | sort > two.sorted
    test "$(grep -c pair one.sorted)" = 400
    # every contact's two atoms are owned by different ranks (procs.dump: id proc, at the end of the run)
    awk 'FNR == NR {if (f) rank[$1] = $2; if (/^ITEM: ATOMS/) f = 1; next}
         {n++; if (!($3 in rank) || !($4 in rank)) {print "atom missing from procs.dump"; exit 1}; s += rank[$3] != rank[$4]}
         END {printf "ranks: %d of %d contacts between atoms on different ranks\n", s, n; exit !(n == 400 && s == n)}' \
      procs.dump two.sorted
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
  restart)  # write_restart in mid-contact (wall and pair) and read_restart: the same as the run that never stopped
    fresh restart
    in=$src/tests/dem/restart.in
    phase() { "$lmp" -in "$in" -screen none -log "$1.lammps" -var table "$table" -var phase "$1" -var plog "$1.pair" -var wlog "$1.wall" "${@:2}"; }
    phase straight && mv final.dump straight.dump
    phase write
    phase read && mv final.dump read.dump
    phase read_other -var wallid other && mv final.dump other.dump
    maxdv() { paste <(sed -n '/ITEM: ATOMS/,$p' "$1" | tail -n +2) <(sed -n '/ITEM: ATOMS/,$p' "$2" | tail -n +2) |
      awk '$1 != $5 {print "atom order differs" > "/dev/stderr"; exit 1}
           {for (k = 2; k <= 4; ++k) {d = $k - $(k + 4); d = d < 0 ? -d : d; m = d > m ? d : m}} END {printf "%.3g\n", m}'; }
    d_read=$(maxdv straight.dump read.dump) d_other=$(maxdv straight.dump other.dump)
    echo "restart: max |v(read_restart) - v(uninterrupted)| = $d_read m/s (bound 1e-9); with the wall's records not restored: $d_other"
    awk -v a="$d_read" -v b="$d_other" 'BEGIN {exit !(a <= 1e-9 && b > 1e-9)}'
    # no contact is drawn again after the restart: the contacts of write + read are those of the uninterrupted run
    grep -hv '^#' straight.pair straight.wall | sort > straight.all
    grep -hv '^#' write.pair write.wall read.pair read.wall | sort > cut.all
    cmp straight.all cut.all && test "$(wc -l < straight.all)" = 3
    # the pair created overlapping and separating: no impact, the lowest row's median, counted
    median=$(awk -F, '/^speed_m_s/ {for (k = 2; k <= NF; ++k) if ($k == "p=0.5") c = k; next} /^[0-9]/ && c {print $c; exit}' "$table")
    awk -v m="$median" '$2 == "pair" && $3 == 4 && $4 == 5 {n++; d = $7 - m; ok = $9 == "separating" && d * d < 1e-24}
      END {printf "restart: atoms 4-5, first seen separating: eps %s (the lowest row'"'"'s median %s)\n", ok ? "= median" : "WRONG", m; exit !(n == 1 && ok)}' straight.all
    grep -F "pair_style asperity/hooke: 2 contacts begun in this run: 1 within the table's speeds, 0 below them" straight.lammps | grep -F "1 first seen separating"
    ;;
  units)  # the bouncing balls in units cgs equal those in si; units metal is refused, naming units
    fresh units
    lammps "$ex/bouncing-ball.in" -var table "$table" -var balls 25 -var impacts 20 -var log si.log
    lammps "$ex/bouncing-ball.in" -var table "$table" -var balls 25 -var impacts 20 -var log cgs.log -var units cgs
    paste <(grep -v '^#' si.log) <(grep -v '^#' cgs.log) |
      awk '{n++; for (k = 5; k <= 7; k += 2) {d = ($k - $(k + 9)) / $k; d = d < 0 ? -d : d; m = d > m ? d : m}}
           END {printf "units: %d impacts, max relative |si - cgs| of approach speed and eps = %.3g (bound 1e-9)\n", n, m; exit !(n == 500 && m < 1e-9)}'
    if "$lmp" -log none -in "$ex/bouncing-ball.in" -var table "$table" -var log none -var units metal > out.txt 2>&1; then
      echo "units metal was accepted"; exit 1
    fi
    grep -F "fix asperity/wall/hooke: 'units metal' is not supported: the table's speeds are m/s" out.txt ;;
  pour)  # fix pour into an empty box, and into one with a 1 mm sphere: no atom lost, no deep overlap
    fresh pour
    for seed_atom in 0 1; do
      lammps "$ex/pour.in" -var table "$table" -var seed_atom "$seed_atom" -var out "final$seed_atom.dump"
      sed -n '/ITEM: ATOMS/,$p' "final$seed_atom.dump" | tail -n +2 |
        awk -v want=$((60 + seed_atom)) '{id[NR] = $1; r[NR] = $2; x[NR] = $3; y[NR] = $4; z[NR] = $5}
          END {L = 0.03; worst = 0
               for (i = 1; i <= NR; ++i) {if (z[i] < r[i] * 0.9) worst = 1e9
                 for (j = i + 1; j <= NR; ++j) {dx = x[i] - x[j]; dy = y[i] - y[j]; dx -= L * int(2 * dx / L); dy -= L * int(2 * dy / L)
                   d = sqrt(dx * dx + dy * dy + (z[i] - z[j]) ^ 2); o = (r[i] + r[j] - d) / (r[i] + r[j]); if (o > worst) worst = o}}
               printf "pour: %d atoms (%d expected), deepest overlap %.3g of the radius sum (bound 0.05)\n", NR, want, worst
               exit !(NR == want && worst < 0.05)}'
    done
    # the wrong input it must refuse: an empty box with nothing to insert atoms (no radius to size the cutoff)
    grep -v '^fix pour' "$ex/pour.in" > nopour.in
    if "$lmp" -log none -in nopour.in -var table "$table" > out.txt 2>&1; then echo "an empty box without fix pour was accepted"; exit 1; fi
    grep -F "no atom with a radius > 0, and no fix pour or fix deposit to insert one" out.txt ;;
  hybrid)  # pair_style hybrid (asperity/hooke for type pair 1 2, zero elsewhere) gives the plain style's run
    fresh hybrid
    lammps "$ex/two-spheres.in" -var table "$table" -var pairs 100 -var log plain.log -var out plain.dump
    lammps "$ex/two-spheres.in" -var table "$table" -var pairs 100 -var log hybrid.log -var out hybrid.dump -var hybrid 1
    test "$(grep -vc '^#' hybrid.log)" = 100 && cmp plain.log hybrid.log && cmp plain.dump hybrid.dump
    echo "hybrid: 100 contacts, the same draws and velocities as without hybrid"
    # the keyword 'table' under hybrid starts LAMMPS's pair style table: refused (use cortable)
    if "$lmp" -log none -in "$ex/two-spheres.in" -var table "$table" -var hybrid 2 -var log none > out.txt 2>&1; then
      echo "hybrid with the keyword 'table' was accepted"; exit 1
    fi
    grep -F "under pair_style hybrid write 'cortable FILE'" out.txt ;;
  outside)  # contacts outside the table's speeds (0.05-2 m/s) are flagged per contact and counted; 'outside error' refuses them
    fresh outside
    lammps "$ex/two-spheres.in" -var table "$table" -var pairs 20 -var speed 3.0 -var log fast.log -var out fast.dump
    cp lammps.log fast.lammps
    lammps "$ex/two-spheres.in" -var table "$table" -var pairs 20 -var speed 0.03 -var log slow.log -var out slow.dump
    test "$(awk '$9 == "above"' fast.log | wc -l)" = 20 && test "$(awk '$9 == "below"' slow.log | wc -l)" = 20
    grep -F "20 contacts begun in this run: 0 within the table's speeds, 0 below them (drawn from the 0.05 m/s row), 20 above them (drawn from the 2 m/s row)" fast.lammps
    grep -F "20 contacts begun in this run: 0 within the table's speeds, 20 below them (drawn from the 0.05 m/s row), 0 above them" lammps.log
    sed 's/seed ${seed} scale_damping/seed ${seed} outside error scale_damping/' "$ex/two-spheres.in" > strict.in
    if "$lmp" -log none -in strict.in -var table "$table" -var speed 3.0 -var log none > out.txt 2>&1; then
      echo "outside error accepted a 3 m/s contact"; exit 1
    fi
    grep -F "meet at 3.000000 m/s, outside the table's speeds (outside error)" out.txt
    sed 's/seed ${seed} scale_damping/seed ${seed} outside maybe scale_damping/' "$ex/two-spheres.in" > bad.in
    if "$lmp" -log none -in bad.in -var table "$table" -var log none > out.txt 2>&1; then echo "outside maybe accepted"; exit 1; fi
    grep -F "outside 'maybe': clamp or error" out.txt
    echo "outside: 20 contacts at 3 m/s flagged above, 20 at 0.03 m/s below; outside error refuses" ;;
  types)  # two type pairs, two tables (pair_coeff 2 3 table B): each follows its own; B = 1 - 1.5 (1 - eps) of the table
    fresh types
    awk -F, 'BEGIN {OFS = ","} /^[0-9]/ {for (k = 2; k <= NF; ++k) $k = sprintf("%.12g", 1 - 1.5 * (1 - $k))} {print}' "$table" > b.csv
    lammps "$ex/two-spheres.in" -var table "$table" -var pairs 4000 -var types 1 -var table2 b.csv
    # split the contacts by the type of their left sphere (1: table, 3: b.csv)
    sed -n '/ITEM: ATOMS/,$p' final.dump | tail -n +2 | awk '{print $1, $2}' > types.txt
    awk 'FNR == NR {t[$1] = $2; next} /^#/ {next} {print > ((t[$3] == 3 || t[$4] == 3) ? "b.log" : "a.log")}' types.txt contacts.log
    echo "types: $(wc -l < a.log) contacts of type pair 1 2, $(wc -l < b.log) of 2 3"
    "$check" headon "$table" a.log final.dump 1.0 accept
    "$check" headon b.csv b.log final.dump 1.0 accept
    # the wrong input it must reject: type pair 1 2 checked against the other table
    "$check" headon b.csv a.log final.dump 1.0 reject ;;
  crowd)  # one sphere with 40 contacts (records start with 16 slots): runs, equals gran/hooke/history with one eps
    fresh crowd
    lammps "$src/tests/dem/crowd.in" -var table "$table" -var log crowd.log -var out asperity.dump
    lammps "$src/tests/dem/crowd.in" -var native 1 -var out native.dump
    test "$(grep -c '^0 pair 1 ' crowd.log)" = 40
    paste <(sed -n '/ITEM: ATOMS/,$p' asperity.dump | tail -n +2) <(sed -n '/ITEM: ATOMS/,$p' native.dump | tail -n +2) |
      awk '$1 != $5 {print "atom order differs"; exit 1}
           {for (k = 2; k <= 4; ++k) {d = $k - $(k + 4); d = d < 0 ? -d : d; m = d > m ? d : m}; if ($1 == 1) v = $2 * $2 + $3 * $3 + $4 * $4}
           END {printf "crowd: 40 contacts on atom 1; max |v(asperity) - v(gran/hooke/history)| = %.3g m/s (bound 1e-12)\n", m; exit !(NR == 41 && m < 1e-12)}'
    # the comparison can fail: gran/hooke/history with another eps (0.8) must differ by more than 1e-6 m/s
    lammps "$src/tests/dem/crowd.in" -var native 1 -var constant 0.8 -var out other.dump
    paste <(sed -n '/ITEM: ATOMS/,$p' asperity.dump | tail -n +2) <(sed -n '/ITEM: ATOMS/,$p' other.dump | tail -n +2) |
      awk '{for (k = 2; k <= 4; ++k) {d = $k - $(k + 4); d = d < 0 ? -d : d; m = d > m ? d : m}}
           END {printf "crowd: against eps 0.8 instead: max |dv| = %.3g m/s (must exceed 1e-6)\n", m; exit !(m > 1e-6)}' ;;
  walls)  # fix asperity/wall/hooke with one eps equals fix wall/gran hooke/history, plane and zcylinder (oblique, spin, friction)
    fresh walls
    for wall in zplane zcylinder; do
      lammps "$src/tests/dem/walls.in" -var wall $wall && mv final.dump asperity.dump
      grep -F "fix w asperity/wall/hooke: 9 contacts begun in this run, eps 0.9 (constant) for each" lammps.log
      lammps "$src/tests/dem/walls.in" -var wall $wall -var native 1 && mv final.dump native.dump
      paste <(sed -n '/ITEM: ATOMS/,$p' asperity.dump | tail -n +2) <(sed -n '/ITEM: ATOMS/,$p' native.dump | tail -n +2) |
        awk -v w=$wall '$1 != $8 {print "atom order differs"; exit 1}
             {for (k = 2; k <= 4; ++k) {d = $k - $(k + 7); d = d < 0 ? -d : d; m = d > m ? d : m; s += $k * $k}
              for (k = 5; k <= 7; ++k) {d = ($k - $(k + 7)) * 3e-3; d = d < 0 ? -d : d; m = d > m ? d : m}}
             END {printf "walls: %s, 9 spheres: max |v - v(wall/gran)| and R |omega - omega(wall/gran)| = %.3g m/s (bound 1e-12)\n", w, m
                  exit !(NR == 9 && m < 1e-12 && s > 0)}'
    done
    # a wrong input it must refuse
    sed 's/${wall} ${wallarg} constant/zcylinder -0.02 constant/' "$src/tests/dem/walls.in" > bad.in
    if "$lmp" -log none -in bad.in -var wall zcylinder > out.txt 2>&1; then echo "a negative cylinder radius was accepted"; exit 1; fi
    grep -F "zcylinder radius '-0.02' must be > 0" out.txt ;;
  install)  # cmake --install --component dem: the program, its examples and command pages; the installed example runs
    fresh install
    build=$(dirname "$(dirname "$(dirname "$lmp")")")
    cmake --install "$build" --prefix "$work/install/prefix" --component dem > install.out
    p=$work/install/prefix
    test -x "$p/bin/asperity-lammps"
    for page in pair_asperity_hooke fix_asperity_wall_hooke; do
      for section in Syntax Examples Description "Restart info" Restrictions "Related commands" Default; do
        grep -q "^## $section\$" "$p/share/doc/asperity/$page.md" || { echo "$page.md: no section '$section'"; exit 1; }
      done
    done
    cp "$p/share/asperity/examples/dem/two-spheres.in" "$table" .
    "$p/bin/asperity-lammps" -in two-spheres.in -var table rough-sphere.csv -screen none
    test "$(grep -c pair contacts.log)" = 1
    if "$p/bin/asperity-lammps" -in two-spheres.in -var table missing.csv -var log none -screen none > out.txt 2>&1; then
      echo "a missing table was accepted"; exit 1
    fi
    echo "install: $(wc -l < install.out) files; the installed asperity-lammps runs the installed example" ;;
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
    "$src/bench/dem_lammps_cost.sh" "$build" "$table" 20 3 | tee cost.out
    grep -q "^per contact (1000 steps each): table - constant" cost.out
    # no time it prints may be negative (a difference of two noisy walls is reported as below the spread);
    # the pattern catches the line the script printed before this check (a wrong input it must reject)
    neg='(^|[ (:=])-[0-9.]+ ?(s|us)\b'
    echo "per contact (1000 steps each): table - constant -861.92 us of loop time" | grep -Eq "$neg"
    if grep -Eq "$neg" cost.out; then echo "bench: a negative time was printed"; exit 1; fi
    awk '$1 ~ /^(table|constant|native)$/ && NF == 3 {n++; if (!($2 > 0 && $3 > 0)) bad++}
         END {exit !(n == 9 && bad == 0)}' cost.out || { echo "bench: 9 positive loop and Pair times expected"; exit 1; }
    ;;
  bench_ir)  # the dense-packing callgrind script of docs/dem-coupling.md section 5 at 32 atoms, 10 steps (one
    # valgrind run, ~10 s of CPU; bench/dem_lammps_instructions.sh, six runs, is left to the bench itself)
    if ! command -v valgrind > /dev/null; then
      echo "SKIPPED: valgrind is not installed (bench/dem_fcc_instructions.sh needs callgrind)"
      exit 77
    fi
    fresh bench_ir
    build=$(dirname "$(dirname "$(dirname "$lmp")")")
    "$src/bench/dem_fcc_instructions.sh" "$build" 2 10 | tee ir.out
    grep -Eq "^dem_fcc: 32 atoms, 10 steps: asperity/hooke [0-9]+, gran/hooke/history [0-9]+ instructions per atom-step; ratio [0-9.]+$" ir.out
    # the two styles ran the same dynamics: equal final kinetic energies (to 1e-12 relative)
    awk '/final kinetic energy/ {a = $6; b = $8; sub(",", "", a); d = (a - b) / b; exit !(d * d < 1e-24)}' ir.out ;;
  examples)  # the commands of docs/dem-coupling.md, as written there (in a copy of examples/dem)
    fresh examples
    cp "$ex"/two-spheres.in "$ex"/bouncing-ball.in "$ex"/pour.in "$table" .
    "$lmp" -in two-spheres.in -var table rough-sphere.csv
    "$lmp" -in bouncing-ball.in -var table rough-sphere.csv
    "$lmp" -in pour.in -var table rough-sphere.csv
    test "$(grep -c pair contacts.log)" = 1 && test "$(grep -c wall impacts.log)" = 50
    test "$(sed -n '/ITEM: ATOMS/,$p' final.dump | tail -n +2 | wc -l)" = 60
    echo "examples: 1 pair contact, 50 impacts, 60 spheres poured" ;;
  *) echo "unknown case $case_" >&2; exit 2 ;;
esac
