// SPDX-License-Identifier: GPL-3.0-or-later
// A downstream DEM contact model: finds the touching asperity and resolves the impulse using only
// core headers (asperity/core/...), so it builds against asperity::core alone.
#include <asperity/core/contact.hpp>
#include <asperity/core/geometry.hpp>
#include <asperity/core/impact.hpp>

#include <cmath>
#include <iostream>

int main() {
  const auto body = asperity::make_rough_sphere({1000, 3e-3, 6.5e-7}, 1, 0);
  const auto index = asperity::make_contact_query(asperity::Backend::grid, body.centres);
  const asperity::Vec3 down(0, 0, -1);
  const auto n = index->lowest(down);
  const bool ok = n == asperity::brute_lowest(body.centres, down);
  std::cout << "lowest asperity " << n.index << (ok ? " (matches brute force)" : " (MISMATCH)") << "\n";

  asperity::ImpactState s;
  s.r = 3e-3 * body.centres[n.index];
  const auto hit = asperity::solve_impact(asperity::RigidBody::sphere(1e-3, 3e-3), s, 0.9);
  const bool impulse_ok = hit && std::isfinite(hit->eps) && hit->P.z() > 0;
  std::cout << "impulse " << (impulse_ok ? "resolved" : "FAILED") << "\n";
  return ok && impulse_ok ? 0 : 1;
}
