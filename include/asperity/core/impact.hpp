// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The collision of a rigid rough body with a flat plate as an instantaneous impulse (paper Eqs.
// 3-7). Frame: the world frame of orientation.hpp, z UP; the plate's unit normal n points OUT of
// the plate, towards the body (n = +z for a horizontal plate). r is the contact vector from the
// centre of mass to the contact point. The body approaches when the normal contact velocity
// v_n = (V + Omega x r) . n is negative. The impulse P acts on the body (P . n > 0).
//
// Contact law (Eq. 5): v'_n = -eps_n v_n and v'_t = eps_t v_t (tangential contact velocity);
// eps_t = 1 keeps v_t unchanged (what the paper calls "elastic no-slip"), eps_t = 0 is sticking,
// eps_t = -1 reverses it. Units: SI (kg, kg m^2, m, m/s, rad/s, N s).
#include <Eigen/Core>
#include <optional>

#include "asperity/core/geometry.hpp"
#include "asperity/core/restitution.hpp"

namespace asperity {

/// Mass properties. For the paper's sphere, inertia = (2/5) M R^2 (central sphere only: the
/// asperities' mass is neglected, Sec. II).
struct RigidBody {
  double mass = 1;                             ///< M [kg]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();  ///< J about the centre of mass, world frame [kg m^2]

  /// A solid homogeneous sphere: M = mass [kg], J = (2/5) M R^2 I with R = radius [m]. Throws
  /// std::invalid_argument unless both are finite and > 0.
  static RigidBody sphere(double mass, double radius);
};

/// The body's motion just before the impact and where it touches (world frame, SI).
struct ImpactState {
  Vec3 V{0, 0, -1};      ///< centre-of-mass velocity before [m/s]
  Vec3 Omega{0, 0, 0};   ///< angular velocity before [rad/s]
  Vec3 r{0, 0, -1e-3};   ///< contact vector [m]
  Vec3 n{0, 0, 1};       ///< unit plate normal, out of the plate
};

/// The motion just after the impact, and the numbers that produced it.
struct ImpactResult {
  Vec3 P;           ///< impulse on the body [N s]
  Vec3 V_after;     ///< [m/s]
  Vec3 Omega_after; ///< [rad/s]
  double v_n = 0;   ///< normal contact velocity before (< 0) [m/s]
  double eps_n = 0; ///< microscopic coefficient used, eps_n(|v_n|)
  double eps = 0;   ///< macroscopic coefficient, Eq. 1: -V'.n / V.n
};

/// General solve of Eq. 7 for any inertia tensor: with [r]x the cross-product matrix,
/// Delta v = (1/M - [r]x J^-1 [r]x) P, a symmetric positive-definite 3x3 system (Eigen LDLT).
/// Returns nullopt when there is no impact (v_n >= 0: the contact point does not approach the
/// plate), and throws std::invalid_argument for non-finite input, |n| != 1, or V.n == 0 (eps of
/// Eq. 1 undefined).
std::optional<ImpactResult> solve_impact(const RigidBody& body, const ImpactState& s, double eps_n, double eps_t = 1.0);
/// The same with a speed-dependent microscopic coefficient: eps_n is evaluated at the normal
/// contact speed |v_n| before the impact (ImpactResult::eps_n records the value used).
std::optional<ImpactResult> solve_impact(const RigidBody& body, const ImpactState& s, const Restitution& eps_n,
                                         double eps_t = 1.0);

/// Closed form for an isotropic body (J = M I_g, scalar I_g = J/M), by Sherman-Morrison:
/// P = M/(I_g + r^2) (I_g Delta v + r (r . Delta v)). Same contract as solve_impact.
std::optional<ImpactResult> solve_impact_isotropic(double mass, double inertia, const ImpactState& s, double eps_n,
                                                   double eps_t = 1.0);

}  // namespace asperity
