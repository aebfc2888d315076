# SPDX-License-Identifier: GPL-3.0-or-later
"""The in-tree build backend (cmake/pep517_backend.py, issue 42 item 4): its Python floor is
pyproject.toml's requires-python, so before 3.11 (no tomllib) it reads the [project] table itself,
and the result must be tomllib's; the backend and the package's Python files parse at the floor."""
import ast
import importlib.util
import re
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def backend():
    spec = importlib.util.spec_from_file_location("asperity_pep517_backend", ROOT / "cmake" / "pep517_backend.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def floor():
    m = re.fullmatch(r">=\s*3\.(\d+)", tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["requires-python"])
    assert m, "requires-python is not of the form >=3.N"
    return (3, int(m.group(1)))


def test_fallback_reader_equals_tomllib():
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    assert backend()._project_table(text) == tomllib.loads(text)["project"]


def test_fallback_reader_forms():
    text = ('[build-system]\nrequires = ["x"]\n[project]\nname = "a#b" # c\nlist = [\n  "p, q",  # note\n  "]",\n]\n'
            'license = { text = "MIT" }\nauthors = [{ name = "n", email = "e@x" }]\n[tool.x]\nname = "other"\n')
    assert backend()._project_table(text) == tomllib.loads(text)["project"]
    with pytest.raises(RuntimeError, match="pyproject.toml:2"):
        backend()._project_table("[project]\nflag = true\n")


def test_without_tomllib(monkeypatch):
    monkeypatch.setitem(sys.modules, "tomllib", None)  # as on Python < 3.11: import tomllib fails
    b = backend()
    assert b._project()["requires-python"] == tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["requires-python"]
    assert "Requires-Python: >=3." in b._metadata()


@pytest.mark.parametrize("path", ["cmake/pep517_backend.py", "src/python/__init__.py", "src/python/_arguments.py"])
def test_parses_at_the_floor(path):
    ast.parse((ROOT / path).read_text(encoding="utf-8"), filename=path, feature_version=floor())
