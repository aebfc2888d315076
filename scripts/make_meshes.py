#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the base bodies of meshes/ as closed, outward-oriented triangle meshes (OFF, metres).

  icosphere.off     sphere R = 3 mm, icosahedron subdivided 3 times (1280 faces)
  ellipsoid.off     semi-axes 4, 3, 2.25 mm (the icosphere's vertices scaled; 1280 faces)
  rounded_cube.off  superellipsoid |x|^8 + |y|^8 + |z|^8 = a^8, a = 2.5 mm, from a cube-sphere
                    grid of 12 x 12 quads per face (1728 faces)

Deterministic: rerunning reproduces the committed files byte for byte.
Usage: scripts/make_meshes.py [OUTDIR]   (default: meshes/ next to scripts/)
"""
import math
import os
import sys


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


def icosphere(subdivisions):
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [normalize(v) for v in [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
                                     (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
             (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                va, vb = verts[a], verts[b]
                verts.append(normalize(tuple((x + y) / 2 for x, y in zip(va, vb))))
                cache[key] = len(verts) - 1
            return cache[key]

        new = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return verts, faces


def rounded_cube(n, a, m):
    verts, faces, index = [], [], {}

    def vid(p):
        key = tuple(round(c, 12) for c in p)
        if key not in index:
            d = normalize(p)
            s = sum(abs(c) ** m for c in d) ** (1.0 / m)
            verts.append(tuple(a * c / s for c in d))
            index[key] = len(verts) - 1
        return index[key]

    for axis in range(3):
        for sign in (-1.0, 1.0):
            u_ax, v_ax = [k for k in range(3) if k != axis]
            for i in range(n):
                for j in range(n):
                    quad = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0.0, 0.0, 0.0]
                        p[axis] = sign
                        p[u_ax] = -1.0 + 2.0 * (i + di) / n
                        p[v_ax] = -1.0 + 2.0 * (j + dj) / n
                        quad.append(vid(p))
                    faces += [(quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3])]
    return verts, faces


def orient_outward(verts, faces):
    """Star-shaped about the origin: a face is outward iff its normal points away from it."""
    out = []
    for a, b, c in faces:
        pa, pb, pc = verts[a], verts[b], verts[c]
        e1 = [pb[k] - pa[k] for k in range(3)]
        e2 = [pc[k] - pa[k] for k in range(3)]
        nrm = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
        cen = [(pa[k] + pb[k] + pc[k]) for k in range(3)]
        out.append((a, b, c) if sum(nrm[k] * cen[k] for k in range(3)) > 0 else (a, c, b))
    return out


def write_off(path, verts, faces, comment):
    with open(path, "w") as f:
        f.write("OFF\n# %s\n%d %d 0\n" % (comment, len(verts), len(faces)))
        for v in verts:
            f.write("%.12e %.12e %.12e\n" % v)
        for a, b, c in faces:
            f.write("3 %d %d %d\n" % (a, b, c))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "meshes")
    os.makedirs(out, exist_ok=True)
    v, f = icosphere(3)
    R = 3e-3
    write_off(os.path.join(out, "icosphere.off"), [tuple(R * c for c in p) for p in v], orient_outward(v, f),
              "icosphere, R = 3 mm (vertices on the sphere), 3 subdivisions, metres")
    axes = (4e-3, 3e-3, 2.25e-3)
    ve = [tuple(axes[k] * p[k] for k in range(3)) for p in v]
    write_off(os.path.join(out, "ellipsoid.off"), ve, orient_outward(ve, f),
              "ellipsoid, semi-axes 4, 3, 2.25 mm (vertices on the ellipsoid), metres")
    vc, fc = rounded_cube(12, 2.5e-3, 8.0)
    write_off(os.path.join(out, "rounded_cube.off"), vc, orient_outward(vc, fc),
              "rounded cube |x|^8+|y|^8+|z|^8 = (2.5 mm)^8, cube-sphere grid 12x12 per face, metres")


if __name__ == "__main__":
    main()
