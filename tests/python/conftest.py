"""Shared fixtures: small scenes and the CLI's report for the same scene and seed.

Run by ctest (python.pytest) with PYTHONPATH at build/python and ASPERITY_CLI at validate-geometry;
by hand: PYTHONPATH=build/python ASPERITY_CLI=build/validate-geometry python3 -m pytest tests/python
"""
import json
import os
import subprocess
from pathlib import Path

import pytest

# A small Fig. 4: N = 1000, 20000 fresh drops with impacts; seconds.
SMALL_IMPACT = """format = 1
name = "small-impact"
[body]
kind = "sphere"
radius = 3e-3
[material]
density = 7850.0
eps_t = 1.0
restitution = {{ model = "viscoelastic", beta = 0.0467 }}
[asperities]
count = {count}
radius = {{ distribution = "fixed", value = 6.5e-7 }}
[ensemble]
mode = "{mode}"
drops = {drops}
spheres = {spheres}
seed = {seed}
backend = "{backend}"
threads = 0
[experiment]
kind = "impact"
V = [0.0, 0.0, -1.3]
Omega = [0.2, 0.0, 0.0]
[outputs]
contact = true
restitution = true
plots = false
alpha = 0.01
dir = "{out}"
report = "report.json"
"""


@pytest.fixture
def small_scene(tmp_path):
    """Writes a small impact scene file; returns a function of (mode, drops, spheres, seed)."""

    def make(mode="fresh", drops=20000, spheres=1, seed=7, name="scene.toml", count=1000, backend="auto"):
        out = tmp_path / ("out-" + name)
        path = tmp_path / name
        path.write_text(SMALL_IMPACT.format(mode=mode, drops=drops, spheres=spheres, seed=seed, out=out, count=count, backend=backend))
        return path

    return make


def cli_report(scene_path, *extra):
    """report.json of validate-geometry for the scene (skips the test without the CLI)."""
    cli = os.environ.get("ASPERITY_CLI")
    if not cli or not os.path.exists(cli):
        pytest.skip("ASPERITY_CLI (validate-geometry) not set")
    import tomllib

    outputs = tomllib.loads(scene_path.read_text())["outputs"]
    r = subprocess.run([cli, "--scene", str(scene_path), "--quiet", *extra], capture_output=True, text=True)
    assert r.returncode in (0, 1), r.stderr
    return json.loads((Path(outputs["dir"]) / outputs["report"]).read_text())
