# SPDX-License-Identifier: GPL-3.0-or-later
"""Restitution tables: the Python API, the files, and the C header reading them."""
import json
import os
import subprocess

import numpy as np
import pytest

import asperity


def small(**kw):
    args = dict(scene="fig4", speeds=[0.5, 1.0, 2.0], probabilities=11, drops=5000)
    args.update(kw)
    return asperity.cor_table(**args)


def test_table_quantiles_and_header(tmp_path):
    path = tmp_path / "steel.csv"
    t = small(path=path)
    assert t["quantiles"].shape == (3, 11)
    assert np.all(np.diff(t["quantiles"], axis=1) >= 0)
    np.testing.assert_allclose(t["probabilities"], np.linspace(0, 1, 11), rtol=0, atol=1e-15)
    np.testing.assert_array_equal(t["speeds_m_s"], [0.5, 1.0, 2.0])
    assert "p" not in t and "speeds" not in t  # one name per field: the .json header's
    assert t["format_version"] == 1 and t["body"]["N"] == 100000
    assert len(t["rows"]) == 3 and all("m" in r["eq2_fit"] for r in t["rows"])
    # the spin after the impact: its marginal quantiles on the same grid, centred on Omega_x = 0.2
    w = np.array(t["rows"][1]["omega_x_after"]["quantiles"])
    assert w.shape == (11,) and np.all(np.diff(w) >= 0) and w[0] < 0.2 < w[-1]
    assert sorted(t["files"]) == sorted([str(path), str(path.with_suffix(".json"))])
    header = json.loads(path.with_suffix(".json").read_text())
    assert header["speeds_m_s"] == [0.5, 1.0, 2.0]
    lines = [l for l in path.read_text().splitlines() if not l.startswith("#")]
    assert lines[0].split(",")[0] == "speed_m_s" and len(lines) == 4
    row = np.array([float(x) for x in lines[2].split(",")])
    assert row[0] == 1.0
    np.testing.assert_array_equal(row[1:], t["quantiles"][1])
    # Faster impacts lose more energy: the median eps falls with the speed.
    assert np.all(np.diff(t["quantiles"][:, 5]) < 0)


def test_table_is_reproducible():
    np.testing.assert_array_equal(small()["quantiles"], small()["quantiles"])


def test_table_progress_and_bad_input():
    calls = []
    small(progress=lambda d, t: calls.append((d, t)))
    assert calls and calls[-1][1] == 15000
    with pytest.raises(ValueError, match="speeds"):
        small(speeds=[1.0, 0.5])
    with pytest.raises(ValueError, match="probabilities"):
        small(probabilities=1)
    with pytest.raises(ValueError, match="-5"):
        small(drops=-5)
    with pytest.raises(TypeError, match="speeds"):  # a wrong type (issue 24 item 6)
        small(speeds="fast")
    with pytest.raises(ValueError, match="not a sphere impact scene"):
        small(scene="fig6")


def test_c_header_reads_the_table(tmp_path):
    exe = os.environ.get("ASPERITY_TEST_C")
    if not exe or not os.path.exists(exe):
        pytest.skip("ASPERITY_TEST_C (the C consumer test) not built")
    path = tmp_path / "t.csv"
    t = small(path=path)
    r = subprocess.run([exe, str(path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "3 speeds x 11 probabilities" in r.stdout
    # The C sampler at the first speed and u = 0.5 is the median column.
    assert float(r.stdout.split("=")[-1]) == pytest.approx(t["quantiles"][0, 5], abs=1e-6)


def test_spin_grid_and_omega_bands(tmp_path):
    path = tmp_path / "spins.csv"
    t = small(spins=[-1.0, 0.0, 1.0], omega_bands=5, path=path)
    assert t["format_version"] == 2 and list(t["spins_rad_s"]) == [-1.0, 0.0, 1.0]
    assert t["quantiles"].shape == (3, 3, 11)
    assert t["omega_band_quantiles"].shape == (3, 3, 5, 11)
    lines = [l for l in path.read_text().splitlines() if not l.startswith("#")]
    assert lines[0].startswith("spin_rad_s,speed_m_s,row,p=0")
    assert len(lines) == 1 + 3 * 3 * (1 + 5)
    with pytest.raises(ValueError, match="spins"):
        small(spins=[1.0, -1.0])
    with pytest.raises(ValueError, match="omega_bands"):
        small(omega_bands=5000)


def test_read_cor_table_returns_what_was_written(tmp_path):
    """read_cor_table(path) gives back cor_table()'s dict: the same keys, the same arrays bit for bit."""
    for kw in (dict(), dict(spins=[-1.0, 0.0, 1.0], omega_bands=3)):
        path = tmp_path / f"t{len(kw)}.csv"
        t = small(path=path, **kw)
        r = asperity.read_cor_table(path)
        assert set(r) == set(t) - {"files"}
        for key in ("speeds_m_s", "probabilities", "quantiles", "spins_rad_s", "omega_band_quantiles"):
            if key in t:
                assert isinstance(r[key], np.ndarray), key
                np.testing.assert_array_equal(r[key], t[key], err_msg=key)
        assert r["rows"] == t["rows"] and r["format_version"] == t["format_version"]


def test_read_cor_table_refuses_a_truncated_table(tmp_path):
    path = tmp_path / "t.csv"
    small(path=path)
    text = path.read_text().splitlines()
    path.write_text("\n".join(text[:-1]) + "\n")  # the last speed's row lost
    with pytest.raises(ValueError, match="speeds=3"):
        asperity.read_cor_table(path)
