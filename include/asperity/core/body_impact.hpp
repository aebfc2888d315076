// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A single impact of a general rough body (body.hpp) on the plate, with its full inertia tensor:
// the touching asperity from the exact support query, J rotated into the world frame
// (J_world = Q J_body Q^T), r = Q (c_i + rho_i d), and the general 3x3 solve of impact.hpp.
#include <optional>

#include "asperity/core/body.hpp"
#include "asperity/core/impact.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/support.hpp"
#include "asperity/core/tangential.hpp"

namespace asperity {

/// The outcome of body_impact: where the body touched, and the impact if there was one.
struct BodyImpact {
  BodyContact contact;                 ///< world-frame contact
  std::optional<ImpactResult> result;  ///< nullopt: the contact point does not approach the plate
};

/// Rigid body of b at orientation q (body -> world): mass and world-frame inertia.
RigidBody world_rigid_body(const RoughBody& b, const Rotation& q);

/// The impact of b (index q_index over it) at orientation q with centre-of-mass velocity V and
/// spin Omega (world frame, SI) on the plate n = +z.
BodyImpact body_impact(const RoughBody& b, const SupportQuery& index, const Rotation& q, const Vec3& V, const Vec3& Omega,
                       const Restitution& eps_n, double eps_t = 1.0);
/// The same under any tangential law (core/tangential.hpp): eps_n is the microscopic normal
/// coefficient of the law's normal rule (Walton's e_n), as in solve_impact(const RigidBody&, const
/// ImpactState&, const Restitution&, const TangentialLaw&).
BodyImpact body_impact(const RoughBody& b, const SupportQuery& index, const Rotation& q, const Vec3& V, const Vec3& Omega,
                       const Restitution& eps_n, const TangentialLaw& law);

}  // namespace asperity
