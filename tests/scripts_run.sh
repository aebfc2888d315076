#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# scripts/run passes the user's arguments through and picks the output directory (issue 32): a
# user's --out or --resume wins (validate-geometry refuses two --out), otherwise out/<preset>,
# out/<scene file name>, or out/fig3. A stand-in validate-geometry prints its arguments
# (ASPERITY_VALIDATE_GEOMETRY: no setup, no build). Argument: SOURCE_DIR.
set -euo pipefail
src=$1
work=$(mktemp -d "${TMPDIR:-/tmp}/asperity-run.XXXXXX")
trap 'rm -rf "$work"' EXIT
printf '#!/bin/sh\necho "$*"\n' > "$work/vg"; chmod +x "$work/vg"
bad=0
expect() {  # expect "ARGS VALIDATE-GEOMETRY GETS" scripts/run ARGS...
  local want=$1; shift
  local got; got=$(ASPERITY_VALIDATE_GEOMETRY="$work/vg" "$src/scripts/run" "$@")
  if [ "$got" = "$want" ]; then echo "ok   scripts/run $*  ->  $got"
  else echo "FAIL scripts/run $*  ->  '$got', expected '$want'"; bad=1; fi
}
expect "--out out/fig3"                                   
expect "--out out/fig4 --preset fig4"                      --preset fig4
expect "--out out/fig5 --preset=fig5 --drops 100"          --preset=fig5 --drops 100
expect "--preset fig3-fixed --out out/fixed"               --preset fig3-fixed --out out/fixed
expect "--out=x --preset fig4"                             --out=x --preset fig4
expect "--out out/my-scene --scene scenes/my-scene.toml"   --scene scenes/my-scene.toml
expect "--resume out/fig4"                                 --resume out/fig4
expect "--help"                                            --help
exit "$bad"
