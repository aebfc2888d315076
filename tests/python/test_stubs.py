# SPDX-License-Identifier: GPL-3.0-or-later
"""The type stubs (src/python/_asperity.pyi) against the compiled module, both ways: every public
name has a stub and every stub names something real; every function's parameters (as pybind11's
signature line states them) are the stub's, in order. A binding added without its stub fails here."""
import ast
import re
from pathlib import Path

import asperity._asperity as mod

STUB = Path(asperity_file := mod.__file__).parent / "_asperity.pyi"


def stub_tree():
    return ast.parse(STUB.read_text())


def public(names):
    return {n for n in names if not n.startswith("_") or n == "__version__"}


def stub_names(tree):
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return names


def test_every_binding_has_a_stub_and_back():
    tree = stub_tree()
    aliases = {"ArrayLike", "FloatArray", "Scene", "Progress"}  # the stub's own type aliases
    compiled = public(dir(mod))
    stubs = stub_names(tree)
    assert compiled - stubs == set(), "bindings without a stub"
    assert stubs - compiled == set(), "stubs of nothing"
    assert not aliases & compiled


def pybind_parameters(fn):
    first = (fn.__doc__ or "").splitlines()[0]
    m = re.match(r"\w+\((.*)\) ->", first)
    assert m, f"no signature line in {fn.__name__}.__doc__: {first!r}"
    return [p for p in re.findall(r"(?:^|, )(\w+):", m.group(1)) if p != "self"]


def stub_parameters(node):
    return [a.arg for a in node.args.args if a.arg != "self"]


def test_parameters_match():
    for node in stub_tree().body:
        if isinstance(node, ast.FunctionDef):
            assert pybind_parameters(getattr(mod, node.name)) == stub_parameters(node), node.name
        if isinstance(node, ast.ClassDef):
            cls = getattr(mod, node.name)
            for f in node.body:
                if isinstance(f, ast.FunctionDef) and not any(
                        isinstance(d, ast.Name) and d.id in ("property", "overload") for d in f.decorator_list):
                    assert pybind_parameters(getattr(cls, f.name)) == stub_parameters(f), f"{node.name}.{f.name}"


def test_a_wrong_stub_is_caught():
    # The comparison has teeth: a stub with a renamed parameter does not match.
    fn = next(n for n in stub_tree().body if isinstance(n, ast.FunctionDef) and n.name == "eq14_rxy")
    fn.args.args[0].arg = "n"
    assert pybind_parameters(mod.eq14_rxy) != stub_parameters(fn)
