// SPDX-License-Identifier: GPL-3.0-or-later
// The only CGAL mesh headers of the project: reading and checking triangle meshes.
#include "asperity/app/mesh_io.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/IO/polygon_mesh_io.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "asperity/app/atomic_file.hpp"
#include "core/format.hpp"

namespace asperity {

using detail::num;

TriangleMesh read_mesh(const std::filesystem::path& file, double scale) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  const std::string f = file.string();
  if (!std::isfinite(scale) || scale <= 0) throw std::invalid_argument("mesh scale must be finite and > 0, got " + num(scale));
  if (!std::filesystem::is_regular_file(file)) throw std::invalid_argument("mesh file '" + f + "' does not exist");
  Mesh sm;
  if (!CGAL::Polygon_mesh_processing::IO::read_polygon_mesh(f, sm) || sm.number_of_faces() == 0)
    throw std::invalid_argument("mesh file '" + f + "' could not be read as a polygon mesh (OFF, PLY, STL, OBJ)");
  if (!CGAL::is_triangle_mesh(sm)) throw std::invalid_argument("mesh '" + f + "' is not a triangle mesh");
  if (!CGAL::is_closed(sm)) throw std::invalid_argument("mesh '" + f + "' is not closed (it has border edges)");
  if (CGAL::Polygon_mesh_processing::does_self_intersect(sm))
    throw std::invalid_argument("mesh '" + f + "' intersects itself");
  TriangleMesh m;
  std::vector<std::uint32_t> id(sm.number_of_vertices() + sm.number_of_removed_vertices(), 0);
  for (auto v : sm.vertices()) {
    const auto& p = sm.point(v);
    id[v.idx()] = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.emplace_back(scale * p.x(), scale * p.y(), scale * p.z());
  }
  for (auto fc : sm.faces()) {
    std::array<std::uint32_t, 3> t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(fc), sm)) t[static_cast<std::size_t>(k++)] = id[v.idx()];
    m.faces.push_back(t);
  }
  // A closed, consistently oriented mesh has volume of one sign; outward means positive.
  double vol = 0;
  for (const auto& t : m.faces) vol += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6.0;
  if (!(vol > 0)) throw std::invalid_argument("mesh '" + f + "' is not outward oriented (volume " + num(vol) + " m^3)");
  return m;
}

void write_ply(const std::filesystem::path& file, const RoughBody& b, PlyStyle style, double inflate,
               const TriangleMesh* base, const Vec3& base_offset) {
  if (!std::isfinite(inflate) || inflate <= 0) throw std::invalid_argument("inflate must be finite and > 0, got " + num(inflate));
  std::ostringstream os;
  os.precision(9);
  os << "ply\nformat ascii 1.0\ncomment asperity rough body '" << b.name << "', body frame, metres\n";
  if (style == PlyStyle::points) {
    os << "element vertex " << b.size() << "\nproperty double x\nproperty double y\nproperty double z\n"
       << "property double radius\nend_header\n";
    for (std::size_t i = 0; i < b.size(); ++i)
      os << b.centres[i].x() << " " << b.centres[i].y() << " " << b.centres[i].z() << " " << b.radii[i] << "\n";
  } else {
    // Unit icosahedron.
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3> iv{{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (auto& v : iv) v.normalize();
    const int ifc[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                            {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    const std::size_t nbv = base ? base->vertices.size() : 0, nbf = base ? base->faces.size() : 0;
    os << "element vertex " << 12 * b.size() + nbv << "\nproperty double x\nproperty double y\nproperty double z\n"
       << "element face " << 20 * b.size() + nbf << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (std::size_t i = 0; i < b.size(); ++i)
      for (const Vec3& v : iv) {
        const Vec3 p = b.centres[i] + inflate * b.radii[i] * v;
        os << p.x() << " " << p.y() << " " << p.z() << "\n";
      }
    for (std::size_t k = 0; k < nbv; ++k) {
      const Vec3 p = base->vertices[k] + base_offset;
      os << p.x() << " " << p.y() << " " << p.z() << "\n";
    }
    for (std::size_t i = 0; i < b.size(); ++i)
      for (const auto& f : ifc) os << "3 " << 12 * i + f[0] << " " << 12 * i + f[1] << " " << 12 * i + f[2] << "\n";
    for (std::size_t k = 0; k < nbf; ++k) {
      const auto& f = base->faces[k];
      os << "3 " << 12 * b.size() + f[0] << " " << 12 * b.size() + f[1] << " " << 12 * b.size() + f[2] << "\n";
    }
  }
  write_file_atomic(file, os.str());
}

}  // namespace asperity
