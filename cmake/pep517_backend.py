# SPDX-License-Identifier: GPL-3.0-or-later
"""asperity's PEP 517 build backend: `pip install .` builds the Python package through CMake.

In-tree (pyproject.toml: `backend-path = ["cmake"]`) and standard library only, so pip fetches
no build dependency: `pip install .` works offline, build isolation or not. CMake and the compiler
come from Debian (scripts/setup --python).

- Build directory: `build/pip` in the source tree, or an existing one named by the config setting
  `build-dir` (`pip install -C build-dir=build/release .`, pip >= 23.1; `--config-settings` before)
  or the environment variable ASPERITY_BUILD_DIR. A configured directory is reused as it is
  (ninja then rebuilds only what changed); only the module's target and the libraries it links
  are built.
- Progress: pip shows a build's output only with `-v`, so the compiler's progress lines (ninja's
  `[done/total]`) and this backend's own lines also go to the terminal (/dev/tty) when there is
  one, and otherwise (a CI job, a notebook's `!pip install .`, `pip install . 2>&1 | tee log`,
  `>> log`) to pip's own standard error (the parent process's, when it is a pipe, a device or a
  file opened for appending), which pip does not capture. Every line of the
  build also goes to `asperity-pip.log` in the build directory.
- Python: the floor is pyproject.toml's `requires-python` (3.9). pyproject.toml is read with
  tomllib where there is one (3.11+); before 3.11 with a reader for the [project] table's simple
  forms (strings, arrays, inline tables), which tests/python/test_pep517_backend.py checks
  against tomllib.
- The wheel: CMake installs the component `python-wheel` (module, __init__.py, the stubs,
  py.typed and the asperity shared libraries) into a staging directory. A wheel cannot hold a
  symbolic link, and the loader asks for each library by its SONAME (libasperity_core.so.1), so
  each library is stored once, under its SONAME: the link's name gets the real file's bytes and
  the fully versioned file (libasperity_core.so.1.0.0) is left out.
"""
import base64
import hashlib
import io
import os
import re
import shutil
import stat
import subprocess
import sys
import sysconfig
import tarfile
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NAME = "asperity"


def _version():
    text = (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    m = re.search(r"project\(asperity\s+VERSION\s+([0-9]+\.[0-9]+\.[0-9]+)", text)
    if not m:
        raise RuntimeError("CMakeLists.txt: no project(asperity VERSION x.y.z)")
    return m.group(1)


def _project_table(text):
    """The [project] table of pyproject.toml without tomllib (Python < 3.11): `key = value` lines
    whose values are basic strings, arrays and inline tables of them (a value may span lines until
    its brackets close). Anything else raises, naming the line."""
    import ast
    out, inside, pending, start = {}, False, "", 0
    for no, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if not pending:
            if stripped.startswith("["):
                inside = stripped == "[project]"
                continue
            if not inside or not stripped or stripped.startswith("#"):
                continue
            start = no
        pending += line + "\n"
        body = re.sub(r'"(?:[^"\\]|\\.)*"', '""', pending)  # brackets inside strings do not count
        body = re.sub(r"#.*", "", body)
        if body.count("[") + body.count("{") > body.count("]") + body.count("}"):
            continue
        key, sep, value = pending.partition("=")
        pending = ""
        key = key.strip().strip('"')
        if not sep or not re.fullmatch(r"[A-Za-z0-9_-]+", key):
            raise RuntimeError(f"pyproject.toml:{start}: not a `key = value` line this reader knows")
        value = "\n".join(re.sub(r'^((?:[^"#]|"(?:[^"\\]|\\.)*")*)#.*$', r"\1", v) for v in value.splitlines())
        value = re.sub(r'([{,]\s*)([A-Za-z0-9_-]+)\s*=', r'\1"\2":', value)  # inline tables: k = v -> "k": v
        try:
            out[key] = ast.literal_eval(value.strip())
        except (ValueError, SyntaxError) as e:
            raise RuntimeError(f"pyproject.toml:{start}: {key}: a value this reader cannot read ({e})") from e
    return out


def _project():
    with open(ROOT / "pyproject.toml", "rb") as f:
        data = f.read()
    try:
        import tomllib
    except ModuleNotFoundError:  # Python < 3.11: pyproject.toml's requires-python is 3.9
        return _project_table(data.decode("utf-8"))
    return tomllib.loads(data.decode("utf-8"))["project"]


def _metadata():
    p = _project()
    lines = ["Metadata-Version: 2.1", f"Name: {p['name']}", f"Version: {_version()}",
             f"Summary: {p['description']}", f"Requires-Python: {p['requires-python']}",
             f"License: {p['license']['text']}"]
    lines += [f"Author: {a['name']}" for a in p.get("authors", [])]
    lines += [f"Requires-Dist: {d}" for d in p.get("dependencies", [])]
    lines += [f"Classifier: {c}" for c in p.get("classifiers", [])]
    lines.append("Description-Content-Type: text/markdown")
    readme = (ROOT / p["readme"]).read_text(encoding="utf-8")
    return "\n".join(lines) + "\n\n" + readme


def _tag():
    impl = sys.implementation.name
    if impl != "cpython":
        raise RuntimeError(f"asperity's module is built for CPython, not {impl}")
    py = f"cp{sys.version_info.major}{sys.version_info.minor}"
    plat = re.sub(r"[-.]", "_", sysconfig.get_platform())
    return f"{py}-{py}-{plat}"


def _dist_info():
    return f"{NAME}-{_version()}.dist-info"


def _say(msg):
    print(f"asperity build: {msg}", file=sys.stderr, flush=True)


def _same_file(a, b):
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


def _progress_sink():
    """Where the progress lines go, as pip swallows this process's output: the user's terminal,
    or, without one, pip's own standard error (the parent's; Linux /proc), unless that is where
    this process's output goes anyway. None when neither can be opened."""
    try:
        return open("/dev/tty", "w", encoding="utf-8", errors="replace")
    except OSError:
        pass
    ppid = os.getppid()
    parent = f"/proc/{ppid}/fd/2"
    try:
        st = os.stat(parent)
        if _same_file(st, os.fstat(sys.stdout.fileno())):
            return None
        if stat.S_ISREG(st.st_mode):
            # A file opened without O_APPEND (`> log`): pip writes at its own offset, over lines
            # added at the end; only an appending one (`>> log`) can be shared.
            with open(f"/proc/{ppid}/fdinfo/2", encoding="ascii") as info:
                flags = next((int(line.split()[1], 8) for line in info if line.startswith("flags:")), 0)
            if not flags & os.O_APPEND:
                return None
        elif not (stat.S_ISFIFO(st.st_mode) or stat.S_ISCHR(st.st_mode)):
            return None
        return open(parent, "a", encoding="utf-8", errors="replace")
    except (OSError, ValueError, io.UnsupportedOperation):
        return None


class _Output:
    """The build's output: every line to this process's stdout (pip -v) and the build directory's
    asperity-pip.log; the progress lines also to the sink."""

    def __init__(self, log_path):
        self.sink = _progress_sink()
        self.log = None
        if log_path is not None:
            try:
                log_path.parent.mkdir(parents=True, exist_ok=True)
                self.log = open(log_path, "a", encoding="utf-8", errors="replace")
            except OSError:
                self.log = None

    def say(self, msg):
        line = f"asperity build: {msg}\n"
        sys.stderr.write(line)
        sys.stderr.flush()
        self._write(line, True)

    def line(self, out):
        sys.stdout.write(out)
        sys.stdout.flush()
        self._write(out, bool(re.match(r"\[\d+/\d+\]|\[ *\d+%\]|ninja: ", out)))

    def _write(self, text, progress):
        for f in ((self.log, self.sink) if progress else (self.log,)):
            if f is None:
                continue
            try:
                f.write(text)
                f.flush()
            except OSError:
                pass

    def close(self):
        for f in (self.log, self.sink):
            if f is not None:
                try:
                    f.close()
                except OSError:
                    pass


def _run(args, out):
    line = "cmake " + " ".join(str(a) for a in args)
    out.say(line)
    proc = subprocess.Popen(["cmake", *map(str, args)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, errors="replace")
    for text in proc.stdout:
        out.line(text)
    if proc.wait() != 0:
        raise RuntimeError(f"{line} failed (exit {proc.returncode}); its output is above (pip install -v shows it)")


def _build_dir(config_settings):
    named = (config_settings or {}).get("build-dir") or os.environ.get("ASPERITY_BUILD_DIR")
    if named:
        d = Path(named)
        return (d if d.is_absolute() else ROOT / d).resolve(), True
    return ROOT / "build" / "pip", False


def _build(staging, config_settings):
    build, named = _build_dir(config_settings)
    if named and not (build / "CMakeCache.txt").exists():
        raise RuntimeError(f"{build}: not a configured CMake build directory (no CMakeCache.txt)")
    out = _Output(build / "asperity-pip.log")
    try:
        out.say(f"the whole build's output: {build / 'asperity-pip.log'}")
        if not (build / "CMakeCache.txt").exists():
            out.say("first build of the Python module in build/pip: ~60 files, a few minutes on 2 cores; "
                    "later installs rebuild only what changed")
            gen = ["-G", "Ninja"] if shutil.which("ninja") and not os.environ.get("CMAKE_GENERATOR") else []
            _run(["-S", ROOT, "-B", build, *gen, "-DCMAKE_BUILD_TYPE=Release", "-DASPERITY_PYTHON=ON",
                  "-DASPERITY_BUILD_TESTS=OFF", "-DASPERITY_BUILD_BENCH=OFF", "-DASPERITY_BUILD_CLI=OFF",
                  "-DASPERITY_WITH_MPI=OFF", f"-DPython3_EXECUTABLE={sys.executable}"], out)
        else:
            out.say(f"reusing the configured build {build}")
        jobs = (config_settings or {}).get("jobs") or str(os.cpu_count() or 1)
        _run(["--build", build, "--target", "asperity_python", "-j", jobs], out)
        _run(["--install", build, "--component", "python-wheel", "--prefix", staging], out)
    finally:
        out.close()
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    if not (Path(staging) / NAME / f"_asperity{suffix}").exists():
        found = sorted(p.name for p in (Path(staging) / NAME).glob("_asperity*"))
        raise RuntimeError(f"{build} built {found}, not _asperity{suffix} for {sys.executable}: "
                           "name a build configured with -DPython3_EXECUTABLE for this Python")


def _package_files(staging):
    """(name in the wheel, path of the bytes): each symbolic link's name carries its target's
    bytes and the target itself is left out (one real copy of every shared library)."""
    pkg = Path(staging) / NAME
    files, replaced = {}, set()
    for p in sorted(pkg.iterdir()):
        if p.is_symlink():
            target = p.resolve()
            if target.parent != pkg.resolve():
                raise RuntimeError(f"{p} links outside the package ({target})")
            files[f"{NAME}/{p.name}"] = target
            replaced.add(target.name)
        elif p.is_file():
            files[f"{NAME}/{p.name}"] = p
        else:
            raise RuntimeError(f"{p}: not a file (the package is flat)")
    for name in replaced:
        files.pop(f"{NAME}/{name}", None)
    return files


def _record_line(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def _write_wheel(path, files, dist_info):
    record = []
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as z:
        def add(name, data, mode=0o644):
            info = zipfile.ZipInfo(name, date_time=(2026, 1, 1, 0, 0, 0))
            info.external_attr = (0o100000 | mode) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, data)
            record.append(_record_line(name, data))
        for name, src in sorted(files.items()):
            add(name, src.read_bytes(), 0o755 if ".so" in name else 0o644)
        add(f"{dist_info}/METADATA", _metadata().encode())
        add(f"{dist_info}/WHEEL", (f"Wheel-Version: 1.0\nGenerator: asperity in-tree backend\n"
                                   f"Root-Is-Purelib: false\nTag: {_tag()}\n").encode())
        add(f"{dist_info}/LICENSE", (ROOT / "LICENSE").read_bytes())
        record.append(f"{dist_info}/RECORD,,")
        z.writestr(zipfile.ZipInfo(f"{dist_info}/RECORD", date_time=(2026, 1, 1, 0, 0, 0)),
                   "\n".join(record) + "\n")


# ---- PEP 517 hooks ----

def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    d = Path(metadata_directory) / _dist_info()
    d.mkdir(parents=True, exist_ok=True)
    (d / "METADATA").write_text(_metadata(), encoding="utf-8")
    return d.name


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    with tempfile.TemporaryDirectory(prefix="asperity-wheel-") as staging:
        _build(staging, config_settings)
        name = f"{NAME}-{_version()}-{_tag()}.whl"
        _write_wheel(Path(wheel_directory) / name, _package_files(staging), _dist_info())
    _say(f"wrote {name}")
    return name


def build_sdist(sdist_directory, config_settings=None):
    """The tracked files (git ls-files when this is a git checkout; otherwise every file outside
    build/ and out/) under asperity-VERSION/."""
    base = f"{NAME}-{_version()}"
    try:
        listed = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z"], check=True,
                                capture_output=True).stdout.decode().split("\0")
        names = [n for n in listed if n and (ROOT / n).is_file()]
    except (OSError, subprocess.CalledProcessError):
        names = [str(p.relative_to(ROOT)) for p in ROOT.rglob("*")
                 if p.is_file() and p.relative_to(ROOT).parts[0] not in ("build", "out", ".git")]
    with tarfile.open(Path(sdist_directory) / f"{base}.tar.gz", "w:gz", format=tarfile.PAX_FORMAT) as t:
        for n in sorted(names):
            t.add(ROOT / n, arcname=f"{base}/{n}", recursive=False)
        info = tarfile.TarInfo(f"{base}/PKG-INFO")
        data = _metadata().encode()
        info.size = len(data)
        t.addfile(info, io.BytesIO(data))
    return f"{base}.tar.gz"
