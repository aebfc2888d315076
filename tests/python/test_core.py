# SPDX-License-Identifier: GPL-3.0-or-later
"""The vectorised core: rough spheres, contact queries, the impulse, eps_n models, the laws."""
import gc

import numpy as np
import pytest

import asperity


def random_unit(m, seed=3):
    v = np.random.default_rng(seed).normal(size=(m, 3))
    return v / np.linalg.norm(v, axis=1)[:, None]


def test_centres_are_a_view_that_keeps_the_sphere_alive():
    s = asperity.make_rough_sphere(2000, 3e-3, 6.5e-7, seed=5)
    c = s.centres
    assert c.shape == (2000, 3) and c.dtype == np.float64
    assert not c.flags.owndata and not c.flags.writeable
    assert np.shares_memory(c, s.centres)  # two views of the same C++ memory: no copy
    np.testing.assert_allclose(np.linalg.norm(c, axis=1), 1.0, rtol=0, atol=1e-15)
    first = c[0].copy()
    del s
    gc.collect()
    np.testing.assert_array_equal(c[0], first)  # the view keeps its owner alive


def test_same_seed_same_sphere():
    a = asperity.make_rough_sphere(100, seed=9, sphere_id=2).centres
    b = asperity.make_rough_sphere(100, seed=9, sphere_id=2).centres
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("backend", asperity.backends())
def test_every_backend_agrees_with_numpy(backend):
    s = asperity.make_rough_sphere(5000, seed=2)
    d = random_unit(300)
    got = s.query(backend).lowest(d)
    keys = ((s.centres[None, :, :] - d[:, None, :]) ** 2).sum(axis=2)
    np.testing.assert_array_equal(got["index"], keys.argmin(axis=1))
    np.testing.assert_allclose(got["key"], keys.min(axis=1), rtol=1e-12, atol=1e-300)
    one = s.query(backend).lowest(d[0])
    assert one["index"] == got["index"][0]


def test_contacts_for_orientations():
    s = asperity.make_rough_sphere(100000, 3e-3, 6.5e-7)
    q = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0]])
    c = s.query("grid").contact(q)
    assert c["r"].shape == (2, 3)
    assert np.all(c["r"][:, 2] < -3e-3)  # below the centre, about R + a down
    np.testing.assert_allclose(np.hypot(c["r"][:, 0], c["r"][:, 1]), c["r_xy"], rtol=1e-12)
    np.testing.assert_allclose(asperity.body_down(q[1]), [0, 0, 1], atol=1e-15)


def test_query_bad_input():
    q = asperity.make_rough_sphere(100).query("brute")
    with pytest.raises(ValueError, match="octree"):
        asperity.make_rough_sphere(100).query("octree")
    with pytest.raises(ValueError, match=r"shape \(5, 2\)"):
        q.lowest(np.zeros((5, 2)))
    with pytest.raises(ValueError, match="not a unit vector"):
        q.lowest(np.array([[0.0, 0.0, -2.0]]))
    with pytest.raises(ValueError, match="not finite"):
        q.lowest(np.array([[np.nan, 0.0, -1.0]]))
    with pytest.raises(ValueError, match="unit quaternion"):
        q.contact(np.array([[2.0, 0, 0, 0]]))
    with pytest.raises(ValueError, match="asperities"):
        asperity.make_rough_sphere(0)
    with pytest.raises(ValueError, match="asperity.radius"):
        asperity.make_rough_sphere(10, 1e-3, 2e-3)


def test_restitution_models():
    m = asperity.pade14(0.0467)
    v = np.array([0.0, 0.1, 1.3, 10.0])
    e = m(v)
    assert e.shape == v.shape and e[0] == 1.0 and np.all(np.diff(e) < 0)
    assert m(1.3) == e[2]
    assert asperity.constant(0.5)(v).tolist() == [0.5] * 4
    with pytest.raises(ValueError, match="-1"):
        m(np.array([-1.0]))
    with pytest.raises(ValueError, match="beta"):
        asperity.pade14(-1.0)
    with pytest.raises(ValueError, match="1.5"):
        asperity.constant(1.5)


def test_impulse_over_arrays():
    R, M = 3e-3, 1e-3
    J = 0.4 * M * R * R
    r = np.zeros((4, 3))
    r[:, 2] = -R
    r[:, 0] = [0.0, 1e-6, -1e-6, 2e-6]
    res = asperity.solve_impact(M, J, V=[0, 0, -1.3], Omega=[0.2, 0, 0], r=r, eps_n=asperity.pade14())
    assert res["eps"].shape == (4,) and res["impact"].all()
    assert res["eps_n"][0] == pytest.approx(asperity.pade14()(1.3 - 0.2 * R * 0), rel=1e-3)
    central = asperity.solve_impact(M, J, V=[0, 0, -1.0], Omega=[0, 0, 0], r=[0, 0, -R], eps_n=0.8)
    assert central["eps"] == pytest.approx(0.8, rel=1e-14)
    away = asperity.solve_impact(M, J, V=[0, 0, 1.0], Omega=[0, 0, 0], r=[0, 0, -R])
    assert not away["impact"] and np.isnan(away["eps"])
    with pytest.raises(ValueError, match="mass"):
        asperity.solve_impact(-1.0, J, V=[0, 0, -1], Omega=[0, 0, 0], r=[0, 0, -R])
    with pytest.raises(ValueError, match="different lengths"):
        asperity.solve_impact(M, J, V=np.zeros((2, 3)) - 1, Omega=[0, 0, 0], r=np.zeros((3, 3)))


def test_laws_over_arrays():
    N, R = 100000, 3e-3
    x = np.linspace(0, 4e-5, 50)
    for law in (asperity.eq14_rxy(N, R), asperity.exact_sphere_rxy(N, R)):
        F = law.cdf(x)
        assert F.shape == x.shape and F[0] == 0 and np.all(np.diff(F) >= 0)
        assert law.pdf(x).shape == x.shape
        assert law.cdf(1e-5) == F[np.searchsorted(x, 1e-5)] or 0 < law.cdf(1e-5) < 1
    assert asperity.eq18_rx(N, R).cdf(0.0) == pytest.approx(0.5)
    e = asperity.eq28_corrected()
    grid = np.linspace(e.mean - 5e-4, e.mean + 1e-4, 20001)  # eps is spread over ~1e-4
    assert np.trapz(e.pdf(grid), grid) == pytest.approx(1.0, abs=1e-3)
    assert "eq28" in asperity.eq28_printed().name
    assert asperity.eq33_corrected().cdf(0.2) == pytest.approx(0.5)
    with pytest.raises(ValueError, match="speed"):
        asperity.eq28_corrected(speed=-1.0)
