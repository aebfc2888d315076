// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/core/body_impact.hpp"

namespace asperity {

RigidBody world_rigid_body(const RoughBody& b, const Rotation& q) {
  const Eigen::Matrix3d Q = q.toRotationMatrix();
  RigidBody rb;
  rb.mass = b.mass;
  rb.inertia = Q * b.inertia * Q.transpose();
  rb.inertia = 0.5 * (rb.inertia + rb.inertia.transpose());  // exactly symmetric for LDLT
  return rb;
}

BodyImpact body_impact(const RoughBody& b, const SupportQuery& index, const Rotation& q, const Vec3& V, const Vec3& Omega,
                       const Restitution& eps_n, double eps_t) {
  return body_impact(b, index, q, V, Omega, eps_n, TangentialLaw::kinematic(eps_t));
}

BodyImpact body_impact(const RoughBody& b, const SupportQuery& index, const Rotation& q, const Vec3& V, const Vec3& Omega,
                       const Restitution& eps_n, const TangentialLaw& law) {
  BodyImpact out;
  out.contact = make_body_contact(index.support(body_down(q)), b, q);
  ImpactState s;
  s.V = V;
  s.Omega = Omega;
  s.r = out.contact.r;
  s.n = Vec3(0, 0, 1);
  out.result = solve_impact(world_rigid_body(b, q), s, eps_n, law);
  return out;
}

}  // namespace asperity
