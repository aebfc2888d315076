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


def test_signatures_are_python_types():
    """Every signature line (help() shows it first) in Python's types: none of pybind11's internals
    (`handle`, `object` for a parameter, a C++ class name) -- issue 32."""
    import asperity
    bad = re.compile(r"\bhandle\b|: object\b|-> object\b|::|anonymous namespace|std::")
    seen = 0
    for name in asperity.__all__:
        obj = getattr(asperity, name)
        fns = [obj] if callable(obj) and not isinstance(obj, type) else \
              [f for n, f in vars(obj).items() if callable(f) and (not n.startswith("__") or n in ("__call__", "__len__"))] \
              if isinstance(obj, type) else []
        for fn in fns:
            first = (getattr(fn, "__doc__", None) or "").splitlines()[:1]
            assert first and "(" in first[0], f"{name}: no signature line"
            assert not bad.search(first[0]), f"{name}: {first[0]}"
            seen += 1
    assert seen > 25
    # the check has teeth: pybind11's own line for a py::handle parameter is caught
    assert bad.search("run(scene: handle, progress: object = None) -> object")


def test_help_lists_the_api():
    import pydoc
    import asperity
    text = pydoc.render_doc(asperity, renderer=pydoc.plaintext)
    for name in ("run", "make_rough_sphere", "cor_table", "read_cor_table", "RoughSphere", "ContactQuery", "Law"):
        assert name in asperity.__all__, name
        assert f"\n    {name}(" in text or f"class {name}" in text, f"help(asperity) does not list {name}"
    assert "scene: str | os.PathLike[str] | Mapping[str, Any]" in pydoc.render_doc(asperity.run, renderer=pydoc.plaintext)
