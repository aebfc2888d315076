// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/experiments/bounce.hpp"
#include "asperity/core/parallel_errors.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <functional>
#include <span>
#include <ostream>
#include <limits>
#include <locale>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include <boost/sort/pdqsort/pdqsort.hpp>

#include "asperity/core/contact.hpp"
#include "asperity/core/impact.hpp"
#include "asperity/core/lazy_sphere.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/random.hpp"
#include "asperity/core/restitution.hpp"
#include "asperity/core/tangential.hpp"
#include "asperity/laws/theory_impact.hpp"
#include "core/format.hpp"

namespace asperity {

using detail::fmt;
using detail::num;

std::string_view to_string(BounceVariant v) {
  switch (v) {
    case BounceVariant::paper: return "paper";
    case BounceVariant::paper_printed33: return "paper-printed33";
    case BounceVariant::random_orientation: return "random-orientation";
    case BounceVariant::dynamic: return "dynamic";
    case BounceVariant::paper_corrected28: return "paper-corrected28";
  }
  return "?";
}

BounceVariant parse_bounce_variant(std::string_view s) {
  for (auto v : {BounceVariant::paper, BounceVariant::paper_printed33, BounceVariant::random_orientation, BounceVariant::dynamic,
                 BounceVariant::paper_corrected28})
    if (s == to_string(v)) return v;
  throw std::invalid_argument("unknown bounce variant '" + std::string(s) +
                              "' (known: paper, paper-printed33, random-orientation, dynamic, paper-corrected28)");
}

void validate(const BounceExperiment& b) {
  // Messages start with the scene key: the scene reader points at that key's line (a message
  // without one was reported at line 1, issue 33 item 8).
  auto pos = [](const char* f, double v) {
    if (!std::isfinite(v) || !(v > 0)) throw std::invalid_argument(std::string(f) + ": must be finite and > 0, got " + num(v));
  };
  if (b.variants.empty()) throw std::invalid_argument("bounce: no variant selected");
  if (b.sequences < 1 || b.sequences > 0xFFFFFFFFull)
    throw std::invalid_argument("experiment.sequences (--sequences): must be in [1, 2^32 - 1], got " + std::to_string(b.sequences));
  pos("experiment.speed (--speed)", b.speed);
  if (b.speed > kMaxBounceSpeed)
    throw std::invalid_argument("experiment.speed (--speed): " + num(b.speed) + " m/s is outside the supported range (0, " + num(kMaxBounceSpeed) +
                                "] m/s (the collision law of Eq. 9 is quasi-static: far below the speed of sound)");
  if (!b.omega.allFinite()) throw std::invalid_argument("experiment.Omega: must be finite");
  pos("experiment.stop_speed", b.stop_speed);
  if (!(b.stop_speed < b.speed))
    throw std::invalid_argument("experiment.stop_speed: " + num(b.stop_speed) + " must be below the first impact speed " + num(b.speed));
  pos("experiment.gravity", b.gravity);
  if (b.gravity < kMinGravity || b.gravity > kMaxGravity)
    throw std::invalid_argument("experiment.gravity: " + num(b.gravity) + " m/s^2 is outside the supported range [" + num(kMinGravity) +
                                ", " + num(kMaxGravity) + "] m/s^2 (1e-4 g to 1e3 g; the flight time 2 speed/gravity must stay resolvable)");
  pos("material.density", b.density);
  pos("material.restitution.beta", b.beta);
  if (!std::isfinite(b.eps_t) || b.eps_t < -1 || b.eps_t > 1) throw std::invalid_argument("bounce: eps_t must be in [-1, 1], got " + num(b.eps_t));
  validate(b.tangential);
  if (b.max_impacts < 1) throw std::invalid_argument("bounce: max_impacts must be >= 1");
  for (const auto& [lo, hi] : b.windows)
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo >= 0) || !(lo < hi))
      throw std::invalid_argument("bounce: speed window [" + num(lo) + ", " + num(hi) + "] must satisfy 0 <= lo < hi");
  for (unsigned k : b.impact_numbers)
    if (k < 1) throw std::invalid_argument("bounce: impact numbers start at 1, got 0");
  if (!std::isfinite(b.alpha) || !(b.alpha > 0) || !(b.alpha < 1))
    throw std::invalid_argument("bounce: alpha must be in (0, 1), got " + num(b.alpha));
  if (b.bootstrap_draws < 1) throw std::invalid_argument("bounce: bootstrap_draws must be >= 1");
}

namespace {

using Clock = std::chrono::steady_clock;

struct Impact {
  std::uint32_t k;
  double u, eps, eps_time;
  float spin, wx;
  std::uint8_t core;
};

struct SequenceOut {
  std::vector<Impact> impacts;
  std::uint64_t cells = 0, centres = 0;
  bool cut = false;
};

std::pair<double, double> normal_pair(Stream& s) {
  const double r = std::sqrt(-2.0 * std::log(s.uniform())), t = 2.0 * std::numbers::pi * s.uniform0();
  return {r * std::cos(t), r * std::sin(t)};
}

struct Physics {
  std::uint64_t n;
  double R, a, mass, J, g;
  const Restitution* eps_n;
  double beta;
  TangentialLaw law;  // kinematic: the closed form with b.eps_t; else the impulse process
};

// The impact of the explicit variants: the paper's kinematic law in closed form (as before, bit for
// bit), any other tangential law by core/tangential's solve_impact on the same sphere.
std::optional<ImpactResult> sphere_impact(const Physics& p, const ImpactState& st, double e, double eps_t) {
  if (p.law.model == TangentialLaw::Model::kinematic) return solve_impact_isotropic(p.mass, p.J, st, e, eps_t);
  RigidBody body;
  body.mass = p.mass;
  body.inertia = Eigen::Matrix3d::Identity() * p.J;
  return solve_impact(body, st, e, p.law);
}

// The lowest asperity for a down direction d_new that is delta = |d_new - d_old| away from a
// direction already queried. Keys are squared chords, so every other centre keeps
// sqrt(key) >= sqrt(K2) - delta and the winner sqrt(key) <= sqrt(K1) + delta: when those bounds do
// not cross, the winner is unchanged and only its key is recomputed (exactly as a query would);
// otherwise a full query. Saves the second query of the landing-time iteration, where d moves by
// ~1e-9. runner_up_key then becomes a lower bound on every other key (so chained calls stay
// exact), and runner_up is stale: neither is used by the bounce dynamics.
LazyNearest requery(LazySphere& S, const LazyNearest& old, const Vec3& d_old, const Vec3& d_new) {
  const double delta = (d_new - d_old).norm();
  const double k1 = std::sqrt(old.nearest.key) + delta, k2 = std::sqrt(old.nearest.runner_up_key) - delta;
  if (k2 > 0 && k1 * k1 * (1 + 1e-9) < k2 * k2) {
    LazyNearest r = old;
    r.nearest.key = contact_key(old.u, d_new);
    r.nearest.runner_up_key = k2 * k2 / (1 + 1e-9);  // a lower bound for every other centre at d_new
    return r;
  }
  return S.lowest(d_new);
}

double depth(const LazyNearest& L, const Physics& p) { return std::max(p.R, p.R * (1.0 - 0.5 * L.nearest.key) + p.a); }

void run_explicit(std::uint64_t i, BounceVariant v, const BounceExperiment& b, const Physics& p, std::uint64_t seed,
                  LazySphere& S, SequenceOut& out) {
  S.reset(seed, i);
  Stream s0(seed, Purpose::bounce, i, 0);
  Rotation q = random_rotation(s0);
  Vec3 V(0, 0, -b.speed), W(0, 0, 0);
  LazyNearest L = S.lowest(body_down(q));
  double T_prev = std::numeric_limits<double>::quiet_NaN();
  for (std::uint32_t k = 1; k <= b.max_impacts; ++k) {
    const double u = -V.z();
    if (u < b.stop_speed) break;
    const Contact c = make_contact(L.nearest, L.u, q, p.R, p.a);
    ImpactState st;
    st.V = V, st.Omega = W, st.r = c.core ? Vec3(0, 0, -p.R) : c.r, st.n = Vec3(0, 0, 1);
    const double vn = (st.V + st.Omega.cross(st.r)).z();
    if (!(vn < 0)) {
      out.cut = true;
      break;
    }
    const auto res = sphere_impact(p, st, (*p.eps_n)(-vn), b.eps_t);
    if (!res) {  // the process' own test of approach (cannot differ from vn < 0 above by more than rounding)
      out.cut = true;
      break;
    }
    const double h0 = -st.r.z();
    const float spin_before = static_cast<float>(W.norm());
    V = res->V_after, W = res->Omega_after;
    const double vz = V.z();
    double t = 0, v_land = 0;
    Rotation q_land = q;
    if (v == BounceVariant::random_orientation) {
      Stream sk(seed, Purpose::bounce, i, k);
      q_land = random_rotation(sk);
      L = S.lowest(body_down(q_land));
      {
        const Flight f = ballistic_flight(h0, vz, depth(L, p), p.g);
        t = f.time, v_land = f.landing_vz;
      }
    } else {
      // Fixed point t = flight(D(q(t))): D moves by nanometres, so 2-3 steps reach equality.
      t = ballistic_flight(h0, vz, h0, p.g).time;
      Vec3 d_prev;
      for (int it = 0; it < 8; ++it) {
        q_land = advance_rotation(q, W, t);
        const Vec3 d = body_down(q_land);
        L = it == 0 ? S.lowest(d) : requery(S, L, d_prev, d);
        d_prev = d;
        const Flight f = ballistic_flight(h0, vz, depth(L, p), p.g);
        const double tn = f.time, vn_land = f.landing_vz;
        const bool same = tn == t;
        t = tn, v_land = vn_land;
        if (same) break;
      }
    }
    out.impacts.push_back({k, u, res->eps, t / T_prev, spin_before, static_cast<float>(W.x()), static_cast<std::uint8_t>(c.core)});
    V.z() = v_land;
    q = q_land;
    T_prev = t;
  }
  out.cells = S.cells_generated(), out.centres = S.centres_generated();
}

// The paper's Sec. V procedure (bounce.hpp): only Omega_x, eps and Omega'_x drawn per impact.
void run_paper(std::uint64_t i, BounceVariant v, const BounceExperiment& b, const Physics& p, std::uint64_t seed,
               SequenceOut& out) {
  Stream s(seed, Purpose::bounce, i, std::uint64_t{1} << 40);
  double u = b.speed, wx = 0, T_prev = std::numeric_limits<double>::quiet_NaN();
  ImpactScene sc;
  sc.asperities = p.n, sc.radius = p.R, sc.asperity_radius = p.a, sc.beta = p.beta, sc.omega_y = 0;
  for (std::uint32_t k = 1; k <= b.max_impacts; ++k) {
    if (u < b.stop_speed) break;
    sc.speed = u, sc.omega_x = wx;
    const auto q = impact_law_parameters(sc, *p.eps_n);  // the run's Pade law: no allocation per impact
    const auto [g1, g2] = normal_pair(s);
    const double g3 = normal_pair(s).first;
    double eps = 0, wx_after = 0;
    if (v == BounceVariant::paper_corrected28) {
      const double x = q.sigma * g1 + q.shift, y = q.sigma * g2;
      eps = q.eps_max - q.alpha * (x * x + y * y);
      wx_after = wx + q.sigma_c * g3;
    } else {
      const double r_xy = q.sigma * std::hypot(g1, g2);  // Rayleigh(sigma), Eq. 14
      eps = eq28_paper_route_eps(q, u, wx, r_xy);
      const double r_y = q.sigma * g3;                  // Eq. 18, independent of r_xy as in the paper
      wx_after = v == BounceVariant::paper_printed33 ? wx + q.sigma_printed * g3 : wx + (1.0 + eps) * u * r_y / q.c2;
    }
    const double t = 2.0 * eps * u / p.g;
    out.impacts.push_back({k, u, eps, t / T_prev, static_cast<float>(std::abs(wx)), static_cast<float>(wx_after), 0});
    u *= eps, wx = wx_after, T_prev = t;
  }
}

}  // namespace

Eigen::Quaterniond advance_rotation(const Eigen::Quaterniond& q, const Vec3& w, double t) {
  const double wn = w.norm();
  if (wn == 0 || t == 0) return q;
  return (Eigen::Quaterniond(Eigen::AngleAxisd(wn * t, w / wn)) * q).normalized();
}

Flight ballistic_flight(double h0, double vz, double D, double g) {
  const double root = std::sqrt(std::max(0.0, vz * vz + 2.0 * g * (h0 - D)));
  return {(vz + root) / g, -root};
}

namespace {
// Room for all impacts, extrapolated from the first block (+5 %): the append after each block is
// serial, and growing 8 vectors of ~5e6 entries by doubling copies them and faults in their pages
// twice over. Only capacity: a wrong estimate just lets them grow as before.
void reserve_samples(BounceSamples& s, const std::vector<SequenceOut>& outs, std::size_t m, std::uint64_t sequences) {
  std::size_t impacts = 0;
  for (std::size_t j = 0; j < m; ++j) impacts += outs[j].impacts.size();
  const auto n = static_cast<std::size_t>(1.05 * static_cast<double>(impacts) * static_cast<double>(sequences) /
                                          static_cast<double>(std::max<std::size_t>(1, m))) + 1;
  s.sequence.reserve(n), s.number.reserve(n), s.speed.reserve(n), s.eps.reserve(n);
  s.eps_time.reserve(n), s.spin.reserve(n), s.omega_x_after.reserve(n), s.core.reserve(n);
}
}  // namespace

BounceSamples run_bounces(const SphereParams& sphere, const BounceExperiment& b, BounceVariant v, std::uint64_t seed,
                          int threads, const Progress& progress) {
  validate(sphere);
  validate(b);
  if (b.omega != Vec3::Zero())
    throw std::invalid_argument("bounce: the sphere variants start without spin (Omega = 0, Sec. V); Omega is for bodies");
  const auto t0 = Clock::now();
  const auto en = viscoelastic_pade14(b.beta);
  Physics p;
  p.n = sphere.asperities, p.R = sphere.radius, p.a = sphere.asperity_radius, p.g = b.gravity, p.beta = b.beta;
  p.mass = 4.0 / 3.0 * std::numbers::pi * p.R * p.R * p.R * b.density;
  p.J = 0.4 * p.mass * p.R * p.R;  // central sphere only (paper Sec. II)
  p.eps_n = en.get();
  p.law = b.tangential;
  const bool explicit_geometry = v == BounceVariant::random_orientation || v == BounceVariant::dynamic;
  if (!explicit_geometry && b.tangential.model != TangentialLaw::Model::kinematic)
    throw std::invalid_argument("bounce: the tangential law " + b.tangential.describe() + " applies to the explicit variants "
                                "(random-orientation, dynamic); variant " + std::string(to_string(v)) +
                                " is the paper's procedure with its kinematic law");
  if (explicit_geometry) check_asperity_count(sphere.asperities, "bounce: asperities");

  BounceSamples s;
  s.variant = v;
  s.sequences = b.sequences;
  s.sphere = sphere;
  s.first_speed = b.speed;
  const std::uint64_t chunk = kBounceBlock;
  std::vector<SequenceOut> outs(static_cast<std::size_t>(std::min(chunk, b.sequences)));
  const int nt = threads > 0 ? threads : omp_get_max_threads();
  // The mode pmf of every cell count the spheres split, computed once for all sequences (8 bytes
  // per possible count; above 2^24 centres the counts near the root are computed each time).
  std::unique_ptr<BinomialModeCache> modes;
  if (explicit_geometry) modes = std::make_unique<BinomialModeCache>(std::min<std::uint64_t>(sphere.asperities, 1u << 24));
  // One lazy sphere per thread for the whole run (reset per sequence): its memory and its tables
  // of edge functions (sphere-independent) carry over from block to block.
  std::vector<std::unique_ptr<LazySphere>> spheres(static_cast<std::size_t>(std::max(1, nt)));
  for (std::uint64_t start = 0; start < b.sequences; start += chunk) {
    const std::int64_t m = static_cast<std::int64_t>(std::min(chunk, b.sequences - start));
    LowestIndexError error;  // an exception must not leave the parallel region
#pragma omp parallel num_threads(nt)
    {
      auto& S = spheres[static_cast<std::size_t>(omp_get_thread_num())];
      error.run(-1, [&] {
        if (explicit_geometry && !S) S = std::make_unique<LazySphere>(sphere.asperities, seed, 0, 8, modes.get());
      });
#pragma omp for schedule(dynamic, 8)
      for (std::int64_t j = 0; j < m; ++j)
        if (!error.failed())
          error.run(j, [&] {
            auto& o = outs[static_cast<std::size_t>(j)];
            o.impacts.clear(), o.cut = false, o.cells = o.centres = 0;
            const std::uint64_t i = start + static_cast<std::uint64_t>(j);
            if (explicit_geometry) run_explicit(i, v, b, p, seed, *S, o);
            else run_paper(i, v, b, p, seed, o);
          });
    }
    error.rethrow();
    // Append in sequence order: identical for any thread count and schedule.
    if (start == 0) reserve_samples(s, outs, static_cast<std::size_t>(m), b.sequences);
    for (std::int64_t j = 0; j < m; ++j) {
      const auto& o = outs[static_cast<std::size_t>(j)];
      const auto i = static_cast<std::uint32_t>(start + static_cast<std::uint64_t>(j));
      for (const auto& x : o.impacts) {
        s.sequence.push_back(i), s.number.push_back(x.k), s.speed.push_back(x.u), s.eps.push_back(x.eps);
        s.eps_time.push_back(x.eps_time), s.spin.push_back(x.spin), s.omega_x_after.push_back(x.wx), s.core.push_back(x.core);
      }
      s.no_impacts += o.cut ? 1 : 0;
      s.cells += o.cells, s.centres += o.centres;
    }
    // Outside the parallel region: an exception from the callback leaves through here.
    if (progress) progress(start + static_cast<std::uint64_t>(m), b.sequences);
  }
  s.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return s;
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// eps_n(u) of Eq. 9 at every impact's speed, once (the lag-1 correlation and every group use it).
std::vector<double> eps_n_of_impacts(const BounceSamples& s, double beta) {
  const auto en = viscoelastic_pade14(beta);
  std::vector<double> e(s.speed.size());
  LowestIndexError error;
  const auto n = static_cast<std::int64_t>(e.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t j = 0; j < n; ++j)
    error.run(j, [&] { e[static_cast<std::size_t>(j)] = (*en)(s.speed[static_cast<std::size_t>(j)]); });
  error.rethrow();
  return e;
}

// Per sequence: the spin before its last impact; per impact: eps(times) - eps(velocities).
void summarise_sequences(const BounceSamples& s, BounceVariantReport& r) {
  double spin_last = 0, sum = 0, sum2 = 0;
  std::size_t last = 0;
  for (std::size_t j = 0; j < s.eps.size(); ++j) {
    if (j + 1 == s.eps.size() || s.sequence[j + 1] != s.sequence[j]) spin_last += s.spin[j], ++last;
    if (std::isfinite(s.eps_time[j])) {
      const double d = s.eps_time[j] - s.eps[j];
      sum += d, sum2 += d * d, ++r.time_n;
      r.time_diff_max_abs = std::max(r.time_diff_max_abs, std::abs(d));
    }
  }
  r.spin_final_mean = last ? spin_last / static_cast<double>(last) : 0.0;
  if (r.time_n) {
    r.time_diff_mean = sum / static_cast<double>(r.time_n);
    r.time_diff_sd = std::sqrt(std::max(0.0, sum2 / static_cast<double>(r.time_n) - r.time_diff_mean * r.time_diff_mean));
  }
}

// Correlation of consecutive residuals eps - eps_n(u) of one sequence (both impacts after the
// first spin-up, k - 1 >= 2): the memory the paper's procedure keeps and explicit geometry does not.
void lag1_residual_correlation(const BounceSamples& s, const std::vector<double>& en_u, BounceVariantReport& r) {
  double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  std::size_t np = 0;
  for (std::size_t j = 1; j < s.eps.size(); ++j) {
    if (s.sequence[j] != s.sequence[j - 1] || s.number[j - 1] < 2) continue;
    const double x = s.eps[j - 1] - en_u[j - 1], y = s.eps[j] - en_u[j];
    sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y, ++np;
  }
  r.lag1_pairs = np;
  if (np > 2) {
    const double n = static_cast<double>(np);
    const double cxy = sxy / n - sx / n * sy / n, vx = sxx / n - sx / n * sx / n, vy = syy / n - sy / n * sy / n;
    r.lag1_correlation = {cxy / std::sqrt(vx * vy), 1.0 / std::sqrt(n)};
  } else {
    r.lag1_correlation = {kNaN, kNaN};
  }
}

// Semi-analytic residual laws per impact number (explicit variants and the paper's route).
std::vector<BounceResidualLaw> residual_laws(const BounceSamples& s, const BounceExperiment& b) {
  const bool theory = s.sphere && (s.variant == BounceVariant::random_orientation || s.variant == BounceVariant::dynamic ||
                                   s.variant == BounceVariant::paper);
  if (!theory || s.number.empty()) return {};
  ImpactScene sc;
  sc.asperities = s.sphere->asperities, sc.radius = s.sphere->radius, sc.asperity_radius = s.sphere->asperity_radius;
  sc.beta = b.beta, sc.speed = s.first_speed;
  return bounce_residual_laws(sc, *std::max_element(s.number.begin(), s.number.end()), s.variant == BounceVariant::paper);
}

// The members of one group, in impact order, and the sums its statistics need.
struct GroupSums {
  std::vector<double> res;            ///< eps - eps_n(u)
  std::vector<std::size_t> kcount;    ///< members per impact number (laws.size() + 1 entries)
  double su = 0, sw = 0, sd = 0, sd2 = 0;
  std::size_t nd = 0;
  double cu = 0, cr = 0, cuu = 0, crr = 0, cur = 0;  ///< speed (shifted) and residual moments
};

template <class Member>
GroupSums collect_group(const BounceSamples& s, const BounceExperiment& b, const std::vector<double>& en_u,
                        std::size_t laws, std::size_t n, bool window, const Member& member, BounceGroup& g) {
  GroupSums t;
  t.res.reserve(n), g.sorted.reserve(n);
  t.kcount.assign(laws + 1, 0);
  for (std::size_t j = 0; j < s.eps.size(); ++j) {
    if (!member(j)) continue;
    const double r = s.eps[j] - en_u[j];
    t.res.push_back(r);
    g.sorted.push_back(window ? r : s.eps[j]);
    if (s.number[j] <= laws) ++t.kcount[s.number[j]];
    const double du = s.speed[j] - b.speed;  // shifted for accuracy
    t.cu += du, t.cr += r, t.cuu += du * du, t.crr += r * r, t.cur += du * r;
    t.su += s.speed[j], t.sw += s.spin[j];
    if (std::isfinite(s.eps_time[j])) {
      const double d = s.eps_time[j] - s.eps[j];
      t.sd += d, t.sd2 += d * d, ++t.nd;
    }
  }
  return t;
}

// What the KS of a group's residuals against its semi-analytic law needs: the sorted residuals
// (a window's are its g.sorted) and the members per impact number. Run beside the bootstrap
// replicates (bootstrap_tests): the largest window's test alone took as long as all other groups.
struct TheoryInput {
  bool active = false;
  std::vector<double> res;  ///< sorted; empty when they are the group's g.sorted
  std::vector<std::size_t> kcount;
};

// KS of the group's residuals against the mixture of the per-impact laws of its members.
void residual_theory_test(std::span<const double> res, const std::vector<std::size_t>& kcount,
                          const std::vector<BounceResidualLaw>& laws, BounceGroup& g) {
  const double n = static_cast<double>(res.size());
  std::vector<std::pair<double, const BounceResidualLaw*>> mix;
  for (std::size_t k = 1; k < kcount.size(); ++k)
    if (kcount[k]) mix.push_back({static_cast<double>(kcount[k]) / n, &laws[k - 1]});
  double wsum = 0;
  for (const auto& m : mix) wsum += m.first;
  if (mix.empty() || !(wsum > 0.999999)) return;
  g.has_theory = true;
  // A mixture over up to ~10^3 impact numbers: the pruned KS evaluates it at n/23 of the points at
  // n = 1e5 (fewer the larger n), the same D.
  g.theory_ks = ks_one_sample_monotone(res, [&mix](double x) {
    double F = 0;
    for (const auto& [w, L] : mix) F += w * L->cdf(x);
    return F;
  });
  if (mix.size() == 1) g.theory_rate_below = mix[0].second->rate_below(), g.theory_rate_above = mix[0].second->rate_above();
}

// Residual mean, spread, speed correlation and Eq. 2 fit; sorts t.res (pdqsort: the same sorted
// values as std::sort, faster).
void residual_statistics(GroupSums& t, BounceGroup& g) {
  if (t.res.size() <= 2) return;
  const double n = static_cast<double>(t.res.size());
  const double mr = t.cr / n, vr = std::max(0.0, t.crr / n - mr * mr), vu = std::max(0.0, t.cuu / n - t.cu / n * t.cu / n);
  g.residual_mean = {mr, std::sqrt(vr / (n - 1))};
  g.residual_std = std::sqrt(vr * n / (n - 1));
  const double den = std::sqrt(vr * vu);
  g.speed_residual_correlation = {den > 0 ? (t.cur / n - t.cu / n * mr) / den : kNaN, 1.0 / std::sqrt(n)};
  boost::sort::pdqsort_branchless(t.res.begin(), t.res.end());
  try {
    g.residual_fit = fit_asymmetric_laplace_sorted(t.res);
    g.residual_fitted = t.res.size() >= 20;
  } catch (const std::invalid_argument&) {
    g.residual_fitted = false;
  }
}

// Mean speed and spin, mean and spread of the group's quantity, eps(times) - eps(velocities).
void group_moments(const GroupSums& t, BounceGroup& g) {
  g.n = g.sorted.size();
  if (g.n) {
    const double n = static_cast<double>(g.n);
    g.mean_speed = t.su / n, g.spin_mean = t.sw / n;
    double m = 0;
    for (double e : g.sorted) m += e;
    m /= n;
    double v = 0;
    for (double e : g.sorted) v += (e - m) * (e - m);
    g.eps_std = g.n > 1 ? std::sqrt(v / (n - 1)) : 0.0;
    g.eps_mean = {m, g.eps_std / std::sqrt(n)};
  }
  if (t.nd) {
    const double mean = t.sd / static_cast<double>(t.nd);
    const double var = std::max(0.0, t.sd2 / static_cast<double>(t.nd) - mean * mean);
    g.eps_time_minus_eps = {mean, t.nd > 1 ? std::sqrt(var / static_cast<double>(t.nd - 1)) : kNaN};
  } else {
    g.eps_time_minus_eps = {kNaN, kNaN};
  }
}

std::size_t bootstrap_count(const BounceExperiment& b, std::size_t n) {
  const auto B_floor = static_cast<std::size_t>(std::ceil(1.0 / b.alpha - 1e-9));
  return b.bootstrap == 0 ? 0
                          : std::min<std::size_t>(std::max(b.bootstrap, B_floor), std::max<std::uint64_t>(19, b.bootstrap_draws / n));
}

// Eq. 2 fitted to the (sorted) group; its bootstrap test comes later (gof_jobs, bootstrap_verdict).
void laplace_fit(BounceGroup& g) {
  if (g.n < 20) return;
  try {
    g.fit = fit_asymmetric_laplace_sorted(g.sorted);
    g.fitted = true;
  } catch (const std::invalid_argument&) {
    g.fitted = false;  // e.g. all values equal
  }
}

// The bootstrap test of every fitted group, all replicates in one parallel loop (laplace_gof_batch).
// B adapts up to the smallest count whose floor 1/(1+B) is below alpha (ceil(1/alpha): 100 at
// alpha = 0.01; B = 99 could never reject), within a work budget B n <= bootstrap_draws (B >= 19)
// for the big low-speed windows; a group left with floor >= alpha is undecided when no
// replicate reaches D (bootstrap_verdict), never accepted.
void bootstrap_tests(const BounceExperiment& b, std::uint64_t seed, const std::vector<std::uint64_t>& index,
                     std::vector<BounceGroup>& groups, std::span<const std::function<void()>> beside) {
  std::vector<GofJob> jobs;
  std::vector<std::size_t> of;  // the group of each job
  for (std::size_t j = 0; j < groups.size(); ++j) {
    auto& g = groups[j];
    if (!g.fitted) continue;
    if (b.bootstrap == 0) {
      g.gof.p = kNaN, g.gof.D = 0;
      continue;
    }
    jobs.push_back({g.sorted, &g.fit, bootstrap_count(b, g.n), index[j], SequentialStop{b.bootstrap_stop, b.alpha}});
    of.push_back(j);
  }
  const auto gof = laplace_gof_batch(jobs, seed, beside);
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    auto& g = groups[of[i]];
    g.gof = gof[i];
    // p = (1 + #{D_b >= D})/(1 + B): with no replicate at D the test only says p <= floor;
    // when floor > alpha that is no verdict (the group can never reject at this B).
    const double floor = 1.0 / (1.0 + static_cast<double>(g.gof.bootstrap));
    g.gof_verdict = verdict_at(g.gof.p, b.alpha);
    if (g.gof_verdict == Verdict::accept && g.gof.p <= floor * (1 + 1e-9) && !(floor < b.alpha))
      g.gof_verdict = Verdict::undecided;
  }
}

// One group to analyse: a speed window [lo, hi] or an impact number (lo = hi = k).
struct GroupSpec {
  bool window;
  double lo, hi;
  std::uint64_t index;  // its bootstrap's stream index
};

BounceGroup make_group(const BounceSamples& s, const BounceExperiment& b, const std::vector<BounceResidualLaw>& laws,
                       const std::vector<double>& en_u, const GroupSpec& spec, std::size_t n, TheoryInput& th) {
  BounceGroup g;
  g.by = spec.window ? "speed" : "impact", g.lo = spec.lo, g.hi = spec.hi;
  g.quantity = spec.window ? "eps-eps_n(u)" : "eps";
  const auto k = static_cast<std::uint32_t>(spec.lo);
  GroupSums t = spec.window ? collect_group(s, b, en_u, laws.size(), n, true,
                                            [&](std::size_t j) { return s.speed[j] >= spec.lo && s.speed[j] <= spec.hi; }, g)
                            : collect_group(s, b, en_u, laws.size(), n, false, [&](std::size_t j) { return s.number[j] == k; }, g);
  residual_statistics(t, g);  // sorts t.res (n > 2)
  group_moments(t, g);
  th.active = t.res.size() > 2 && !laws.empty();
  th.kcount = std::move(t.kcount);
  // A window's quantity is its residual, already sorted above: the same values, one sort fewer.
  if (spec.window && std::is_sorted(t.res.begin(), t.res.end())) {
    g.sorted = std::move(t.res);
  } else {
    boost::sort::pdqsort_branchless(g.sorted.begin(), g.sorted.end());
    if (th.active) th.res = std::move(t.res);
  }
  laplace_fit(g);
  return g;
}

// The groups side by side, one thread each (each group is a pure function of the samples and its
// own streams, so the report is the same for any thread count), then the bootstrap tests of all
// groups together, their replicates spread over the threads.
std::vector<BounceGroup> make_groups(const BounceSamples& s, const BounceExperiment& b,
                                     const std::vector<BounceResidualLaw>& laws, const std::vector<double>& en_u,
                                     const std::vector<GroupSpec>& specs, std::uint64_t seed) {
  std::vector<BounceGroup> groups(specs.size());
  std::vector<std::exception_ptr> errors(specs.size());
  const auto m = static_cast<std::int64_t>(specs.size());
  // Largest groups (their sorts) first, so that no big group starts last and runs alone.
  std::vector<std::size_t> n(specs.size(), 0), order(specs.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t g = 0; g < m; ++g) {
    const auto& sp = specs[static_cast<std::size_t>(g)];
    std::size_t c = 0;
    for (std::size_t j = 0; j < s.eps.size(); ++j) c += sp.window ? (s.speed[j] >= sp.lo && s.speed[j] <= sp.hi) : s.number[j] == sp.lo;
    n[static_cast<std::size_t>(g)] = c;
  }
  for (std::size_t g = 0; g < order.size(); ++g) order[g] = g;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return n[x] > n[y]; });
  std::vector<TheoryInput> theory(specs.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t i = 0; i < m; ++i) {
    const auto j = order[static_cast<std::size_t>(i)];
    try {
      groups[j] = make_group(s, b, laws, en_u, specs[j], n[j], theory[j]);
    } catch (...) {
      errors[j] = std::current_exception();  // an exception must not leave the parallel region
    }
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
  // The semi-analytic law's KS tests run beside the bootstrap replicates, largest first.
  std::vector<std::function<void()>> tests;
  for (std::size_t j : order)
    if (theory[j].active)
      tests.emplace_back([&, j] {
        const std::span<const double> res = theory[j].res.empty() ? std::span<const double>(groups[j].sorted) : theory[j].res;
        residual_theory_test(res, theory[j].kcount, laws, groups[j]);
      });
  std::vector<std::uint64_t> index;
  for (const auto& sp : specs) index.push_back(sp.index);
  bootstrap_tests(b, seed, index, groups, tests);
  return groups;
}

}  // namespace

BounceVariantReport analyse_bounces(const BounceSamples& s, const BounceExperiment& b, std::uint64_t seed) {
  BounceVariantReport r;
  r.variant = s.variant;
  r.sequences = s.sequences, r.impacts = s.eps.size(), r.no_impacts = s.no_impacts, r.seconds = s.seconds;
  const double ns = static_cast<double>(std::max<std::uint64_t>(1, s.sequences));
  r.impacts_per_sequence = static_cast<double>(r.impacts) / ns;
  r.cells_per_sequence = static_cast<double>(s.cells) / ns;
  r.centres_per_sequence = static_cast<double>(s.centres) / ns;
  summarise_sequences(s, r);
  const std::vector<double> en_u = eps_n_of_impacts(s, b.beta);
  lag1_residual_correlation(s, en_u, r);
  const std::vector<BounceResidualLaw> laws = residual_laws(s, b);
  const std::uint64_t base = 1000000 + 1000 * static_cast<std::uint64_t>(s.variant);
  std::vector<GroupSpec> specs;
  for (const auto& [lo, hi] : b.windows) specs.push_back({true, lo, hi, base + specs.size()});
  for (unsigned k : b.impact_numbers) specs.push_back({false, double(k), double(k), base + specs.size()});
  r.groups = make_groups(s, b, laws, en_u, specs, seed);
  return r;
}

std::vector<BounceVariantReport> run_bounce_experiment(const SphereParams& sphere, const BounceExperiment& b,
                                                       std::uint64_t seed, int threads, std::ostream* log,
                                                       const Progress& progress) {
  std::vector<BounceVariantReport> out;
  const std::uint64_t total = b.sequences * b.variants.size();
  for (auto v : b.variants) {
    const auto t0 = Clock::now();
    const std::uint64_t offset = b.sequences * out.size();
    Progress in_variant;
    if (progress) in_variant = [&](std::uint64_t done, std::uint64_t) { progress(offset + done, total); };
    const BounceSamples s = run_bounces(sphere, b, v, seed, threads, in_variant);
    out.push_back(analyse_bounces(s, b, seed));
    if (log)
      *log << "bounce " << to_string(v) << ": " << s.sequences << " sequences, " << s.eps.size() << " impacts, run "
           << s.seconds << " s, analysis " << std::chrono::duration<double>(Clock::now() - t0).count() - s.seconds << " s\n";
  }
  return out;
}

std::vector<BounceComparison> compare_bounce_variants(const std::vector<BounceVariantReport>& r) {
  std::vector<BounceComparison> out;
  std::vector<std::pair<const BounceGroup*, const BounceGroup*>> pairs;
  for (std::size_t i = 0; i < r.size(); ++i)
    for (std::size_t j = i + 1; j < r.size(); ++j)
      for (const auto& ga : r[i].groups)
        for (const auto& gb : r[j].groups)
          if (ga.by == gb.by && ga.lo == gb.lo && ga.hi == gb.hi && ga.n >= 20 && gb.n >= 20) {
            out.push_back({r[i].variant, r[j].variant, ga.by, ga.lo, ga.hi, {}});
            pairs.push_back({&ga, &gb});
          }
  // The tests (up to ~2e6 values each) side by side; each is a pure function of its two samples.
  const auto m = static_cast<std::int64_t>(pairs.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t k = 0; k < m; ++k) {
    const auto& [a, b] = pairs[static_cast<std::size_t>(k)];
    out[static_cast<std::size_t>(k)].ks = ks_two_sample(a->sorted, b->sorted);
  }
  return out;
}

std::string bounce_grouping_note() {
  return "Impact numbers k give p(eps | k-th bounce): the law after k - 1 impacts of spin-up. Speed windows give "
         "p(eps | u in window), what the experiment reports, mixing the impact numbers whose speeds fall in the window. "
         "Neither grouping is free of history: u_k = u_1 prod eps_j, so window membership (and survival of the stopping "
         "rule) selects sequences by their past eps. That biases the window's law only if the current eps is correlated "
         "with the past. In explicit geometry it is not (lag-1 correlation ~0, and the windows follow the residual law "
         "of their mix of k); in the paper's procedure the sign of Omega_x is kept (lag-1 correlation ~0.78) and a window "
         "whose edge cuts through one impact's cohort is biased (fig6, 0.5-0.6 m/s: mean residual -6.75e-6 instead of "
         "-5.6e-6). Windows fit eps - eps_n(u) (eps_n changes by ~5e-4 across a 0.1 m/s window), impact numbers eps; "
         "`residual` holds eps - eps_n(u_k) for every group.";
}





}  // namespace asperity
