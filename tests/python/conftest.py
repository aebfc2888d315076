# SPDX-License-Identifier: GPL-3.0-or-later
"""Shared fixtures: small scenes and the CLI's report for the same scene and seed.

Run by ctest (python.pytest) with PYTHONPATH at build/python and ASPERITY_CLI at validate-geometry;
by hand: PYTHONPATH=build/python ASPERITY_CLI=build/validate-geometry python3 -m pytest tests/python
Scenes are the presets with smaller numbers (so renamed modes or new keys follow the presets).
"""
import json
import os
import subprocess
import tomllib
from pathlib import Path

import pytest

import asperity


def preset_dict(name):
    return tomllib.loads(asperity.preset_text(name))


@pytest.fixture
def small_scene(tmp_path):
    """Writes a small Fig. 4 scene file (impacts, N = 1000, no plots); returns its path.

    mode "sampled" draws from the exact law (no geometry), "explicit" builds K explicit spheres x rotations."""

    def make(mode="sampled", drops=20000, spheres=1, seed=7, name="scene.toml", count=1000, backend="auto"):
        s = preset_dict("fig4")
        s["name"] = "small-impact"
        s["asperities"]["count"] = count
        e = s["ensemble"]
        if mode == "fixed":
            e["mode"] = preset_dict("fig3-fixed")["ensemble"]["mode"]
        e.update(drops=drops, spheres=spheres, seed=seed, backend=backend)
        s["outputs"].update(plots=False, dir=str(tmp_path / ("out-" + name)))
        path = tmp_path / name
        path.write_text(asperity.scene_toml(s))
        return path

    return make


def cli_report(scene_path, *extra):
    """report.json of validate-geometry for the scene (skips the test without the CLI)."""
    cli = os.environ.get("ASPERITY_CLI")
    if not cli or not os.path.exists(cli):
        pytest.skip("ASPERITY_CLI (validate-geometry) not set")
    outputs = tomllib.loads(scene_path.read_text())["outputs"]
    r = subprocess.run([cli, "--scene", str(scene_path), "--quiet", *extra], capture_output=True, text=True)
    assert r.returncode in (0, 1), r.stderr
    return json.loads((Path(outputs["dir"]) / outputs["report"]).read_text())
