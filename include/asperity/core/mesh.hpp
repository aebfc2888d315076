// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Bodies from triangle meshes (meshes/*.off, made by scripts/make_meshes.py): mass properties
// of the closed mesh and asperities tiled uniformly by area. Files: app/mesh_io.hpp.
// Units: the mesh file's coordinates are metres (pass a scale otherwise).
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "asperity/core/body.hpp"

namespace asperity {

/// A closed, consistently oriented triangle mesh: the base body of a mesh body (app/mesh_io.hpp
/// reads it from an OFF file).
struct TriangleMesh {
  std::vector<Vec3> vertices;                      ///< [m]
  std::vector<std::array<std::uint32_t, 3>> faces; ///< counter-clockwise seen from outside
};


/// Mass properties of the closed mesh as a solid of uniform density.
struct MassProperties {
  double volume = 0;    ///< [m^3]
  double area = 0;      ///< surface area [m^2]
  double mass = 0;      ///< [kg]
  Vec3 centroid{0, 0, 0};  ///< centre of mass, mesh coordinates [m]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about the centre of mass, mesh axes [kg m^2]
};
/// By signed tetrahedra from the origin (exact for the polyhedron, any origin): volume
/// sum det/6, first moments sum det (a+b+c)/24, second moments
/// int x x^T = sum det/120 (a a^T + b b^T + c c^T + (a+b+c)(a+b+c)^T). Throws std::invalid_argument
/// for a non-positive volume or density.
MassProperties mass_properties(const TriangleMesh& m, double density);

/// Optional map of a point on the mesh onto a smooth surface the mesh approximates (e.g. the true
/// ellipsoid): without it, asperity centres lie on the flat facets, and a body lands on a mesh
/// VERTEX's neighbourhood: facet sag (~R h^2/8 for edge h) dwarfs the sub-micron height
/// differences that decide the paper's contact statistics.
using SurfaceMap = std::function<Vec3(const Vec3&)>;
/// Radial projection onto the ellipsoid (x/a)^2 + (y/b)^2 + (z/c)^2 = 1 (mesh coordinates) [m].
SurfaceMap ellipsoid_surface(double a, double b, double c);
/// Radial projection onto the superellipsoid |x/a|^m + |y/b|^m + |z/c|^m = 1 (m >= 2; m = 2 is
/// the ellipsoid, meshes/rounded_cube.off is a = b = c = 2.5 mm, m = 8).
SurfaceMap superellipsoid_surface(double a, double b, double c, double m);
/// The surface of a scene's `smooth = [a, b, c(, m)]` (m = 2 if absent): empty -> no map (centres
/// stay on the facets). Throws std::invalid_argument for another count or a bad value.
SurfaceMap smooth_surface(const std::vector<double>& axes);

/// N asperity centres uniform by area on the mesh surface: triangle by area (cumulative table,
/// binary search on one uniform), point by the sqrt trick (two uniforms), then the radius
/// (sample_radius) -- all from Stream(seed, Purpose::sphere, body_id, i). Chosen over CGAL's
/// Random_points_in_triangle_mesh_3 (CGAL::Random) so that asperity i is a pure function of
/// (seed, body_id, i): reproducible and thread-count independent. If `onto` is set, each centre
/// is mapped onto that surface. Centres are stored relative to the centre of mass, with the mass
/// properties of `density`.
RoughBody make_rough_mesh_body(const TriangleMesh& m, std::uint64_t n, const RadiusDistribution& radii, double density,
                               std::uint64_t seed, std::uint64_t body_id, const SurfaceMap& onto = {},
                               std::string name = "mesh");


}  // namespace asperity
