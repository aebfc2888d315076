// SPDX-License-Identifier: GPL-3.0-or-later
// The only CGAL mesh headers of the project: reading and checking triangle meshes.
#include "asperity/app/mesh_io.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/IO/polygon_mesh_io.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <cmath>
#include <fstream>
#include <new>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "asperity/app/atomic_file.hpp"
#include "asperity/app/bounded_read.hpp"
#include "core/format.hpp"

namespace asperity {

using detail::num;

namespace {

/// Largest mesh file read: ~20 M triangles of ASCII OFF. A mesh body is the smooth shape under
/// the asperities; nothing asperity does needs more.
constexpr std::uint64_t kMaxMeshBytes = std::uint64_t{1} << 30;

/// The element counts an OFF or PLY header claims must fit in the file: every vertex or face takes
/// at least 6 bytes in any encoding ("0 0 0\n"; binary: 3 floats), so a header claiming 2e9
/// vertices in a small file is refused by name before the mesh library allocates for them.
void check_header_counts(const std::filesystem::path& file, std::uint64_t size) {
  std::ifstream in(file, std::ios::binary);
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::istringstream is(head);
  std::string word;
  long double claimed = 0;
  if (!(is >> word)) return;
  if (word == "OFF") {
    std::string line;
    std::getline(is, line);
    while (std::getline(is, line)) {  // the first line that is not a comment holds the counts
      if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t\r")] == '#') continue;
      std::istringstream counts(line);
      long double nv = 0, nf = 0;
      if (counts >> nv >> nf) claimed = nv + nf;
      break;
    }
  } else if (word == "ply") {
    std::string line;
    while (std::getline(is, line) && line.rfind("end_header", 0) != 0) {
      std::istringstream e(line);
      std::string kw, name;
      long double n = 0;
      if (e >> kw >> name >> n && kw == "element") claimed += n;
    }
  }
  if (claimed * 6 > static_cast<long double>(size))
    throw std::invalid_argument("mesh file '" + file.string() + "': its header claims " + num(static_cast<double>(claimed)) +
                                " vertices and faces, more than its " + std::to_string(size) + " bytes can hold");
}

}  // namespace

TriangleMesh read_mesh(const std::filesystem::path& file, double scale) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  const std::string f = file.string();
  if (!std::isfinite(scale) || scale <= 0) throw std::invalid_argument("mesh scale must be finite and > 0, got " + num(scale));
  std::uint64_t size = 0;
  try {
    size = checked_input_size(file, kMaxMeshBytes, "mesh file");
  } catch (const InputFileError& e) {
    throw std::invalid_argument(e.what());
  }
  check_header_counts(file, size);
  Mesh sm;
  bool read = false;
  try {
    read = CGAL::Polygon_mesh_processing::IO::read_polygon_mesh(f, sm);
  } catch (const std::bad_alloc&) {
    throw std::invalid_argument("mesh file '" + f + "': not enough memory to read it (" + std::to_string(size) + " bytes)");
  }
  if (!read || sm.number_of_faces() == 0)
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
