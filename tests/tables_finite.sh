#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# No nan or inf in a user-facing table (issue 32): every preset, cheaply sized, writes report.txt
# without a "nan"/"inf" token; where a number does not exist the table says why ("one-sided",
# "not defined"). Arguments: VALIDATE_GEOMETRY [TABLE...]: with tables given, only checks those
# (tests/tables/with-nan.txt must be refused: the check's power). Fig. 4 and Fig. 5 also draw their
# figures (small): no legend shows a law's internal id (eq28-printed) where a label belongs.
set -uo pipefail
vg=$1; shift
bad=0
check() {  # check FILE LABEL
  local hits
  hits=$(grep -n -i -E '(^|[^a-z])[+-]?(nan|inf)([^a-z]|$)' "$1" | grep -v -i 'info' || true)
  if [ -n "$hits" ]; then echo "FAIL $2: nan/inf in the table:"; echo "$hits" | head -5; bad=1; else echo "ok   $2"; fi
}
if [ $# -gt 0 ]; then
  for f in "$@"; do check "$f" "$f"; done
  exit "$bad"
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/asperity-tables.XXXXXX")
trap 'rm -rf "$work"' EXIT
run() {  # run NAME ARGS...
  local name=$1; shift
  local plots=(--no-plots)
  case $name in fig4|fig5) plots=(--plot-format png@0.25) ;; esac
  "$vg" --out "$work/$name" "${plots[@]}" --threads 2 "$@" > "$work/$name.log" 2>&1
  local rc=$?
  if [ "$rc" -gt 1 ]; then echo "FAIL $name: validate-geometry exited $rc"; tail -5 "$work/$name.log"; bad=1; return; fi
  check "$work/$name/report.txt" "$name ($*)"
  local ids
  ids=$(cut -d, -f1 "$work/$name"/*.csv 2>/dev/null | grep -E '^"?(eq[0-9]+|exact)-[a-z]' | sort -u || true)
  if [ -n "$ids" ]; then echo "FAIL $name: figure legends show internal ids: $ids"; bad=1; fi
}
run fig3 --preset fig3 --drops 2000
run fig3-fixed --preset fig3-fixed --drops 2000
run fig4 --preset fig4 --drops 2000
run fig5 --preset fig5 --drops 2000
run fig6 --preset fig6 --sequences 2000
exit "$bad"
