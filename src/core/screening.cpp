// SPDX-License-Identifier: GPL-3.0-or-later
// Screening of unequal asperities on a rough sphere: exact local tests (see screening.hpp).
#include "asperity/core/screening.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

#include "asperity/core/parallel_errors.hpp"
#include "asperity/core/random.hpp"

namespace asperity {
namespace {

// cos of the angular radius of the largest empty spherical cap of the unit centres: the largest
// circumcap of the facets of their convex hull (the spherical Delaunay triangulation). Returns
// -1 (everything may compete) when the hull does not enclose the origin (tiny N).
double cos_cover(const std::vector<Vec3>& u) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using P = K::Point_3;
  if (u.size() < 4) return -1.0;
  std::vector<P> pts;
  pts.reserve(u.size());
  for (const Vec3& v : u) pts.emplace_back(v.x(), v.y(), v.z());
  CGAL::Surface_mesh<P> hull;
  CGAL::convex_hull_3(pts.begin(), pts.end(), hull);
  if (hull.number_of_faces() < 4) return -1.0;
  double cmin = 1.0;
  for (auto f : hull.faces()) {
    auto h = hull.halfedge(f);
    const P& pa = hull.point(hull.target(h));
    const P& pb = hull.point(hull.target(hull.next(h)));
    const P& pc = hull.point(hull.target(hull.next(hull.next(h))));
    Vec3 a(pa.x(), pa.y(), pa.z()), b(pb.x(), pb.y(), pb.z()), c(pc.x(), pc.y(), pc.z());
    // CGAL does not fix which vertex starts a face (two hulls of the same points differed), and
    // the rounding of n depends on it: start at the lexicographically smallest vertex (a rotation,
    // the orientation kept) so that the result is a function of the points alone.
    const auto less = [](const Vec3& x, const Vec3& y) { return std::lexicographical_compare(x.data(), x.data() + 3, y.data(), y.data() + 3); };
    if (less(b, a) && !less(c, b)) std::tie(a, b, c) = std::make_tuple(b, c, a);
    else if (less(c, a) && less(c, b)) std::tie(a, b, c) = std::make_tuple(c, a, b);
    const Vec3 n = (b - a).cross(c - a);
    const double nn = n.norm();
    if (!(nn > 0)) return -1.0;
    const double cf = std::min({n.dot(a), n.dot(b), n.dot(c)}) / nn;
    if (cf <= 0) return -1.0;
    cmin = std::min(cmin, cf);
  }
  return cmin;
}

struct HalfSpace {
  Vec3 n;
  double beta;  // n.x >= beta
};

// Least-norm point of { x : n_k.x = beta_k, k in S } for |S| <= 3; false if degenerate.
bool least_norm(const HalfSpace* const* s, int m, Vec3& x) {
  if (m == 0) {
    x.setZero();
    return true;
  }
  if (m == 1) {
    const double nn = s[0]->n.squaredNorm();
    if (!(nn > 0)) return false;
    x = (s[0]->beta / nn) * s[0]->n;
    return true;
  }
  if (m == 2) {
    const Vec3 &a = s[0]->n, &b = s[1]->n;
    const double g00 = a.dot(a), g01 = a.dot(b), g11 = b.dot(b);
    const double det = g00 * g11 - g01 * g01;
    if (!(det > 1e-13 * g00 * g11)) return false;
    const double l0 = (g11 * s[0]->beta - g01 * s[1]->beta) / det;
    const double l1 = (g00 * s[1]->beta - g01 * s[0]->beta) / det;
    x = l0 * a + l1 * b;
    return true;
  }
  const Vec3 &a = s[0]->n, &b = s[1]->n, &c = s[2]->n;
  const Vec3 bc = b.cross(c), ca = c.cross(a), ab = a.cross(b);
  const double det = a.dot(bc);
  if (!(std::abs(det) > 1e-12 * a.norm() * b.norm() * c.norm())) return false;
  x = (s[0]->beta * bc + s[1]->beta * ca + s[2]->beta * ab) / det;
  return true;
}

// Does the intersection of the unit ball with the given half-spaces (at most 4) have a point?
// Its min-norm point is the least-norm point of some subset of <= 3 active constraints (KKT),
// so the smallest feasible candidate norm is the exact minimum. Tolerances favour "yes".
bool ball_meets(const HalfSpace* hs, int m) {
  const HalfSpace* sub[3];
  double best = std::numeric_limits<double>::infinity();
  for (int mask = 0; mask < (1 << m); ++mask) {
    const int bits = __builtin_popcount(static_cast<unsigned>(mask));
    if (bits > 3) continue;
    int k = 0;
    for (int i = 0; i < m; ++i)
      if (mask & (1 << i)) sub[k++] = &hs[i];
    Vec3 x;
    if (!least_norm(sub, bits, x)) continue;
    bool ok = true;
    for (int i = 0; i < m && ok; ++i) ok = hs[i].n.dot(x) >= hs[i].beta - 1e-12 * (hs[i].n.norm() + std::abs(hs[i].beta));
    if (ok) best = std::min(best, x.squaredNorm());
  }
  return best <= 1.0 + 1e-10;
}

// Helly in R^3: the ball, the `fixed` half-spaces (0 or 1) and the competitors have an empty
// intersection iff the ball, the fixed ones and some THREE competitors do (all of them if fewer).
bool some_triple_misses_ball(const HalfSpace* fixed, int nfixed, const std::vector<HalfSpace>& comp) {
  HalfSpace hs[4];
  for (int i = 0; i < nfixed; ++i) hs[i] = fixed[i];
  const int k = static_cast<int>(comp.size());
  if (k < 3) {
    for (int i = 0; i < k; ++i) hs[nfixed + i] = comp[static_cast<std::size_t>(i)];
    return !ball_meets(hs, nfixed + k);
  }
  for (int z = 2; z < k; ++z)
    for (int y = 1; y < z; ++y)
      for (int x = 0; x < y; ++x) {
        hs[nfixed] = comp[static_cast<std::size_t>(x)];
        hs[nfixed + 1] = comp[static_cast<std::size_t>(y)];
        hs[nfixed + 2] = comp[static_cast<std::size_t>(z)];
        if (!ball_meets(hs, nfixed + 3)) return true;
      }
  return false;
}

// Counts by status, lambda_eff and the mean number of competitors.
void tally(ScreeningResult& r, const std::vector<std::uint32_t>& ncomp) {
  const std::size_t n = ncomp.size();
  double comp_sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    comp_sum += ncomp[i];
    switch (r.status[i]) {
      case Screen::screened: ++r.screened; break;
      case Screen::witness: ++r.witnessed; break;
      case Screen::helly: ++r.helly; break;
    }
  }
  r.kept = r.witnessed + r.helly;
  r.lambda_eff = r.area > 0 ? static_cast<double>(r.kept) / r.area : 0.0;
  r.mean_competitors = n ? comp_sum / static_cast<double>(n) : 0.0;
}

}  // namespace

namespace {

// Competitors of asperity j on a sphere: the centres within L R whose half-space is not satisfied
// everywhere in the cap region {|x| <= 1, u_j.x >= c} where j can win.
std::vector<HalfSpace> cap_competitors(const RoughBody& b, const SupportQuery& q, const std::vector<Vec3>& u,
                                       const std::vector<double>& sr, std::uint32_t j, double c, double S, double L) {
  const Vec3& uj = u[j];
  std::vector<HalfSpace> comp;
  for (std::uint32_t i : q.within(b.centres[j], L * b.base_radius)) {
    if (i == j) continue;
    const Vec3 a = uj - u[i];
    const double beta = sr[i] - sr[j];
    if (c > 0) {
      // min over the cap region of a.x, on its rim.
      const double au = a.dot(uj);
      const double perp = std::sqrt(std::max(0.0, a.squaredNorm() - au * au));
      if (c * au - S * perp - beta > 1e-13) continue;  // satisfied everywhere in the region
    }
    comp.push_back({a, beta});
  }
  return comp;
}

// Witness search: over-relaxed projections onto the most violated constraint, on the sphere; true
// if a direction where j wins is found (confirmed by the exact support query).
bool cap_witness(const RoughBody& b, const SupportQuery& q, const std::vector<HalfSpace>& comp, std::uint32_t j,
                 const Vec3& uj, double c) {
  Vec3 d = uj;
  for (int it = 0; it < 200; ++it) {
    double worst = 0;
    const HalfSpace* w = nullptr;
    for (const HalfSpace& h : comp) {
      const double v = h.n.dot(d) - h.beta;
      if (v < worst) worst = v, w = &h;
    }
    if (!w) return support_value(b.centres[j], b.radii[j], d) >= q.support(d).h;
    d += 1.5 * (-worst / w->n.squaredNorm()) * w->n;
    d.normalize();
    if (d.dot(uj) < c) return false;  // left the region where j can win
  }
  return false;
}

}  // namespace

ScreeningResult screen_sphere(const RoughBody& b, const SupportQuery& q) {
  const auto t0 = std::chrono::steady_clock::now();
  const double R = b.base_radius;
  if (!(R > 0)) throw std::invalid_argument("screen_sphere: body '" + b.name + "' is not a rough sphere (base radius 0)");
  const std::size_t n = b.size();
  std::vector<Vec3> u(n);
  std::vector<double> sr(n);
  double s_min = std::numeric_limits<double>::infinity(), s_max = 0;
  for (std::size_t i = 0; i < n; ++i) {
    u[i] = b.centres[i] / R;
    sr[i] = b.radii[i] / R;
    s_min = std::min(s_min, sr[i]);
    s_max = std::max(s_max, sr[i]);
  }
  const double ccov = cos_cover(u);
  // Padded: the region bound must never be too small.
  const double delta_cov = (1.0 - ccov) * (1 + 1e-9) + 1e-15;

  ScreeningResult r;
  r.status.assign(n, Screen::helly);
  r.area = 4.0 * std::numbers::pi * R * R;
  r.lambda = static_cast<double>(n) / r.area;
  r.theta_cover = std::acos(std::max(-1.0, ccov));
  std::vector<std::uint32_t> ncomp(n, 0);

  const auto N = static_cast<std::int64_t>(n);
  LowestIndexError errors;  // an allocation failure must not leave the region (std::terminate)
#pragma omp parallel for schedule(dynamic, 64)
  for (std::int64_t jj = 0; jj < N; ++jj) errors.run(jj, [&] {
    const auto j = static_cast<std::uint32_t>(jj);
    const Vec3& uj = u[j];
    // j can only win at d with 1 - u_j.d <= delta_cov + s_j - s_min (the nearest centre to d is
    // within the largest empty cap, and it has s >= s_min).
    const double delta = (delta_cov + (sr[j] - s_min)) * (1 + 1e-9) + 1e-15;
    const double c = 1.0 - delta;
    const double S = c > 0 ? std::sqrt(std::max(0.0, 1.0 - c * c)) : 1.0;
    const double bmax = s_max - sr[j];
    double L = c > 0 ? (S + std::sqrt(S * S + 2.0 * c * bmax)) / c : 2.1;
    L = std::min(2.1, L * (1 + 1e-9) + 1e-12);
    std::vector<HalfSpace> comp = cap_competitors(b, q, u, sr, j, c, S, L);
    ncomp[j] = static_cast<std::uint32_t>(comp.size());
    // Most threatening (most violated at d = u_j) first: certificates of screening come early.
    std::sort(comp.begin(), comp.end(), [&](const HalfSpace& x, const HalfSpace& y) {
      return x.beta - x.n.dot(uj) > y.beta - y.n.dot(uj);
    });

    const bool won = cap_witness(b, q, comp, j, uj, c);
    if (won) {
      r.status[j] = Screen::witness;
      return;
    }
    // Helly: the unit ball, the region half-space and every triple of competitors.
    const HalfSpace region{uj, c};
    if (some_triple_misses_ball(&region, 1, comp)) r.status[j] = Screen::screened;
  });
  errors.rethrow();
  tally(r, ncomp);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

namespace {

// Local competitors of asperity j: the asperities within a radius holding ~neighbours of them
// (doubled until at least 4), or all of them on small bodies.
std::vector<std::uint32_t> local_competitors(const RoughBody& b, const SupportQuery& q, std::uint32_t j, bool all_compete,
                                             double L0) {
  std::vector<std::uint32_t> nb;
  if (all_compete) {
    nb.resize(b.size());
    for (std::size_t i = 0; i < b.size(); ++i) nb[i] = static_cast<std::uint32_t>(i);
    return nb;
  }
  double L = L0;
  for (int t = 0; t < 8; ++t, L *= 2) {
    nb = q.within(b.centres[j], L);
    if (nb.size() >= 4) break;
  }
  return nb;
}

// Start direction: normal of the local centre cloud (smallest principal axis), outward.
Vec3 start_direction(const RoughBody& b, const std::vector<std::uint32_t>& nb, const Vec3& cj) {
  Vec3 nj = cj.squaredNorm() > 0 ? Vec3(cj.normalized()) : Vec3(0, 0, 1);
  if (nb.size() >= 3) {
    Vec3 mean = Vec3::Zero();
    for (std::uint32_t i : nb) mean += b.centres[i];
    mean /= static_cast<double>(nb.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (std::uint32_t i : nb) cov += (b.centres[i] - mean) * (b.centres[i] - mean).transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    es.computeDirect(cov);
    const Vec3 v = es.eigenvectors().col(0);
    if (v.allFinite() && v.squaredNorm() > 0.5) nj = v.normalized();
  }
  if (nj.dot(cj) < 0) nj = -nj;
  return nj;
}

// Projections onto the most violated half-space, back on the sphere; true once d is in C^S.
bool relax_on_sphere(const std::vector<HalfSpace>& comp, Vec3& d, int iterations) {
  for (int it = 0; it < iterations; ++it) {
    double worst = 0;
    const HalfSpace* w = nullptr;
    for (const HalfSpace& h : comp) {
      const double v = h.n.dot(d) - h.beta;
      if (v < worst) worst = v, w = &h;
    }
    if (!w) return true;
    // Over-relaxed projection ON the sphere: rotate d towards the plane's normal a, by 1.5 times
    // the angle that puts it on the boundary (a chord step then a normalisation converges
    // slowly when the allowed cap is small).
    const double an = w->n.norm();
    if (!(an > 0) || w->beta > an) return false;  // infeasible on its own
    const Vec3 ah = w->n / an;
    const double c = ah.dot(d);
    Vec3 t = d - c * ah;
    const double tn = t.norm();
    const double phi = std::atan2(tn, c), phit = std::acos(std::max(-1.0, w->beta / an));
    const double phin = std::max(0.0, phi - 1.5 * (phi - phit) - 1e-13);
    d = std::cos(phin) * ah + (tn > 0 ? (std::sin(phin) / tn) * t : Vec3(ah.unitOrthogonal() * std::sin(phin)));
  }
  return false;
}

// Relaxation rounds with cutting planes from the exact support query: true if a direction where
// j wins was found (a witness). Each round's winner, if new, joins the competitors.
bool find_witness(const RoughBody& b, const SupportQuery& q, std::uint32_t j, std::vector<HalfSpace>& comp,
                  std::vector<std::uint32_t>& ids, Vec3& d, std::uint32_t max_rounds) {
  const Vec3& cj = b.centres[j];
  const double rj = b.radii[j];
  for (std::uint32_t round = 0; round < max_rounds; ++round) {
    // Even where the relaxation has not converged (thin cells), the winner at d is a competitor
    // worth adding: the set grows towards the asperities that close j's cell.
    const bool feasible = relax_on_sphere(comp, d, round == 0 ? 200 : 48);
    const Support sp = q.support(d);
    if (feasible && support_value(cj, rj, d) >= sp.h) return true;
    // No progress: the winner is already a competitor (d violates its half-space, or rounding).
    if (sp.index == j || std::find(ids.begin(), ids.end(), sp.index) != ids.end()) return false;
    comp.push_back({cj - b.centres[sp.index], b.radii[sp.index] - rj});
    ids.push_back(sp.index);
  }
  return false;
}

// A Helly triple of competitors that misses the ball proves j screened. Tried most violated at d
// first, as an angle (far competitors have long normals), so certificates come early.
bool helly_certificate(std::vector<HalfSpace> comp, const Vec3& d) {
  // x = 0 satisfies every half-space with beta <= 0: C^S meets B, no triple can fail.
  if (std::all_of(comp.begin(), comp.end(), [](const HalfSpace& h) { return h.beta <= 0; })) return false;
  std::vector<std::pair<double, std::size_t>> order(comp.size());
  for (std::size_t i = 0; i < comp.size(); ++i) {
    const double an = comp[i].n.norm();
    order[i] = {an > 0 ? (comp[i].beta - comp[i].n.dot(d)) / an : std::numeric_limits<double>::infinity(), i};
  }
  std::sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first > y.first || (x.first == y.first && x.second < y.second); });
  std::vector<HalfSpace> sorted(comp.size());
  for (std::size_t i = 0; i < comp.size(); ++i) sorted[i] = comp[order[i].second];
  return some_triple_misses_ball(nullptr, 0, sorted);
}

void check_body_screening(const RoughBody& b, const BodyScreeningOptions& o) {
  if (o.neighbours < 3) throw std::invalid_argument("screen_body: neighbours must be >= 3, got " + std::to_string(o.neighbours));
  if (o.max_rounds < 1) throw std::invalid_argument("screen_body: max_rounds must be >= 1, got 0");
  if (b.radii.size() != b.centres.size())
    throw std::invalid_argument("screen_body: body '" + b.name + "' has " + std::to_string(b.centres.size()) + " centres but " +
                                std::to_string(b.radii.size()) + " radii");
}

}  // namespace

ScreeningResult screen_body(const RoughBody& b, const SupportQuery& q, const BodyScreeningOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  check_body_screening(b, o);
  const std::size_t n = b.size();
  ScreeningResult r;
  r.status.assign(n, Screen::helly);
  r.area = b.area > 0 ? b.area : (b.base_radius > 0 ? 4.0 * std::numbers::pi * b.base_radius * b.base_radius : 0.0);
  r.lambda = r.area > 0 ? static_cast<double>(n) / r.area : 0.0;
  r.theta_cover = std::numeric_limits<double>::quiet_NaN();
  // Small bodies: every asperity competes (also covers hand-made bodies without an area).
  const bool all_compete = n <= 64 || !(r.area > 0);
  const double L0 = all_compete ? 0.0 : std::sqrt(o.neighbours * r.area / (std::numbers::pi * static_cast<double>(n)));
  std::vector<std::uint32_t> ncomp(n, 0);

  const auto N = static_cast<std::int64_t>(n);
  LowestIndexError errors;
#pragma omp parallel for schedule(dynamic, 64)
  for (std::int64_t jj = 0; jj < N; ++jj) errors.run(jj, [&] {
    const auto j = static_cast<std::uint32_t>(jj);
    const Vec3& cj = b.centres[j];
    const std::vector<std::uint32_t> nb = local_competitors(b, q, j, all_compete, L0);
    std::vector<HalfSpace> comp;
    std::vector<std::uint32_t> ids;
    comp.reserve(nb.size() + o.max_rounds);
    for (std::uint32_t i : nb) {
      if (i == j) continue;
      comp.push_back({cj - b.centres[i], b.radii[i] - b.radii[j]});
      ids.push_back(i);
    }
    Vec3 d = start_direction(b, nb, cj);
    const bool won = find_witness(b, q, j, comp, ids, d, o.max_rounds);
    ncomp[j] = static_cast<std::uint32_t>(comp.size());
    if (won)
      r.status[j] = Screen::witness;
    else if (helly_certificate(comp, d))
      r.status[j] = Screen::screened;
  });
  errors.rethrow();
  tally(r, ncomp);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

ScreeningCheck check_screening(const RoughBody& b, const SupportQuery& q, const ScreeningResult& r,
                               std::uint64_t directions, std::uint64_t seed) {
  ScreeningCheck c;
  c.directions = directions;
  std::vector<std::uint8_t> hit(b.size(), 0);
  for (std::uint64_t k = 0; k < directions; ++k) {
    Stream st(seed, Purpose::analysis, k);
    const double u = st.uniform0(), v = st.uniform0();
    const Support s = q.support(uniform_on_sphere(u, v));
    hit[s.index] = 1;
  }
  for (std::size_t i = 0; i < b.size(); ++i) {
    const bool kept = r.status[i] != Screen::screened;
    if (hit[i]) ++c.distinct_winners;
    if (hit[i] && !kept) ++c.winners_screened;
    if (!hit[i] && kept) ++c.kept_never_hit;
  }
  return c;
}

}  // namespace asperity
