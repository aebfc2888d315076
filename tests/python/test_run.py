# SPDX-License-Identifier: GPL-3.0-or-later
"""asperity.run against the CLI, the arrays, progress, Ctrl-C and bad input."""
import math
import os
import signal
import threading

import numpy as np
import pytest

import asperity
from conftest import cli_report, preset_dict

# Wall-clock fields differ between two runs of the same scene; everything else must be equal.
VOLATILE = {"timings_s", "seconds", "wall_s"}


def volatile(key):
    return key in VOLATILE or key.endswith("seconds") or key.endswith("_s") and "time" in key


def assert_same(cli, py, path="report"):
    """Every field of the CLI's report is in the module's, equal (extra fields are tolerated)."""
    if isinstance(cli, dict):
        assert isinstance(py, dict), path
        for k, v in cli.items():
            if volatile(k):
                continue
            assert k in py, f"{path}.{k} missing from asperity.run"
            assert_same(v, py[k], f"{path}.{k}")
    elif isinstance(cli, list):
        assert isinstance(py, list) and len(py) == len(cli), path
        for i, (a, b) in enumerate(zip(cli, py)):
            assert_same(a, b, f"{path}[{i}]")
    elif isinstance(cli, float) and math.isnan(cli):
        assert isinstance(py, float) and math.isnan(py), path
    else:
        assert cli == py, f"{path}: CLI {cli!r} != module {py!r}"


@pytest.mark.parametrize("mode,spheres", [("sampled", 1), ("explicit", 4)])
def test_run_equals_cli_report(small_scene, mode, spheres):
    scene = small_scene(mode=mode, spheres=spheres, drops=20000)
    cli = cli_report(scene)
    py = asperity.run(scene)
    assert_same(cli, py)
    assert py["scene"] == "small-impact"


def test_dict_scene_equals_file_scene(small_scene):
    import tomllib

    scene = small_scene(drops=5000)
    as_dict = tomllib.loads(scene.read_text())
    a = asperity.run(scene, arrays=False)
    b = asperity.run(as_dict, arrays=False)
    assert_same(a, b)


def test_arrays_are_the_reported_drops(small_scene):
    r = asperity.run(small_scene(drops=20000))
    arr = r["arrays"]
    for name in ("r_x", "r_y", "r_z", "r_xy", "gap", "core", "eps", "omega_x_after", "eps_n", "eps_core"):
        assert isinstance(arr[name], np.ndarray), name
    assert arr["r_x"].shape == (20000,)
    assert arr["core"].dtype == np.bool_
    q = {x["name"]: x for x in r["quantities"]} if isinstance(r.get("quantities"), list) else None
    # The report's sample count and mean of eps are those of the arrays.
    assert r["samples"] == arr["r_x"].size
    if q and "eps" in q:
        mean = q["eps"]["mean"] if not isinstance(q["eps"]["mean"], dict) else q["eps"]["mean"]["value"]
        assert mean == pytest.approx(float(np.mean(arr["eps"])), rel=1e-12)
    # Owned by numpy without a copy of their own: the base is the capsule holding the C++ vector.
    assert arr["eps"].base is not None


def test_arrays_only_when_asked_or_small(small_scene):
    assert "arrays" not in asperity.run(small_scene(drops=5000), arrays=False)
    assert "arrays" not in asperity.run(small_scene(drops=5000), max_array_drops=1000)


def test_progress_is_called(small_scene):
    calls = []
    asperity.run(small_scene(drops=40000), progress=lambda done, total: calls.append((done, total)), arrays=False)
    assert calls, "progress never called"
    assert all(t == 40000 and 0 < d <= t for d, t in calls)


def test_exception_in_progress_propagates(small_scene):
    class Stop(Exception):
        pass

    def progress(done, total):
        raise Stop(f"{done}/{total}")

    with pytest.raises(Stop):
        asperity.run(small_scene(drops=200000, mode="explicit", spheres=2), progress=progress)


def test_ctrl_c_interrupts(small_scene):
    # SIGINT delivered to this process while the run computes (GIL released): KeyboardInterrupt
    # at the next progress step, long before the run would have finished (load-independent: the
    # drops done when it stopped are counted, not seconds).
    scene = small_scene(drops=1_000_000, mode="explicit", spheres=1, count=20_000, backend="brute")
    done = []
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        asperity.run(scene, arrays=False, progress=lambda d, t: done.append(d))
    timer.join()
    assert max(done, default=0) < 500_000


def test_gil_is_released(small_scene):
    # Another Python thread keeps running while asperity.run computes.
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            stop.wait(0.001)

    t = threading.Thread(target=count)
    t.start()
    asperity.run(small_scene(drops=200000), arrays=False)
    stop.set()
    t.join()
    assert len(ticks) > 10


@pytest.mark.parametrize("scene,needle", [
    ("no-such-preset", "no-such-preset"),
    ({"format": 1, "ensemble": {"drops": -5}}, "drops"),
    ({"format": 1, "ensemble": {"mode": "sideways"}}, "sideways"),
    ({"format": 1, "bogus": 1}, "bogus"),
])
def test_bad_scene_raises_value_error_naming_it(scene, needle):
    with pytest.raises(ValueError, match=needle):
        asperity.run(scene)


def test_wrong_types_raise_type_error_naming_them():  # issue 24 item 6; more in test_errors.py
    with pytest.raises(TypeError, match="scene.*42"):
        asperity.run(42)
    with pytest.raises(TypeError, match="progress"):
        asperity.run("fig3", progress=3)


def test_presets():
    assert "fig3" in asperity.presets()
    assert "N = 1e5" in asperity.preset_text("fig3") or "fig3" in asperity.preset_text("fig3")


def bounce_scene(tmp_path, sequences, variants="paper,random-orientation"):
    """fig6 with fewer sequences and no plots (issue 17: bounce runs report progress, Ctrl-C)."""
    s = preset_dict("fig6")
    s["experiment"].update(sequences=sequences, variants=variants)
    s["outputs"].update(plots=False, dir=str(tmp_path / "out-bounce"))
    path = tmp_path / "bounce.toml"
    path.write_text(asperity.scene_toml(s))
    return path


def test_bounce_progress_counts_sequences_of_every_variant(tmp_path):
    calls = []
    asperity.run(bounce_scene(tmp_path, 3000), progress=lambda done, total: calls.append((done, total)))
    assert calls, "progress never called in a bounce run"
    assert all(t == 6000 and 0 < d <= t for d, t in calls)
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)
    assert calls[-1][0] == 6000


def test_ctrl_c_interrupts_a_bounce_run(tmp_path):
    # 10^6 sequences would take minutes; SIGINT after 0.3 s must end the run at the next block of
    # sequences (1024), long before.
    done = []
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        asperity.run(bounce_scene(tmp_path, 1_000_000, "random-orientation"), progress=lambda d, t: done.append(d))
    timer.join()
    assert max(done, default=0) < 500_000
    assert not (tmp_path / "out-bounce").exists()


def test_run_writes_no_file_unless_asked(small_scene, tmp_path, monkeypatch):
    """out=None (the default) leaves the working directory and the scene's outputs.dir untouched;
    out=DIR writes the figures (and their data) there and nowhere else; a scene whose outputs are
    files is refused without out."""
    monkeypatch.chdir(tmp_path)
    scene = preset_dict("fig3")
    scene["ensemble"].update(drops=4000, spheres=4)
    scene["outputs"].update(plots=True, dir=str(tmp_path / "scene-dir"))
    before = sorted(os.listdir(tmp_path))
    scratch = tmp_path / "tmp"  # issue 43: no scratch directory either (TMPDIR stays empty)
    scratch.mkdir()
    monkeypatch.setenv("TMPDIR", str(scratch))
    seen = []  # TMPDIR while the run computes (a scratch directory would be there, then removed)
    r = asperity.run(scene, arrays=False, progress=lambda done, total: seen.append(os.listdir(scratch)))
    assert sorted(os.listdir(tmp_path)) == sorted(before + ["tmp"]) and r["plots"] == []
    assert seen and all(listing == [] for listing in seen), seen
    out = tmp_path / "figs"
    r = asperity.run(scene, arrays=False, out=out)
    assert r["plots"] and all((out / f).is_file() for f in r["plots"] + r["plot_data"])
    assert not (tmp_path / "scene-dir").exists()
    table = preset_dict("fig4")
    table["asperities"]["count"] = 1000
    table["ensemble"].update(drops=2000, mode="sampled")
    table["outputs"]["cor_table"] = {"file": "t.csv"}
    with pytest.raises(ValueError, match="out="):
        asperity.run(table)
    # A mesh body's PLY export is named by its scene key (it said "body.export_ply", a key no reader has).
    ellipsoid = os.path.join(os.path.dirname(__file__), "..", "..", "scenes", "ellipsoid.toml")
    with pytest.raises(ValueError, match=r"outputs\.export_ply writes a file"):
        asperity.run(ellipsoid)
    with pytest.raises(TypeError, match="out"):
        asperity.run(scene, out=3)


def test_numpy_integers_big_seeds_and_bytes_paths_are_accepted(tmp_path, monkeypatch):
    """Issue 33 item 8: what Python users pass is taken as meant -- numpy integers (numpy.uint64
    included) in a scene dict, a seed up to 2**64 - 1 (2**63 was refused as a float), and an
    os.PathLike whose __fspath__ returns bytes (it wrote into a directory named "b'bp'")."""
    for seed in (2**63, 2**64 - 1, np.uint64(2**64 - 1)):
        text = asperity.scene_toml({"ensemble": {"seed": seed}})
        assert f'seed = "{int(seed)}"' in text, text
    assert "seed = 7\n" in asperity.scene_toml({"ensemble": {"seed": np.int32(7)}})
    assert "count = 500\n" in asperity.scene_toml({"asperities": {"count": np.uint64(500)}})
    with pytest.raises(ValueError, match="seed"):
        asperity.scene_toml({"ensemble": {"seed": 2**64}})

    class BytesPath:
        def __init__(self, b):
            self.b = b

        def __fspath__(self):
            return self.b

    scene_file = tmp_path / "s.toml"
    scene_file.write_text(asperity.preset_text("fig4"))
    assert asperity.scene_toml(BytesPath(os.fsencode(scene_file))) == asperity.scene_toml(str(scene_file))
    monkeypatch.chdir(tmp_path)
    scene = preset_dict("fig3")
    scene["ensemble"].update(drops=4000, spheres=4)
    scene["outputs"].update(plots=True)
    r = asperity.run(scene, arrays=False, out=BytesPath(b"bp"))
    assert r["plots"] and (tmp_path / "bp").is_dir() and not (tmp_path / "b'bp'").exists()
