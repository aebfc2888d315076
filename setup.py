# SPDX-License-Identifier: GPL-3.0-or-later
"""Builds the asperity Python package through CMake for `pip install .`.

The version is read from the one place that states it, `project(asperity VERSION ...)` in
CMakeLists.txt. CMake builds the module (build/pip, or the build directory named by
ASPERITY_BUILD_DIR: an existing configured build is reused, e.g. the test suite's build/release)
and installs the component `python-wheel` -- the module, __init__.py, the type stubs, py.typed and
the asperity shared libraries, found through the module's $ORIGIN rpath -- into the wheel.
"""
import os
import re
import subprocess
import sys
from pathlib import Path

from setuptools import Distribution, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def version():
    text = (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    m = re.search(r"project\(asperity\s+VERSION\s+([0-9]+\.[0-9]+\.[0-9]+)", text)
    if not m:
        raise RuntimeError("CMakeLists.txt: no project(asperity VERSION x.y.z)")
    return m.group(1)


def cmake(*args):
    print("setup.py: cmake " + " ".join(args), flush=True)
    subprocess.run(["cmake", *args], check=True)


class CMakePackage(build_ext):
    """build_ext that lets CMake build and lay out the whole package (there is no pure-Python part
    for setuptools to copy: __init__.py and the stubs come through CMake too)."""

    def run(self):
        build = Path(os.environ.get("ASPERITY_BUILD_DIR", ROOT / "build" / "pip")).resolve()
        if not (build / "CMakeCache.txt").exists():
            cmake("-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                  "-DASPERITY_PYTHON=ON", "-DASPERITY_BUILD_TESTS=OFF", "-DASPERITY_BUILD_BENCH=OFF",
                  "-DASPERITY_BUILD_CLI=OFF", f"-DPython3_EXECUTABLE={sys.executable}")
        jobs = str(os.cpu_count() or 1)
        cmake("--build", str(build), "--target", "asperity_python", "-j", jobs)
        cmake("--install", str(build), "--component", "python-wheel", "--prefix", str(Path(self.build_lib).resolve()))


class BinaryDistribution(Distribution):
    """The package holds compiled code: the wheel is tagged for this platform and Python."""

    def has_ext_modules(self):
        return True


setup(version=version(), cmdclass={"build_ext": CMakePackage}, distclass=BinaryDistribution)
