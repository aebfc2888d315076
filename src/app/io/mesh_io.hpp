// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Mesh files: reading (CGAL, with the checks a solid body needs) and PLY export of rough bodies.
#include <cstdint>
#include <filesystem>

#include "asperity/core/mesh.hpp"

namespace asperity {

/// Reads OFF, PLY, STL or OBJ with CGAL, scaling coordinates by `scale` (to metres). Throws
/// std::invalid_argument naming the file when it cannot be read, is not a triangle mesh, is not
/// closed, self-intersects, or is not outward oriented (non-positive volume).
TriangleMesh read_mesh(const std::filesystem::path& file, double scale = 1.0);

/// The counts a mesh file states, read without parsing the mesh (OFF and PLY headers, the binary
/// STL's face count, OBJ and ASCII STL lines counted): what the memory estimate needs before
/// read_mesh allocates anything. Faces as stored (polygons count once); 0 when unknown.
struct MeshFileSize {
  std::uint64_t vertices = 0, faces = 0;
};
MeshFileSize mesh_file_size(const std::filesystem::path& file);

/// PLY export for MeshLab / ParaView (ASCII, written atomically; the text is built in one
/// allocation of ply_text_bytes, so its peak is the text: resources.cpp counts it).
/// points: one vertex per asperity centre with a `radius` property (body frame, metres).
/// spheres: each asperity as an icosahedron of radius inflate*rho (20 faces; for low N), plus the
/// base mesh if given (translated into the body frame by -centroid).
enum class PlyStyle { points, spheres };
void write_ply(const std::filesystem::path& file, const RoughBody& b, PlyStyle style, double inflate = 1.0,
               const TriangleMesh* base = nullptr, const Vec3& base_offset = Vec3::Zero());

/// Upper bound of the PLY text's size [bytes]: every number at its widest (%.9g: 16 characters).
std::uint64_t ply_text_bytes(std::uint64_t asperities, PlyStyle style, std::uint64_t base_vertices = 0,
                             std::uint64_t base_faces = 0);

}  // namespace asperity
