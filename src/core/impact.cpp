// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/core/impact.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace asperity {

namespace {

std::string vec(const Vec3& v) {
  std::ostringstream os;
  os.precision(17);
  os << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return os.str();
}

void check(const ImpactState& s) {
  if (!s.V.allFinite()) throw std::invalid_argument("impact: V is not finite: " + vec(s.V));
  if (!s.Omega.allFinite()) throw std::invalid_argument("impact: Omega is not finite: " + vec(s.Omega));
  if (!s.r.allFinite()) throw std::invalid_argument("impact: r is not finite: " + vec(s.r));
  if (!s.n.allFinite() || std::abs(s.n.norm() - 1.0) > 1e-12)
    throw std::invalid_argument("impact: n must be a unit vector, got " + vec(s.n));
  if (s.V.dot(s.n) == 0.0) throw std::invalid_argument("impact: V.n = 0, the macroscopic eps of Eq. 1 is undefined");
}

void check_coefficients(double eps_n, double eps_t) {
  if (!std::isfinite(eps_n) || eps_n < 0) throw std::invalid_argument("impact: eps_n must be finite and >= 0");
  if (!std::isfinite(eps_t)) throw std::invalid_argument("impact: eps_t must be finite");
}

// Target change of the contact velocity, Eq. 6.
Vec3 delta_v(const Vec3& v, const Vec3& n, double eps_n, double eps_t) {
  const double vn = v.dot(n);
  const Vec3 vt = v - vn * n;
  return -(1.0 + eps_n) * vn * n - (1.0 - eps_t) * vt;
}

ImpactResult finish(const ImpactState& s, const Vec3& P, const Vec3& dOmega, double mass, double vn, double eps_n) {
  ImpactResult r;
  r.P = P;
  r.V_after = s.V + P / mass;
  r.Omega_after = s.Omega + dOmega;
  r.v_n = vn;
  r.eps_n = eps_n;
  r.eps = -r.V_after.dot(s.n) / s.V.dot(s.n);
  return r;
}

Eigen::Matrix3d cross_matrix(const Vec3& a) {
  Eigen::Matrix3d m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

}  // namespace

RigidBody RigidBody::sphere(double mass, double radius) {
  if (!(mass > 0) || !std::isfinite(mass)) throw std::invalid_argument("sphere: mass must be finite and > 0");
  if (!(radius > 0) || !std::isfinite(radius)) throw std::invalid_argument("sphere: radius must be finite and > 0");
  RigidBody b;
  b.mass = mass;
  b.inertia = Eigen::Matrix3d::Identity() * (0.4 * mass * radius * radius);
  return b;
}

std::optional<ImpactResult> solve_impact(const RigidBody& body, const ImpactState& s, double eps_n, double eps_t) {
  check(s);
  check_coefficients(eps_n, eps_t);
  const Vec3 v = s.V + s.Omega.cross(s.r);
  const double vn = v.dot(s.n);
  if (!(vn < 0)) return std::nullopt;
  const Eigen::Matrix3d Jinv = body.inertia.inverse();
  const Eigen::Matrix3d rx = cross_matrix(s.r);
  const Eigen::Matrix3d K = Eigen::Matrix3d::Identity() / body.mass - rx * Jinv * rx;
  const Vec3 P = K.ldlt().solve(delta_v(v, s.n, eps_n, eps_t));
  return finish(s, P, Jinv * s.r.cross(P), body.mass, vn, eps_n);
}

std::optional<ImpactResult> solve_impact(const RigidBody& body, const ImpactState& s, const Restitution& eps_n,
                                         double eps_t) {
  check(s);
  const double vn = (s.V + s.Omega.cross(s.r)).dot(s.n);
  if (!(vn < 0)) return std::nullopt;
  return solve_impact(body, s, eps_n(-vn), eps_t);
}

std::optional<ImpactResult> solve_impact_isotropic(double mass, double inertia, const ImpactState& s, double eps_n,
                                                   double eps_t) {
  check(s);
  check_coefficients(eps_n, eps_t);
  if (!(mass > 0) || !(inertia > 0)) throw std::invalid_argument("impact: mass and inertia must be > 0");
  const Vec3 v = s.V + s.Omega.cross(s.r);
  const double vn = v.dot(s.n);
  if (!(vn < 0)) return std::nullopt;
  const double Ig = inertia / mass;
  const Vec3 dv = delta_v(v, s.n, eps_n, eps_t);
  const Vec3 P = (mass / (Ig + s.r.squaredNorm())) * (Ig * dv + s.r * s.r.dot(dv));
  return finish(s, P, s.r.cross(P) / inertia, mass, vn, eps_n);
}

}  // namespace asperity
