# SPDX-License-Identifier: GPL-3.0-or-later
"""asperity: explicit-geometry contacts and restitution statistics of rough particles.

Bindings of the C++ library (docs/python.md). Every function and class below has its own help,
with the signature in Python's types: help(asperity.run), help(asperity.RoughSphere).

Scenes and runs
    run(scene, ...)           runs a scene as the CLI validate-geometry does; returns report.json
                              as a dict (with per-drop numpy arrays for small runs)
    presets(), preset_text(name), scene_toml(scene)
                              the built-in scenes (fig3, fig4, ...) and the effective TOML of one;
                              a scene is a preset name, a .toml path or a dict in the file's layout
Explicit geometry
    make_rough_sphere(...)    N asperity centres on a sphere -> RoughSphere (.centres, .query())
    ContactQuery              .lowest(d), .contact(q): the lowest asperities, world-frame contacts
    backends(), body_down(q)  the query backends of this build; body-frame down directions
Impacts
    solve_impact(...)         the impulse solve of Eq. 7 over numpy arrays
    pade14(beta), constant(e) eps_n(v) models (Restitution)
Laws (Law: .pdf, .cdf, .mean)
    eq14_rxy, exact_sphere_rxy, eq18_rx, exact_sphere_rx, core_contact_probability,
    eq28_printed, eq28_corrected, eq28_paper_route, eq33_printed, eq33_corrected
Restitution tables for DEM codes
    cor_table(...)            makes one (and writes path.csv + path.json)
    read_cor_table(path)      reads a written table back as numpy arrays

Errors name the parameter: TypeError for a wrong type, ValueError out of range, MemoryError when
the run would not fit (with the CLI's estimate).
"""
import json as _json
import os as _os

import numpy as _np

from ._asperity import *  # noqa: F401,F403
from ._asperity import __version__  # noqa: F401

# Argument errors name the parameter (TypeError for a wrong type, ValueError out of range).
from . import _asperity as _module  # noqa: E402
from ._arguments import wrap_module as _wrap_module  # noqa: E402

_wrap_module(globals(), _module, [_module.RoughSphere, _module.ContactQuery, _module.Restitution, _module.Law])


def read_cor_table(path):
    """read_cor_table(path: str | os.PathLike[str]) -> dict[str, Any]

    A restitution table written by cor_table(path=...) or validate-geometry (outputs.cor_table),
    as cor_table() returns it: the .json header beside the CSV as a dict (when it is there), with
    speeds_m_s, probabilities (and for format 2 spins_rad_s) and quantiles as numpy arrays read
    from the CSV -- quantiles of shape (speeds, probabilities), or for format 2 (spins, speeds,
    probabilities) and omega_band_quantiles (spins, speeds, bands, probabilities). The counts the
    CSV's first line states are checked against its rows. path must end in .csv.
    """
    path = _os.fspath(path)
    if not isinstance(path, str) or not path.endswith(".csv"):
        raise ValueError(f"read_cor_table: path = {path!r}: must end in .csv (a restitution table)")
    with open(path, encoding="utf-8") as f:
        lines = f.read().splitlines()
    if not lines or not lines[0].startswith("# asperity-cor-table "):
        raise ValueError(f"read_cor_table: {path}: line 1 is not '# asperity-cor-table format=...'")
    counts = dict(kv.split("=", 1) for kv in lines[0].split()[2:])
    fmt = int(counts["format"])
    body = [l for l in lines if l and not l.startswith("#")]
    columns = body[0].split(",")
    probabilities = _np.array([float(c[2:]) for c in columns if c.startswith("p=")])
    rows = [l.split(",") for l in body[1:]]
    header = {}
    sidecar = path[:-4] + ".json"
    if _os.path.exists(sidecar):
        with open(sidecar, encoding="utf-8") as f:
            header = _json.load(f)
    out = dict(header)
    out["probabilities"] = probabilities
    P = len(probabilities)
    if fmt == 1:
        speeds, q = [float(r[0]) for r in rows], [[float(x) for x in r[1:]] for r in rows]
        if len(speeds) != int(counts["speeds"]) or any(len(r) != P for r in q):
            raise ValueError(f"read_cor_table: {path}: {len(speeds)} rows, line 1 states speeds={counts['speeds']}")
        out["speeds_m_s"] = _np.array(speeds)
        out["quantiles"] = _np.array(q).reshape(len(speeds), P)
        return out
    K, S, B = int(counts["spins"]), int(counts["speeds"]), int(counts["bands"])
    if len(rows) != K * S * (1 + B):
        raise ValueError(f"read_cor_table: {path}: {len(rows)} rows, line 1 states {K} spins x {S} speeds x (1 + {B} bands)")
    eps = [r for r in rows if r[2] == "eps"]
    bands = [r for r in rows if r[2].startswith("omega_x:")]
    out["spins_rad_s"] = _np.array([float(r[0]) for r in eps[::S]])
    out["speeds_m_s"] = _np.array([float(r[1]) for r in eps[:S]])
    out["quantiles"] = _np.array([[float(x) for x in r[3:]] for r in eps]).reshape(K, S, P)
    out["omega_band_quantiles"] = _np.array([[float(x) for x in r[3:]] for r in bands]).reshape(K, S, B, P)
    return out


__all__ = sorted(
    [name for name in dir(_module) if not name.startswith("_")] + ["read_cor_table", "__version__"])
