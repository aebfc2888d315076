#pragma once
// Laws of the paper's Sec. IV for the macroscopic restitution coefficient eps and the spin after
// the impact, each "as printed" and "as corrected" (derivations in docs/sec4-derivations.md).
//
// Frame (impact.hpp): z up, plate normal n = +z, the body approaches with V = (0, 0, -u), u > 0,
// spin Omega = (Omega_x, Omega_y, 0). Contact vector r = (r_x, r_y, r_z), r_z ~ -(R + a); the
// flat-cap Poisson model of Sec. III gives r_x, r_y iid Normal(0, sigma^2), sigma^2 = 1/(2 pi lambda).
// Mass properties: J = (2/5) M R^2 (central sphere), I_g = J/M = (2/5) R^2. eps_t = 1.
#include <cstdint>
#include <string>

#include "asperity/restitution.hpp"
#include "asperity/theory.hpp"

namespace asperity {

struct ImpactScene {
  std::uint64_t asperities = 100000;  ///< N
  double radius = 3e-3;               ///< R [m]
  double asperity_radius = 6.5e-7;    ///< a [m]
  double speed = 1.3;                 ///< u = -V.n > 0 [m/s]
  double omega_x = 0.2;               ///< [rad/s]
  double omega_y = 0.0;               ///< [rad/s]
  double beta = 0.0467;               ///< Pade [1/4] material constant [(s/m)^(1/5)]
};

/// Distribution of eps. Names: "eq28-printed", "eq28-corrected".
Law eq28_printed(const ImpactScene& s);
Law eq28_corrected(const ImpactScene& s);

/// Distribution of Omega'_x. Names: "eq33-printed", "eq33-corrected" (Gaussians).
Law eq33_printed(const ImpactScene& s);
Law eq33_corrected(const ImpactScene& s);

}  // namespace asperity
