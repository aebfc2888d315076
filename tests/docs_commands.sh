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
# Code blocks (issue 42 item 1): every ```python block runs as a program (PYTHONPATH at the test
# build's package, MPLBACKEND=Agg, in a scratch directory where out/fig3 holds a small Fig. 3 run
# with its figures and CSVs, as the replot example reads), every ```cpp block is compiled against the
# test build (${CXX:-c++}, the asperity libraries) and run; each must exit 0. A block that is not a
# complete program is marked by the line before its fence, `<!-- fragment of PATH -->` (PATH in the
# tree, a .py or .cpp program): its every non-blank line must appear in PATH, and PATH runs instead.
# Blocks of other kinds (toml, cmake, c) are listed as not run.
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
# ---- code blocks: python and cpp
blocks=$work/blocks
mkdir -p "$blocks" "$work/code/out"
for f in "$src"/README.md "$src"/docs/*.md; do  # each block to blocks/PAGE-N.LANG, listed as "page:line|lang|file|fragment-of"
  awk -v f="${f#"$src"/}" -v dir="$blocks" '
    /^```/ { if (inb) { inb = 0; close(out); next }
             inb = 1; lang = substr($0, 4); n = ++count; out = dir "/" FILENAME_ID "-" n "." lang
             frag = ""; if (match(prev, /^<!-- fragment of [^ ]+ -->$/)) { frag = substr(prev, 18, RLENGTH - 21) }
             print f ":" NR "|" lang "|" out "|" frag; printf "" > out; next }
    inb { print > out }
    { prev = $0 }' FILENAME_ID="$(basename "$f" .md)" "$f"
done > "$work/blocks.tsv"
# The replot example's input: a small Fig. 3 run with its figures (each plot's CSV beside it).
"$vg" --preset fig3 --drops 2000 --spheres 2 --out "$work/code/out/fig3" -q > "$work/fig3.log" 2>&1 \
  || { echo "FAIL: the Fig. 3 run the replot example reads"; cat "$work/fig3.log"; bad=1; }
run_python() { (cd "$work/code" && PYTHONPATH=$build/python MPLBACKEND=Agg "$python" "$1") > "$work/block.log" 2>&1; }
run_cpp() {
  "${CXX:-c++}" -std=c++20 -I"$src/include" -I"$build/generated/include" -isystem /usr/include/eigen3 "$1" \
    -L"$build" -lasperity_app -lasperity_experiments -lasperity_core -Wl,-rpath,"$build" -o "$work/block.bin" \
    > "$work/block.log" 2>&1 && (cd "$work/code" && "$work/block.bin") >> "$work/block.log" 2>&1
}
code=0 notrun=0
while IFS='|' read -r where lang file frag; do
  case $lang in
    python|cpp) ;;
    sh|bash) continue ;;
    *) echo "not run $where: a \`\`\`${lang:-(plain)} block"; notrun=$((notrun + 1)); continue ;;
  esac
  what=$file
  if [ -n "$frag" ]; then
    [ -f "$src/$frag" ] || { echo "FAIL $where: fragment of $frag, which does not exist"; bad=1; continue; }
    missing=$(while IFS= read -r l; do t=$(sed 's/^ *//; s/ *$//' <<<"$l"); [ -z "$t" ] && continue
              grep -qF -- "$t" "$src/$frag" || printf '  %s\n' "$t"; done < "$file")
    [ -z "$missing" ] || { echo "FAIL $where: lines not in $frag:"; echo "$missing"; bad=1; continue; }
    what=$src/$frag; lang=${frag##*.}; [ "$lang" = py ] && lang=python
  fi
  if "run_$lang" "$what"; then
    echo "ok   $where: \`\`\`${lang} block${frag:+ (fragment of $frag)}"; code=$((code + 1))
  else
    echo "FAIL $where: \`\`\`${lang} block${frag:+ (fragment of $frag)}"; tail -n 12 "$work/block.log"; bad=1
  fi
done < "$work/blocks.tsv"
echo "docs code blocks: $code ran, $notrun of other kinds not run"
[ "$code" -ge 4 ] || { echo "FAIL: only $code python/cpp blocks ran (the extraction found too few)"; bad=1; }

# scripts/run's own promise: each run wrote where the docs say.
for d in fig3 fig4 fixed; do
  [ -f "$work/root/out/$d/report.json" ] || { echo "FAIL: no out/$d/report.json after the documented scripts/run commands"; bad=1; }
done
echo "docs commands: $ran ran, $skipped skipped"
[ "$ran" -ge 8 ] || { echo "FAIL: only $ran commands ran (the extraction found too few)"; bad=1; }
exit "$bad"
