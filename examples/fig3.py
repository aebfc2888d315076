# SPDX-License-Identifier: GPL-3.0-or-later
"""Fig. 3 of the paper from explicit geometry: r_xy of the lowest asperity against Eq. 14 and the
exact finite-N law. 20 explicit rough spheres (N = 1e5) x 10^4 random orientations; writes fig3.png.
Run: PYTHONPATH=build/python python3 examples/fig3.py   (a few seconds)"""
import matplotlib; matplotlib.use("Agg")  # noqa: E702
import matplotlib.pyplot as plt
import numpy as np
import asperity

N, R, a = 100_000, 3e-3, 6.5e-7
q = np.random.default_rng(1).normal(size=(10_000, 4))
q /= np.linalg.norm(q, axis=1)[:, None]  # uniformly distributed rotations (w, x, y, z)
r_xy = np.concatenate([asperity.make_rough_sphere(N, R, a, seed=1, sphere_id=k).query("grid").contact(q)["r_xy"]
                       for k in range(20)])
x = np.linspace(0, r_xy.max(), 300)
plt.hist(r_xy * 1e6, bins=80, density=True, alpha=0.5, label=f"{r_xy.size} drops, 20 explicit spheres")
for law in (asperity.eq14_rxy(N, R), asperity.exact_sphere_rxy(N, R)):
    plt.plot(x * 1e6, law.pdf(x) * 1e-6, label=law.name)
plt.xlabel("r_xy [µm]"), plt.ylabel("pdf [1/µm]"), plt.legend(), plt.savefig("fig3.png", dpi=120)
