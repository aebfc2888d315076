// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Mesh files: reading (CGAL, with the checks a solid body needs) and PLY export of rough bodies.
#include <filesystem>

#include "asperity/core/mesh.hpp"

namespace asperity {

/// Reads OFF, PLY, STL or OBJ with CGAL, scaling coordinates by `scale` (to metres). Throws
/// std::invalid_argument naming the file when it cannot be read, is not a triangle mesh, is not
/// closed, self-intersects, or is not outward oriented (non-positive volume).
TriangleMesh read_mesh(const std::filesystem::path& file, double scale = 1.0);

/// PLY export for MeshLab / ParaView (ASCII, written atomically).
/// points: one vertex per asperity centre with a `radius` property (body frame, metres).
/// spheres: each asperity as an icosahedron of radius inflate*rho (20 faces; for low N), plus the
/// base mesh if given (translated into the body frame by -centroid).
enum class PlyStyle { points, spheres };
void write_ply(const std::filesystem::path& file, const RoughBody& b, PlyStyle style, double inflate = 1.0,
               const TriangleMesh* base = nullptr, const Vec3& base_offset = Vec3::Zero());

}  // namespace asperity
