#pragma once
// Screening (paper, Sec. V: "smaller asperities would be screened by larger ones"): which
// asperities of a rough SPHERE with unequal radii can touch the plate in some orientation.
//
// Asperity j touches for the down direction d iff it maximises h_i = c_i.d + rho_i. With unit
// centres u_i = c_i/R and s_i = rho_i/R, j can touch iff the convex cell
//   C_j = { x in R^3 : (u_j - u_i).x >= s_i - s_j  for all i }
// meets the unit sphere. C_j contains t u_j for every large t (all u_i lie on the unit sphere), so
// by convexity C_j meets the sphere iff it meets the closed unit ball B. Restricting to the cap
// u_j.x >= 1 - delta_j of directions where j can possibly win (delta_j from the largest empty cap
// of the centres and the radius spread, below) keeps that argument and makes it local, and by
// Helly's theorem in R^3 the intersection of B, that half-space and the half-spaces of the
// competitors is empty iff it is empty for B, the cap half-space and some THREE competitors.
//
// Per asperity: (1) competitors = centres close enough that their half-space cuts the cap region
// (exact closed form); (2) witness search: a few relaxation steps look for a direction where j
// wins, confirmed by the exact support query -> kept, certified by a witness; (3) otherwise every
// triple of competitors is tested (min-norm point of 4 half-spaces vs the unit ball): a failing
// triple proves j screened; if none fails, j is kept (certified by Helly). Floating-point
// tolerances always err towards "kept", so the kept set is a (tight) superset of the true one.
#include <cstdint>
#include <vector>

#include "asperity/body.hpp"
#include "asperity/support.hpp"

namespace asperity {

enum class Screen : std::uint8_t {
  screened = 0,    ///< no direction makes it the lowest (proved by a triple of competitors)
  witness = 1,     ///< kept: a direction where it touches was found and checked by the support query
  helly = 2,       ///< kept: every triple of competitors leaves a direction (Helly)
};

struct ScreeningResult {
  std::vector<Screen> status;       ///< per asperity
  std::uint64_t kept = 0, screened = 0, witnessed = 0, helly = 0;
  double area = 0;                  ///< 4 pi R^2 [m^2]
  double lambda = 0;                ///< N / area [1/m^2]
  double lambda_eff = 0;            ///< kept / area: areal density of asperities that can touch [1/m^2]
  double theta_cover = 0;           ///< angular radius of the largest empty cap of the centres [rad]
  double mean_competitors = 0;      ///< after the exact half-space filter
  double seconds = 0;
};

/// Screens a rough sphere (b.base_radius > 0, centres at distance R from the origin). q must be a
/// support index over b. Throws std::invalid_argument for a non-sphere body. Parallel over
/// asperities (OpenMP); the result does not depend on the thread count.
ScreeningResult screen_sphere(const RoughBody& b, const SupportQuery& q);

/// Empirical cross-check: `directions` uniform random down directions (Stream(seed,
/// Purpose::analysis, k)); every winner must be kept.
struct ScreeningCheck {
  std::uint64_t directions = 0;
  std::uint64_t winners_screened = 0;   ///< must be 0
  std::uint64_t distinct_winners = 0;   ///< asperities that won at least once
  std::uint64_t kept_never_hit = 0;     ///< kept but never won (small cells, or too few directions)
};
ScreeningCheck check_screening(const RoughBody& b, const SupportQuery& q, const ScreeningResult& r,
                               std::uint64_t directions, std::uint64_t seed);

}  // namespace asperity
