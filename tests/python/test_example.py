# SPDX-License-Identifier: GPL-3.0-or-later
"""examples/fig3.py runs and writes its figure."""
import os
import subprocess
import sys
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fig3.py"


def test_fig3_example_writes_png(tmp_path):
    import asperity

    env = dict(os.environ)  # the package imported here, by absolute path (the test runs elsewhere)
    env["PYTHONPATH"] = os.pathsep.join([str(Path(asperity.__file__).resolve().parents[1]), env.get("PYTHONPATH", "")])
    env["MPLBACKEND"] = "Agg"
    r = subprocess.run([sys.executable, str(EXAMPLE)], cwd=tmp_path, capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "fig3.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
