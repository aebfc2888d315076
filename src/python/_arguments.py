# SPDX-License-Identifier: GPL-3.0-or-later
"""Argument errors that name the parameter.

pybind11 answers an argument it cannot convert with one TypeError for the whole call
("incompatible function arguments ... Invoked with: ...") that names no parameter, and a negative
number for an unsigned one is the same TypeError. Every public function and method of the module
is wrapped here: when pybind11 refuses a call, the arguments are matched against the signature
pybind11 itself wrote (the first line of the docstring) and the first one that cannot convert is
named -- TypeError for a wrong type, ValueError for an integer out of range. Calls that convert
pay nothing: the diagnosis runs only after pybind11 refused.
"""
import functools
import operator

_UINT_MAX = 2**64 - 1


def _split_top(text):
    """Splits a signature's parameter list at its top-level commas (not inside [], (), quotes)."""
    out, depth, quote, cur = [], 0, None, []
    for ch in text:
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch in "[(":
            depth += 1
        elif ch in "])":
            depth -= 1
        elif ch == "," and depth == 0:
            out.append("".join(cur).strip())
            cur = []
            continue
        cur.append(ch)
    if "".join(cur).strip():
        out.append("".join(cur).strip())
    return out


def _signature(doc):
    """[(name, type)] from pybind11's first docstring line "f(a: int, b: float = 1.0) -> ..."."""
    first = (doc or "").split("\n", 1)[0]
    if "(" not in first or ")" not in first:
        return None
    head = first.split(" -> ")[0]
    inner = head[head.index("(") + 1:head.rindex(")")]
    params = []
    for p in _split_top(inner):
        name, _, rest = p.partition(":")
        params.append((name.strip(), rest.split("=", 1)[0].strip()))
    return params


def _kind(value, typ):
    """None if pybind11 converts `value` to `typ`; else (exception class, reason)."""
    if typ == "int":
        if not hasattr(value, "__index__"):
            return TypeError, "expected an integer"
        v = operator.index(value)
        if v < 0 or v > _UINT_MAX:
            return ValueError, "must be in [0, 2^64 - 1]"
    elif typ == "float":
        if isinstance(value, (str, bytes)) or not (hasattr(value, "__float__") or hasattr(value, "__index__")):
            return TypeError, "expected a number"
    elif typ == "bool":
        if not isinstance(value, bool) and type(value).__name__ != "bool_":
            return TypeError, "expected True or False"
    elif typ == "str":
        if not isinstance(value, str):
            return TypeError, "expected a string"
        try:
            value.encode("utf-8")
        except UnicodeEncodeError:
            return ValueError, "cannot be encoded as UTF-8 (a lone surrogate)"
    return None


def _diagnose(qualname, params, args, kwargs):
    """The error naming the first argument pybind11 cannot convert, or None."""
    bound = list(zip(params, args)) + [((k, t), kwargs[k]) for k, t in params if k in kwargs]
    for (name, typ), value in bound:
        if name == "self":
            continue
        bad = _kind(value, typ)
        if bad:
            cls, why = bad
            shown = repr(value)
            shown = shown if len(shown) <= 60 else shown[:57] + "..."
            return cls(f"{qualname}: {name} = {shown} ({type(value).__name__}): {why}")
    names = {n for n, _ in params}
    for k in kwargs:
        if k not in names:
            return TypeError(f"{qualname}: no parameter named {k!r} (parameters: {', '.join(n for n, _ in params if n != 'self')})")
    return None


def _wrap(fn, qualname):
    params = _signature(getattr(fn, "__doc__", None))
    if params is None:
        return fn

    @functools.wraps(fn)
    def call(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except TypeError as e:
            if "incompatible function arguments" not in str(e):
                raise
            named = _diagnose(qualname, params, args, kwargs)
            if named is None:
                raise
            raise named from None

    return call


def wrap_module(namespace, module, classes):
    """Replaces the module's functions in `namespace` and the classes' methods by wrapped ones."""
    for name in dir(module):
        obj = getattr(module, name)
        if type(obj).__name__ == "builtin_function_or_method":
            namespace[name] = _wrap(obj, name)
    for cls in classes:
        for name, obj in list(vars(cls).items()):
            if type(obj).__name__ == "instancemethod" and (not name.startswith("__") or name == "__call__"):
                setattr(cls, name, _wrap(obj, f"{cls.__name__}.{name}"))
