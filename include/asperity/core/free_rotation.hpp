// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Torque-free rotation of a rigid body with a general inertia tensor (the asymmetric top): what a
// non-spherical rough body does between two impacts. In flight only gravity acts, through the
// centre of mass, so the angular momentum L = Q J_b Q^T Omega is constant in the world and the
// rotational kinetic energy T = Omega . L / 2 is constant; the body-frame angular velocity obeys
// Euler's equations J_b w' = (J_b w) x w.
//
// The motion is solved exactly (Jacobi elliptic functions for the body-frame angular velocity, and
// the angle about L by Gauss-Legendre quadrature of a periodic integrand), not integrated step by
// step: `at(t)` is a pure function of t, so any time can be asked in any order (root finding for
// the next contact goes back and forth), with an error that does not grow with the number of
// calls. Degenerate cases (spherical and symmetric tops, principal axes, the separatrix, rest) are
// exact cases of the same formulas (no switching thresholds); src/free_rotation.cpp derives them.
//
// Frames and units: q maps body to world (orientation.hpp), Omega is the WORLD-frame angular
// velocity [rad/s], J_b the body-frame inertia about the centre of mass [kg m^2], t [s].
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <memory>

#include "asperity/core/geometry.hpp"
#include "asperity/core/orientation.hpp"

namespace asperity {

/// Orientation and world-frame angular velocity at one time.
struct RotationState {
  Rotation q = Rotation::Identity();  ///< body -> world
  Vec3 omega{0, 0, 0};                ///< world frame [rad/s]
};

/// The free motion of one body from an initial state (t = 0). Immutable after construction;
/// `at` may be called from several threads.
class FreeRotation {
 public:
  /// Throws std::invalid_argument for a non-finite or non-symmetric J_b (relative asymmetry
  /// > 1e-12), eigenvalues <= 0 or violating the triangle inequality (J1 + J2 >= J3, within
  /// rounding), a non-finite omega, or a quaternion whose norm is not 1 within 1e-9.
  FreeRotation(const Eigen::Matrix3d& inertia_body, const Rotation& q0, const Vec3& omega0);

  /// The state at time t (t may be negative). Exact up to the rounding of the elliptic functions
  /// and of the quadrature: L and T are conserved to ~1e-14 relative at any t; against an Odeint
  /// integration the state agrees to the integrator's own error (5e-11 over <= 20 periods,
  /// tests/test_free_rotation.cpp). Near the separatrix (k' = sqrt(1 - k^2) -> 0) the motion is
  /// ill-conditioned and the phase error grows like eps / k'^2 per period. Costs 3-30 us.
  /// Thread-safe (no mutable state).
  RotationState at(double t) const;

  /// Period of the body-frame angular velocity [s]: 4 K(k) / omega_p (2 pi / omega_p for a
  /// symmetric top); infinity for a steady rotation (rest, spherical top, principal axis) and on
  /// the separatrix. The orientation is not periodic in general (the angle about L is not).
  double period() const;

  Vec3 angular_momentum() const;  ///< L, world frame [kg m^2/s]: constant
  double kinetic_energy() const;  ///< T = Omega . L / 2 [J]: constant

 private:
  struct Impl;  // principal frame, L, T and the parameters of the closed form
  std::shared_ptr<const Impl> impl_;
};

}  // namespace asperity
