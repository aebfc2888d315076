#pragma once
// Orientations of a body. World frame: z points UP, the plate is below the body and its outward
// normal is +z; "down" is -z. A rotation q maps body coordinates to world coordinates.
// Queries are made in the body frame: instead of rotating N centres we rotate one vector,
// the world's down direction, into the body: d = q^{-1} (-z).
#include <Eigen/Geometry>

#include "asperity/core/geometry.hpp"

namespace asperity {

class Stream;
using Rotation = Eigen::Quaterniond;

/// A uniformly (Haar) distributed rotation, from three uniforms of the stream
/// (Shoemake's subgroup algorithm).
Rotation random_rotation(Stream& s);

/// The world's down direction (-z) expressed in the body frame of a body rotated by q.
inline Vec3 body_down(const Rotation& q) { return q.conjugate() * Vec3(0.0, 0.0, -1.0); }

}  // namespace asperity
