#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Every shell command the docs show runs as written (issue 32): the lines of the ```sh blocks of
# README.md and docs/*.md, and the example lines of scripts/run's header ("#     scripts/run ...").
# Cheaply sized: scripts/run gets the test build's validate-geometry (ASPERITY_VALIDATE_GEOMETRY:
# no setup, no second build) in a scratch copy of the tree's root, with --drops 2000 --no-plots
# appended; `.venv` and `build` name scratch/test-build paths, and pip reuses the test build
# (ASPERITY_BUILD_DIR). Skipped, each for a stated reason: scripts/test (the suite that runs this
# check) and the full CMake builds and installs (ctest install.consumer.* does those). A command
# of any other kind fails the check, so a new page's command cannot go untested.
# Arguments: SOURCE_DIR BUILD_DIR PYTHON.
set -uo pipefail
src=$1 build=$2 python=$3
vg=$build/validate-geometry
work=$(mktemp -d "${TMPDIR:-/tmp}/asperity-docs.XXXXXX")
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/root/scripts" && cp "$src/scripts/run" "$work/root/scripts/run"

commands() {  # FILE:LINE<TAB>command, comments stripped
  for f in "$src"/README.md "$src"/docs/*.md; do
    awk -v f="${f#"$src"/}" '/^```/ { if (inb) inb = 0; else { inb = 1; lang = substr($0, 4) } next }
      inb && (lang == "sh" || lang == "bash") { c = $0; sub(/  +#.*/, "", c); sub(/^ +/, "", c); if (c != "") print f ":" NR "\t" c }' "$f"
  done
  awk '/^#     scripts\/run/ { c = substr($0, 7); sub(/  +#.*/, "", c); print "scripts/run:" NR "\t" c }' "$src/scripts/run"
}

ran=0 skipped=0 bad=0
while IFS=$'\t' read -r where cmd; do
  log=$work/cmd.log
  case $cmd in
    "scripts/test"*) echo "skip $where: $cmd (the suite that runs this check)"; skipped=$((skipped + 1)); continue ;;
    "cmake "*) echo "skip $where: $cmd (a full build/install: ctest install.consumer.* builds and installs)"; skipped=$((skipped + 1)); continue ;;
    "scripts/run"*)
      (cd "$work/root" && eval "ASPERITY_VALIDATE_GEOMETRY=$vg ${cmd} --drops 2000 --no-plots") > "$log" 2>&1 ;;
    "python3 -m venv "*)
      (cd "$work" && eval "${cmd/python3/$python}") > "$log" 2>&1 ;;
    ".venv/bin/"*)
      (cd "$src" && eval "ASPERITY_BUILD_DIR=$build ${cmd//.venv/$work/.venv}") > "$log" 2>&1 ;;
    "PYTHONPATH=build/python python3 "*)
      c=${cmd/PYTHONPATH=build/PYTHONPATH=$build}; (cd "$work" && eval "${c/ python3 / $python }") > "$log" 2>&1 ;;
    *) echo "FAIL $where: '$cmd': no rule to run this kind of command (add one to tests/docs_commands.sh)"; bad=1; continue ;;
  esac
  rc=$?
  ran=$((ran + 1))
  if [ "$rc" -le 1 ] && { [ "$rc" = 0 ] || [[ $cmd == scripts/run* ]]; }; then
    echo "ok   $where: $cmd"
  else
    echo "FAIL $where: $cmd (exit $rc)"; tail -n 8 "$log"; bad=1
  fi
done < <(commands)
# scripts/run's own promise: each run wrote where the docs say.
for d in fig3 fig4 fixed; do
  [ -f "$work/root/out/$d/report.json" ] || { echo "FAIL: no out/$d/report.json after the documented scripts/run commands"; bad=1; }
done
echo "docs commands: $ran ran, $skipped skipped"
[ "$ran" -ge 8 ] || { echo "FAIL: only $ran commands ran (the extraction found too few)"; bad=1; }
exit "$bad"
