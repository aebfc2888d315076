// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The test and benchmark reference for FreeRotation: Euler's equations J_b w' = (J_b w) x w for the
// body-frame angular velocity w plus the quaternion kinematics q' = q (0, w) / 2, integrated by
// Boost.Odeint (controlled Runge-Kutta-Fehlberg 7(8)) from 0 to t on every call. Not the library
// path: it is slow and its error grows with t, but it shares nothing with the closed form
// (no principal frame, no elliptic functions), so agreement is evidence for both.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <boost/numeric/odeint.hpp>

#include <array>
#include <cmath>

#include "asperity/core/free_rotation.hpp"

namespace asperity::detail {

/// tol: absolute and relative error per step of the integrator, in units where |Omega0| = 1
/// (time is measured in radians of the initial spin, so one tolerance fits every spin rate).
inline RotationState reference_free_rotation(const Eigen::Matrix3d& J, const Rotation& q0, const Vec3& omega0,
                                             double t, double tol = 1e-13) {
  const double s = omega0.norm();
  if (s == 0 || t == 0) return {q0.normalized(), omega0};
  using State = std::array<double, 7>;  // w/s (body), q = (w, x, y, z)
  const Eigen::Matrix3d Jinv = J.inverse();
  const Vec3 wb = q0.normalized().conjugate() * (omega0 / s);
  const Rotation qn = q0.normalized();
  State y{wb.x(), wb.y(), wb.z(), qn.w(), qn.x(), qn.y(), qn.z()};
  auto rhs = [&](const State& x, State& dx, double) {
    const Vec3 w(x[0], x[1], x[2]);
    const Vec3 dw = Jinv * (J * w).cross(w);
    dx[0] = dw.x(), dx[1] = dw.y(), dx[2] = dw.z();
    // q' = q (0, w) / 2 with q = (a, b): (a, b)(0, w) = (-b.w, a w + b x w)
    const double a = x[3];
    const Vec3 b(x[4], x[5], x[6]);
    const Vec3 v = a * w + b.cross(w);
    dx[3] = -0.5 * b.dot(w), dx[4] = 0.5 * v.x(), dx[5] = 0.5 * v.y(), dx[6] = 0.5 * v.z();
  };
  namespace odeint = boost::numeric::odeint;
  // GCC 12 warns about odeint's own copy of an unused scratch array (a false positive in Boost).
#pragma GCC diagnostic push
#if defined(__GNUC__) && !defined(__clang__)  // clang has no such warning group
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
  const double tau = s * t;
  const double dt0 = tau > 0 ? 1e-3 : -1e-3;
  odeint::integrate_adaptive(odeint::make_controlled<odeint::runge_kutta_fehlberg78<State>>(tol, tol), rhs, y, 0.0,
                             tau, dt0);
#pragma GCC diagnostic pop
  RotationState out;
  out.q = Rotation(y[3], y[4], y[5], y[6]).normalized();
  out.omega = out.q * (s * Vec3(y[0], y[1], y[2]));
  return out;
}

}  // namespace asperity::detail
