#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The repository's metadata as LICENSE and the CHANGELOG's header promise it (issue 32):
# - every file whose SPDX line says MIT is named in LICENSE (the list of exceptions to the GPL) and
#   in .reuse/dep5's MIT stanza;
# - every page of docs/ carries an SPDX line; CITATION.cff cites the software, the paper under references;
# - every version section of CHANGELOG.md has its headings in Keep a Changelog's order
#   (Added, Changed, Deprecated, Removed, Fixed, Security), each at most once, and no other.
# Argument: the tree to check. tests/metadata/defective/ breaks each rule once (ctest WILL_FAIL).
set -uo pipefail
root=${1:?usage: metadata.sh ROOT}
cd "$root" || exit 2
bad=0
fail() { echo "metadata: $*"; bad=1; }

# REUSE-IgnoreStart (the pattern below is not this file's licence)
while IFS= read -r f; do
  f=${f#./}
  grep -qF "$f" LICENSE || fail "$f is MIT (SPDX line) but LICENSE does not name it"
  grep -qF "$f" .reuse/dep5 || fail "$f is MIT (SPDX line) but .reuse/dep5's MIT stanza does not name it"
done < <(grep -rlI --exclude-dir=build --exclude-dir=out --exclude-dir=.git --exclude-dir=metadata \
           -E '^.{0,4}SPDX-License-Identifier: MIT( |$)' . | sort)
# REUSE-IgnoreEnd

# CITATION.cff cites the software (GitHub's "Cite this repository" uses preferred-citation when
# there is one); the paper goes under references (issue 42 item 5).
if [ -f CITATION.cff ]; then
  grep -qx 'type: software' CITATION.cff || fail "CITATION.cff: not 'type: software'"
  ! grep -q '^preferred-citation:' CITATION.cff || fail "CITATION.cff: preferred-citation makes GitHub cite it instead of the software"
  grep -q '^references:' CITATION.cff || fail "CITATION.cff: the paper belongs under references"
fi

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
