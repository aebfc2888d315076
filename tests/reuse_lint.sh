#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Licensing as README and LICENSE state it (issue 42 item 5):
# - every source file (C, C++, CUDA, Python, shell, CMake, TOML, LAMMPS input, linker map,
#   suppression list, and any script with a #! line; not the fuzz corpora and regression inputs,
#   which are data) carries an SPDX-License-Identifier line in its first 5 lines;
# - the tree is REUSE-compliant (https://reuse.software): `reuse lint` (Debian's `reuse`,
#   scripts/setup --test) finds a licence and a copyright for every file (its own SPDX line, or
#   .reuse/dep5 for figures, meshes and data) and every licence's text in LICENSES/.
# With --plant, a copy of the tree gains a source file without an SPDX line and one under a licence
# whose text is not in LICENSES/; the check passes only if both are reported.
# Arguments: SOURCE_DIR [--plant]. Exit 77 (skipped) without reuse or outside a git checkout.
set -uo pipefail
src=$1 plant=${2:-}
command -v reuse > /dev/null || { echo "reuse not installed (scripts/setup --test installs it): skipped"; exit 77; }
files=$(git -C "$src" ls-files --cached --others --exclude-standard 2> /dev/null) \
  || { echo "$src: not a git checkout: skipped"; exit 77; }
root=$src
if [ "$plant" = --plant ]; then
  root=$(mktemp -d "${TMPDIR:-/tmp}/asperity-reuse.XXXXXX")
  trap 'rm -rf "$root"' EXIT
  (cd "$src" && while IFS= read -r f; do [ -f "$f" ] && printf '%s\0' "$f"; done <<< "$files" | xargs -0 cp --parents -t "$root")
  printf 'int planted(void) { return 0; }\n' > "$root/src/planted_without_spdx.c"
  printf '// SPDX-License-Identifier: %s\nint other(void) { return 0; }\n' GPL-2.0-only > "$root/src/planted_gpl2.c"
  files=$(printf '%s\nsrc/planted_without_spdx.c\nsrc/planted_gpl2.c\n' "$files")
fi
report=""
while IFS= read -r f; do
  [ -f "$root/$f" ] || continue
  case $f in
    tests/fuzz/corpus/*|tests/fuzz/regressions/*) continue ;;
    *.c|*.cc|*.cpp|*.h|*.hpp|*.cu|*.cuh|*.py|*.pyi|*.sh|*.cmake|*.toml|*.in|*.map|*.supp|CMakeLists.txt|*/CMakeLists.txt) ;;
    *) [ "$(head -c 2 "$root/$f" | tr -d '\0')" = '#!' ] || continue ;;
  esac
  head -n 5 "$root/$f" | grep -q 'SPDX-License-Identifier:' || report+="$f: a source file without an SPDX line in its first 5 lines"$'\n'
done <<< "$files"
lint=$(reuse --root "$root" lint 2>&1); rc=$?
[ "$rc" = 0 ] || report+="$(tail -n 40 <<< "$lint")"$'\n'"reuse lint: not compliant (exit $rc)"$'\n'
if [ "$plant" = --plant ]; then
  if grep -q 'planted_without_spdx.c: a source file without' <<< "$report" && [ "$rc" != 0 ] && grep -q 'GPL-2.0-only' <<< "$lint"; then
    echo "licensing: a source file without an SPDX line and a licence without its text are both reported, as they must be"
    exit 0
  fi
  printf '%s' "$report"; echo "FAIL: the planted files were not both reported"; exit 1
fi
[ -z "$report" ] || { printf '%s' "$report"; echo "FAIL: licensing"; exit 1; }
echo "licensing: every source file has its SPDX line; $(tail -n 1 <<< "$lint")"
