// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh bodies: mass properties, area-uniform asperity tiling, smooth surfaces. Reading and
// writing mesh files is app/mesh_io.cpp (CGAL's I/O stays out of the core).
#include "asperity/core/mesh.hpp"


#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "core/format.hpp"

#include "asperity/core/random.hpp"

namespace asperity {

using detail::num;


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
  check_asperity_count(n);
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


}  // namespace asperity
