// SPDX-License-Identifier: GPL-3.0-or-later
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

#include "asperity/core/body.hpp"
#include "asperity/core/support.hpp"

namespace asperity {

/// The screening verdict of one asperity.
enum class Screen : std::uint8_t {
  screened = 0,    ///< no direction makes it the lowest (proved by a triple of competitors)
  witness = 1,     ///< kept: a direction where it touches was found and checked by the support query
  helly = 2,       ///< kept: every triple of competitors leaves a direction (Helly)
};

/// Which asperities of a body can touch the plate, with the counts and densities derived from it.
struct ScreeningResult {
  std::vector<Screen> status;       ///< per asperity
  ///@{
  /// Counts of the statuses: kept = witnessed + helly (can touch), screened (cannot), witnessed
  /// (kept with a checked direction), helly (kept without proof); kept + screened = N.
  std::uint64_t kept = 0, screened = 0, witnessed = 0, helly = 0;
  ///@}
  double area = 0;                  ///< 4 pi R^2 [m^2]
  double lambda = 0;                ///< N / area [1/m^2]
  double lambda_eff = 0;            ///< kept / area: areal density of asperities that can touch [1/m^2]
  double theta_cover = 0;           ///< angular radius of the largest empty cap of the centres [rad]
  double mean_competitors = 0;      ///< after the exact half-space filter
  double seconds = 0;               ///< wall-clock time of the screening [s]
};

/// Screens a rough sphere (b.base_radius > 0, centres at distance R from the origin). q must be a
/// support index over b. Throws std::invalid_argument for a non-sphere body. Parallel over
/// asperities (OpenMP); the result does not depend on the thread count.
ScreeningResult screen_sphere(const RoughBody& b, const SupportQuery& q);

/// Screening of a GENERAL rough body (mesh bodies, with or without a smooth surface map; spheres
/// too). Same question, centres c_i and radii rho_i in metres: j can touch iff
///   C_j = { x : (c_j - c_i).x >= rho_i - rho_j  for all i }
/// meets the unit sphere S. The sphere argument "C_j contains t u_j for large t" needs
/// (c_j - c_i).n_j > 0 for all i, which fails on flat facets (coplanar centres: = 0). What holds for
/// any body: C_j is convex, so it meets S iff it meets the closed unit ball B AND is not inside the
/// open ball. The second part holds whenever C_j is unbounded, i.e. its recession cone
/// {x : (c_j - c_i).x >= 0} is not {0}, i.e. c_j is not in the interior of conv{c_i}: true for every
/// centre on the boundary of a CONVEX base body, flat facets included (there C_j is a prism along
/// the facet normal). Hence:
///  * screened  <=> C_j misses B, for centres on a convex surface; and C_j missing B PROVES
///    screening for any body (S lies in B), so a "screened" verdict never depends on convexity.
///  * Locality: a subset S_j of the competitors gives C_j^S containing C_j, so "C_j^S misses B" is
///    a proof as well. By Helly in R^3 the family {B, half-spaces of S_j} is empty iff some four of
///    its members are; for centres on a convex surface C_j^S is not empty (c_j is an extreme
///    point; on a flat facet the problem is planar with Helly number 3), so the four include B:
///    a TRIPLE of competitors missing B is the certificate (min-norm point of <= 3 active planes,
///    as for spheres; tolerances favour "meets", i.e. "kept").
/// Choice of S_j (cutting planes from the exact support query, "the asperities that win around
/// n_j"): start with the centres within L0 = sqrt(neighbours * area / (pi N)) of c_j (q.within)
/// and the direction n_j = the smallest principal axis of those centres, oriented by n.c_j > 0.
/// Repeat: relax d on S towards C_j^S (over-relaxed rotations towards the most violated
/// half-space); ask the support query who wins at d. If d is in C_j^S and j wins (h_j >= max h):
/// kept, WITNESS. Otherwise, if the winner is new, its half-space (violated at d) joins S_j, also
/// when the relaxation stalled (thin or empty cells: this is what finds the far large asperities
/// on flat faces). When the winner repeats (or after max_rounds), triples of S_j are tried, most
/// violated at d first: one missing B screens j. The
/// winners near the directions where j could win are exactly the asperities that cut its cell,
/// so S_j is usually enough; on flat faces, where a large asperity screens small ones at any
/// distance, the winners found are those far ones. If no triple fails, j is kept WITHOUT proof
/// (status helly, counted separately): C_j^S meets B, but a competitor outside S_j may still
/// close the cell (then j is over-kept, never wrongly screened), and for centres inside the hull
/// of others (non-convex bases) the ball test itself cannot see C_j inside the open ball.
/// Lifted to 4D, (c_i, rho_i), j can touch iff it is a vertex of their hull AND its normal cone
/// meets the light cone {(d, 1) : |d| = 1}; the hull alone decides nothing, so no CGAL hull is used.
/// CGAL's exact QP solver (QP_functions.h) could compute min |x| over C_j^S exactly; it answers the
/// same question as the Helly triples (reused from screen_sphere, cheap for ~30 competitors) and
/// would not remove the locality gap behind "kept without proof".
struct BodyScreeningOptions {
  std::uint32_t neighbours = 24;   ///< expected number of initial local competitors (sets L0)
  std::uint32_t max_rounds = 48;   ///< support queries per asperity (cutting planes)
};

/// Screens any rough body (b.area > 0 for lambda; spheres with b.area == 0 use 4 pi R^2). q must
/// be a support index over b. Status witness: kept, direction checked by q; screened: a triple of
/// competitors proves C_j misses B; helly: kept because no proof was found. theta_cover is NaN
/// (no cap bound for general bodies); mean_competitors = mean |S_j|. Parallel (OpenMP) over
/// asperities; the result does not depend on the thread count.
ScreeningResult screen_body(const RoughBody& b, const SupportQuery& q, const BodyScreeningOptions& o = {});

/// Empirical cross-check: `directions` uniform random down directions (Stream(seed,
/// Purpose::analysis, k)); every winner must be kept.
struct ScreeningCheck {
  std::uint64_t directions = 0;         ///< random down directions tried
  std::uint64_t winners_screened = 0;   ///< must be 0
  std::uint64_t distinct_winners = 0;   ///< asperities that won at least once
  std::uint64_t kept_never_hit = 0;     ///< kept but never won (small cells, or too few directions)
};
/// Draws `directions` uniform down directions from Stream(seed, Purpose::analysis, k), asks q for
/// the winner of each and counts, against r (from screen_sphere or screen_body over b), winners
/// that r screened (a bug if any) and kept asperities that never won. Serial; r.status must have
/// one entry per asperity of b.
ScreeningCheck check_screening(const RoughBody& b, const SupportQuery& q, const ScreeningResult& r,
                               std::uint64_t directions, std::uint64_t seed);

}  // namespace asperity
