#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The repository's metadata as LICENSE and the CHANGELOG's header promise it (issue 32):
# - every file whose SPDX line says MIT is named in LICENSE (the list of exceptions to the GPL);
# - every page of docs/ carries an SPDX line;
# - every version section of CHANGELOG.md has its headings in Keep a Changelog's order
#   (Added, Changed, Deprecated, Removed, Fixed, Security), each at most once, and no other.
# Argument: the tree to check. tests/metadata/defective/ breaks each rule once (ctest WILL_FAIL).
set -uo pipefail
root=${1:?usage: metadata.sh ROOT}
cd "$root" || exit 2
bad=0
fail() { echo "metadata: $*"; bad=1; }

while IFS= read -r f; do
  f=${f#./}
  grep -qF "$f" LICENSE || fail "$f is MIT (SPDX line) but LICENSE does not name it"
done < <(grep -rlI --exclude-dir=build --exclude-dir=out --exclude-dir=.git --exclude-dir=metadata \
           -E '^.{0,4}SPDX-License-Identifier: MIT( |$)' . | sort)

for f in docs/*.md; do
  head -n 3 "$f" | grep -q 'SPDX-License-Identifier:' || fail "$f has no SPDX line in its first 3 lines"
done

order=(Added Changed Deprecated Removed Fixed Security)
rank() { local i; for i in "${!order[@]}"; do [ "${order[$i]}" = "$1" ] && { echo "$i"; return; }; done; echo -1; }
version="" last=-1
while IFS= read -r line; do
  case $line in
    "## "*) version=${line#\#\# }; last=-1 ;;
    "### "*)
      h=${line#\#\#\# } r=$(rank "$h")
      if [ "$r" -lt 0 ]; then fail "CHANGELOG.md $version: heading '$h' is not a Keep a Changelog heading"
      elif [ "$r" -le "$last" ]; then fail "CHANGELOG.md $version: '$h' out of order (or twice): ${order[*]}"
      fi
      last=$r ;;
  esac
done < CHANGELOG.md
[ "$bad" = 0 ] && echo "metadata: LICENSE names every MIT file, every docs page has SPDX, CHANGELOG in order"
exit "$bad"
