// Mesh bodies: CGAL reading and checks (the only CGAL mesh headers of the library), mass
// properties, area-uniform asperity tiling, PLY export.
#include "asperity/mesh.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/IO/polygon_mesh_io.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "format.hpp"

#include "asperity/random.hpp"
#include "asperity/report.hpp"

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

MassProperties mass_properties(const TriangleMesh& m, double density) {
  if (!std::isfinite(density) || density <= 0)
    throw std::invalid_argument("density must be a finite number > 0 kg/m^3, got " + num(density));
  // Relative to a reference point inside the body (the vertex mean) to avoid cancellation far from
  // the origin.
  Vec3 o = Vec3::Zero();
  for (const Vec3& v : m.vertices) o += v;
  o /= static_cast<double>(std::max<std::size_t>(1, m.vertices.size()));
  double V = 0, A = 0;
  Vec3 first = Vec3::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const auto& t : m.faces) {
    const Vec3 a = m.vertices[t[0]] - o, b = m.vertices[t[1]] - o, c = m.vertices[t[2]] - o;
    const double det = a.dot(b.cross(c));
    const Vec3 s = a + b + c;
    V += det / 6.0;
    first += det / 24.0 * s;
    second += det / 120.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
    A += 0.5 * (b - a).cross(c - a).norm();
  }
  if (!(V > 0)) throw std::invalid_argument("mesh volume must be > 0 (closed, outward oriented), got " + num(V) + " m^3");
  MassProperties p;
  p.volume = V;
  p.area = A;
  p.mass = density * V;
  const Vec3 g = first / V;  // centroid relative to o
  p.centroid = o + g;
  // Second moments about the centroid, then J = rho (tr(C) I - C).
  const Eigen::Matrix3d C = density * (second - V * g * g.transpose());
  p.inertia = C.trace() * Eigen::Matrix3d::Identity() - C;
  return p;
}

SurfaceMap ellipsoid_surface(double a, double b, double c) {
  for (double v : {a, b, c})
    if (!std::isfinite(v) || v <= 0) throw std::invalid_argument("ellipsoid semi-axis must be finite and > 0 m, got " + num(v));
  return [a, b, c](const Vec3& p) {
    const double s = std::sqrt(p.x() * p.x() / (a * a) + p.y() * p.y() / (b * b) + p.z() * p.z() / (c * c));
    return Vec3(p / s);
  };
}

SurfaceMap superellipsoid_surface(double a, double b, double c, double m) {
  for (double v : {a, b, c})
    if (!std::isfinite(v) || v <= 0) throw std::invalid_argument("superellipsoid semi-axis must be finite and > 0 m, got " + num(v));
  if (!std::isfinite(m) || m < 2) throw std::invalid_argument("superellipsoid exponent must be finite and >= 2, got " + num(m));
  return [a, b, c, m](const Vec3& p) {
    const double s = std::pow(std::pow(std::abs(p.x() / a), m) + std::pow(std::abs(p.y() / b), m) + std::pow(std::abs(p.z() / c), m),
                              1.0 / m);
    return Vec3(p / s);
  };
}

SurfaceMap smooth_surface(const std::vector<double>& axes) {
  if (axes.empty()) return {};
  if (axes.size() != 3 && axes.size() != 4)
    throw std::invalid_argument("smooth surface needs semi-axes a, b, c and an optional exponent m, got " +
                                std::to_string(axes.size()) + " numbers");
  return superellipsoid_surface(axes[0], axes[1], axes[2], axes.size() == 4 ? axes[3] : 2.0);
}

RoughBody make_rough_mesh_body(const TriangleMesh& m, std::uint64_t n, const RadiusDistribution& radii, double density,
                               std::uint64_t seed, std::uint64_t body_id, const SurfaceMap& onto, std::string name) {
  validate(radii);
  if (n < 1 || n > 0xffffffffull) throw std::invalid_argument("asperities must be in [1, 2^32-1], got " + std::to_string(n));
  const MassProperties mp = mass_properties(m, density);
  std::vector<double> cum(m.faces.size());
  double acc = 0;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const auto& t = m.faces[f];
    acc += 0.5 * (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]).norm();
    cum[f] = acc;
  }
  RoughBody b;
  b.name = std::move(name);
  b.mass = mp.mass;
  b.inertia = mp.inertia;
  b.area = mp.area;
  b.centres.resize(n);
  b.radii.resize(n);
  const auto N = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) if (N > 16384)
  for (std::int64_t i = 0; i < N; ++i) {
    Stream s(seed, Purpose::sphere, body_id, static_cast<std::uint64_t>(i));
    const double u0 = s.uniform0() * acc;
    const auto f = static_cast<std::size_t>(std::upper_bound(cum.begin(), cum.end(), u0) - cum.begin());
    const auto& t = m.faces[std::min(f, m.faces.size() - 1)];
    const double r1 = std::sqrt(s.uniform0()), r2 = s.uniform0();
    Vec3 p = (1.0 - r1) * m.vertices[t[0]] + r1 * (1.0 - r2) * m.vertices[t[1]] + r1 * r2 * m.vertices[t[2]];
    if (onto) p = onto(p);
    b.centres[static_cast<std::size_t>(i)] = p - mp.centroid;
    b.radii[static_cast<std::size_t>(i)] = sample_radius(radii, s);
  }
  return b;
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
