// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The contact of a rough sphere whose asperity radii take discrete levels (body.hpp,
// RadiusDistribution::Kind::levels or fixed): an exact O(1) fresh-sphere sampler and the exact
// finite-N laws of r_xy and r_x, to test the paper's conjecture that p(r_x) stays Gaussian.
//
// Model: N centres iid uniform on the sphere of radius R, radii iid from the levels (rho_m with
// probability f_m), independent of the positions. With X = (1 - cos theta)/2 (theta from the
// down pole; X is uniform on (0,1)) asperity i reaches h_i - R = rho_i - 2 R X_i below the
// centre, so the touching one maximises rho - 2 R X. For the winner of level k at X = x, every
// other asperity must have X_m > x + (rho_m - rho_k)/(2R): the density of the winner's X is
//   g(x) = sum_k N f_k (1 - G_k(x))^(N-1),  G_k(x) = sum_m f_m clamp(x + (rho_m - rho_k)/(2R), 0, 1),
// piecewise a power of a linear function, integrated in closed form. r_xy = 2 R sqrt(X (1-X)).
#include <cstdint>

#include "asperity/core/body.hpp"
#include "asperity/laws/theory.hpp"

namespace asperity {

/// The contact of one fresh random rough sphere with level radii (fresh_levels_contact).
struct FreshContact {
  Vec3 r{0, 0, 0};       ///< contact point - centre, world frame (down = -z) [m]
  double rho = 0;        ///< radius of the touching asperity [m]
  std::uint32_t level = 0;   ///< its level index
  std::uint32_t examined = 0;  ///< asperities generated (the rest provably cannot touch)
  bool core = false;     ///< the bare central sphere reaches lower than the touching asperity
};

/// The touching asperity of a fresh random rough sphere (N asperities, radius R, level radii),
/// exactly: the centres are generated in order of X by the Renyi representation (as fresh_cap
/// does) with independent radii and azimuths, until rho_max - 2 R X can no longer beat the best.
/// Draws from Stream(seed, Purpose::fresh, drop, 7). Throws std::invalid_argument for a
/// lognormal distribution (unbounded radii: no exact stopping rule), N == 0, or R <= max radius.
FreshContact fresh_levels_contact(std::uint64_t n, double R, const RadiusDistribution& d, std::uint64_t seed,
                                  std::uint64_t drop);

/// Exact finite-N law of r_xy of the touching asperity (name "exact-levels").
Law levels_sphere_rxy(std::uint64_t n, double R, const RadiusDistribution& d);
/// Exact finite-N law of r_x (name "exact-levels"); tabulated once (pchip). `scale` multiplies
/// the variable (tests use 1.05 as a deliberately wrong law). pdf is the table's derivative.
Law levels_sphere_rx(std::uint64_t n, double R, const RadiusDistribution& d, double scale = 1.0);

/// Gaussian of Eq. 18 for an areal density lambda [1/m^2]: sigma^2 = 1/(2 pi lambda).
Law gaussian_rx(double lambda, std::string name);

}  // namespace asperity
