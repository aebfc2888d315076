# SPDX-License-Identifier: GPL-3.0-or-later
"""asperity: explicit-geometry contacts and restitution statistics of rough particles.

Thin bindings of the C++ library (docs/python.md): asperity.run(scene) runs a scene as the CLI
validate-geometry does and returns report.json as a dict (with per-drop numpy arrays for small
runs); the core pieces (rough spheres, contact queries, the impulse solve, eps_n models, the laws)
work on numpy arrays; asperity.cor_table(...) writes restitution tables for DEM codes.
"""
from ._asperity import *  # noqa: F401,F403
from ._asperity import __version__  # noqa: F401

# Argument errors name the parameter (TypeError for a wrong type, ValueError out of range).
from . import _asperity as _module  # noqa: E402
from ._arguments import wrap_module as _wrap_module  # noqa: E402

_wrap_module(globals(), _module, [_module.RoughSphere, _module.ContactQuery, _module.Restitution, _module.Law])
