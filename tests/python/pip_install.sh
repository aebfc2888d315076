#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# `pip install .` as docs/install.md gives it, offline (--no-index: nothing can be fetched, and
# with build isolation, pip's default, the in-tree backend cmake/pep517_backend.py needs nothing):
# a venv with Debian's site packages (numpy), into a temporary directory; then, from outside the
# source tree, the installed package imports, states the project's version, ships its stubs and
# py.typed, and holds each asperity library once: a regular file named by its SONAME (no copy under
# the fully versioned name).
# Arguments: PYTHON SOURCE_DIR BUILD_DIR (an already built tree, named with --config-settings
# build-dir: the backend reuses it, so this test checks the packaging, not a second build).
set -euo pipefail
python=$1 src=$2 build=$3
work=$(mktemp -d "${TMPDIR:-/tmp}/asperity-pip.XXXXXX")
trap 'rm -rf "$work"' EXIT
"$python" -m venv --system-site-packages "$work/venv"
# setsid: no controlling terminal, as in CI or a notebook; the build's progress must still reach
# pip's own output (issue 42 item 4: it went to /dev/tty only), and its whole output the build log.
setsid -w "$work/venv/bin/pip" install --no-index --config-settings build-dir="$build" "$src" \
  2>&1 < /dev/null | cat > "$work/pip.log" || { cat "$work/pip.log"; exit 1; }
grep -q '^asperity build: cmake --build ' "$work/pip.log" \
  || { cat "$work/pip.log"; echo "FAIL: no build progress in pip's output without a terminal"; exit 1; }
grep -q '^asperity build: cmake --install ' "$build/asperity-pip.log" \
  || { echo "FAIL: $build/asperity-pip.log lacks the build's lines"; exit 1; }
want=$(sed -n 's/^project(asperity VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")
cd "$work"  # not the source tree: the import must find the installed package
PYTHONPATH= "$work/venv/bin/python" - "$want" "$work/venv" <<'PY'
import pathlib, subprocess, sys
import asperity
want, venv = sys.argv[1], pathlib.Path(sys.argv[2]).resolve()
pkg = pathlib.Path(asperity.__file__).resolve().parent
assert venv in pkg.parents, f"imported {pkg}, not the venv's package"
assert asperity.__version__ == want, (asperity.__version__, want)
for f in ("_asperity.pyi", "__init__.pyi", "py.typed"):
    assert (pkg / f).is_file(), f"{f} missing from {pkg}"
libs = sorted(p.name for p in pkg.glob("libasperity_*.so*"))
assert libs, f"no asperity libraries beside the module in {pkg}"
for name in libs:
    p = pkg / name
    assert p.is_file() and not p.is_symlink(), f"{name}: not a regular file"
    soname = subprocess.run(["readelf", "-d", str(p)], capture_output=True, text=True, check=True).stdout
    assert f"[{name}]" in soname, f"{name} is not named by its SONAME: {soname}"
bases = [n.split(".so")[0] for n in libs]
assert len(set(bases)) == len(bases), f"a library twice: {libs}"
assert asperity.eq14_rxy(1000, 1e-3).name, "a binding call"
print(f"pip install: asperity {asperity.__version__} from {pkg} with {', '.join(libs)}")
PY
shown=$("$work/venv/bin/pip" show asperity)
grep -qx "Version: $want" <<<"$shown" || { echo "pip show: $shown"; exit 1; }
