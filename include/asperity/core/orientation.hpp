// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Orientations of a body. World frame: z points UP, the plate is below the body and its outward
// normal is +z; "down" is -z. A rotation q maps body coordinates to world coordinates.
// Queries are made in the body frame: instead of rotating N centres we rotate one vector,
// the world's down direction, into the body: d = q^{-1} (-z).
#include <Eigen/Geometry>

#include "asperity/core/geometry.hpp"

namespace asperity {

class Stream;
/// An orientation: the unit quaternion q that maps body coordinates to world coordinates.
using Rotation = Eigen::Quaterniond;

/// A uniformly (Haar) distributed rotation, from three uniforms of the stream
/// (Shoemake's subgroup algorithm).
Rotation random_rotation(Stream& s);

/// A uniformly (Haar) distributed rotation without trigonometric functions (G. Marsaglia,
/// "Choosing a point from the surface of a sphere", Ann. Math. Statist. 43 (1972) 645): two points
/// (x1, x2), (x3, x4) uniform in the unit disk by rejection from the square (s1, s2 their squared
/// radii), then (x1, x2, x3 f, x4 f), f = sqrt((1 - s1) / s2), is uniform on S^3, i.e. a Haar
/// rotation. Coordinates are signed 64-bit words of the stream times 2^-63 (~5.1 words per draw on
/// average: 1.38 Philox blocks). Not normalised again: |q|^2 = 1 within a few ulp. Other streams
/// than random_rotation's: the explicit drops use it, the bounces keep Shoemake's.
Rotation random_rotation_marsaglia(Stream& s);

/// The world's down direction (-z) expressed in the body frame of a body rotated by q.
inline Vec3 body_down(const Rotation& q) { return q.conjugate() * Vec3(0.0, 0.0, -1.0); }

}  // namespace asperity
