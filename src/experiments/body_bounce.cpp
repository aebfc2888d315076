// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/experiments/body_bounce.hpp"
#include "asperity/core/parallel_errors.hpp"

#include <omp.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include <cstdio>
#include <iomanip>
#include <locale>
#include <numbers>
#include <sstream>

#include "asperity/core/body_impact.hpp"
#include "asperity/core/mesh.hpp"
#include "asperity/laws/figure.hpp"
#include "asperity/core/random.hpp"
#include "asperity/core/restitution.hpp"
#include "core/format.hpp"

namespace asperity {

using detail::fmt;
using detail::num;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Smallest s >= 0 with f + v s - acc s^2/2 = 0 for f >= 0, acc > 0 (the later root written without
// cancellation for v < 0). f = +inf (no runner-up) gives +inf.
double first_root(double f, double v, double acc) {
  if (!(f < kInf)) return kInf;
  const double disc = std::sqrt(v * v + 2.0 * acc * f);
  if (v < 0) return f == 0 ? 0.0 : 2.0 * f / (disc - v);
  return (v + disc) / acc;
}

}  // namespace

BodyBounds BodyBounds::of(const RoughBody& b) {
  BodyBounds r;
  for (const Vec3& c : b.centres) r.c_max = std::max(r.c_max, c.norm());
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(b.inertia, Eigen::EigenvaluesOnly).eigenvalues();
  r.j_min = ev(0), r.j_max = ev(2);
  return r;
}

double body_energy(const RoughBody& b, const Rotation& q, const Vec3& V, const Vec3& Omega, double z, double g) {
  const Eigen::Matrix3d Q = q.toRotationMatrix();
  const Vec3 wb = Q.transpose() * Omega;
  return 0.5 * b.mass * V.squaredNorm() + 0.5 * wb.dot(b.inertia * wb) + b.mass * g * z;
}

Landing next_landing(const RoughBody& b, const BodyBounds& bb, const SupportQuery& index, const FreeRotation& rot,
                     const FlightStart& st, const LandingOptions& o) {
  const double g = st.gravity;
  // |Omega(t)| <= sqrt(2 T / J_min) for the whole flight (T constant); the factor covers rounding.
  const double om_max = std::sqrt(2.0 * rot.kinetic_energy() / bb.j_min) * (1 + 1e-9);
  const double w = o.rotation_bound_scale * om_max * bb.c_max;
  const double acc_rot = o.rotation_bound_scale * om_max * om_max * (1.0 + bb.j_max / bb.j_min);
  Landing L;
  double t = 0;
  for (;;) {
    if (L.queries >= o.max_steps) return L;  // found = false
    const RotationState rs = rot.at(t);
    const double z = st.z + st.vz * t - 0.5 * g * t * t, vz = st.vz - g * t;
    const Support sup = index.support(body_down(rs.q));
    ++L.queries;
    const double f = z - sup.h, f2 = z - sup.runner_up_h;
    const Vec3& ci = b.centres[sup.index];
    const double slope = vz + rs.omega.cross(rs.q * ci).z();  // exact normal velocity of the lowest asperity
    auto land = [&] {
      L.found = true, L.time = t, L.rotation = rs, L.z = z, L.vz = vz, L.support = sup, L.gap = f;
      return L;
    };
    // Touching (or, after a minimal step, just through the plate) and approaching: the landing.
    if (f <= 0 && slope <= 0) return land();
    const double s1 = first_root(std::max(f, 0.0), slope, g + ci.norm() * acc_rot);
    if (s1 < o.time_tolerance && slope < 0) return land();  // within the tolerance of touching
    const double s2 = first_root(std::max(f2, 0.0), vz - w, g);
    // Steps below the tolerance are taken at the tolerance: a contact can then be overshot by at
    // most time_tolerance (and is found at once, penetrated by <= |v| time_tolerance), never missed.
    t += std::max(std::min(s1, s2), o.time_tolerance);
  }
}

void validate(const BodyBounceOptions& o) {
  validate(o.bounce);
  validate(o.tangential);
  if (o.bounce.variants != std::vector<BounceVariant>{BounceVariant::dynamic})
    throw std::invalid_argument("bounce: variants must be \"dynamic\" for a body (orientation carried by the free rotation), got " +
                                std::to_string(o.bounce.variants.size()) + " variant(s) starting with " +
                                std::string(to_string(o.bounce.variants.front())));
  if (!std::isfinite(o.max_time) || !(o.max_time > 0)) throw std::invalid_argument("bounce: max_time must be finite and > 0 s, got " + num(o.max_time));
  if (!std::isfinite(o.landing.time_tolerance) || !(o.landing.time_tolerance > 0))
    throw std::invalid_argument("bounce: time_tolerance must be finite and > 0 s, got " + num(o.landing.time_tolerance));
  if (o.landing.max_steps < 1) throw std::invalid_argument("bounce: max_steps must be >= 1");
  if (!(o.landing.rotation_bound_scale >= 0) || !std::isfinite(o.landing.rotation_bound_scale))
    throw std::invalid_argument("bounce: rotation_bound_scale must be finite and >= 0, got " + num(o.landing.rotation_bound_scale));
}

namespace {

struct Record {
  std::uint32_t k;
  double u, vn, eps, eps_time;
  float spin, wx;
  Vec3 r, omega_after;
  double e_before, e_after, rot_after, trans_after, work, flight;
  std::uint32_t queries;
};

enum class Stop : std::uint8_t { slow, no_approach, max_impacts, max_time, max_steps };

struct SequenceOut {
  std::vector<Record> impacts;
  Stop stop = Stop::slow;
  double e0 = 0;
};

void run_sequence(std::uint64_t s, const RoughBody& b, const BodyBounds& bb, const SupportQuery& index,
                  const BodyBounceOptions& o, const Restitution& eps_n, std::uint64_t seed, SequenceOut& out) {
  const double g = o.bounce.gravity;
  Stream st(seed, Purpose::bounce, s, kBodyBounceSub);
  Rotation q = random_rotation(st);
  Vec3 V(0, 0, -o.bounce.speed), W = o.bounce.omega;
  TangentialLaw law = o.tangential;
  if (law.model == TangentialLaw::Model::kinematic) law.eps_t = o.bounce.eps_t;
  double z = index.support(body_down(q)).h;  // touching at t = 0
  out.e0 = body_energy(b, q, V, W, z, g);
  double T_prev = kNaN, time = 0;
  for (std::uint32_t k = 1;; ++k) {
    const double u = -V.z();
    if (time > o.max_time) { out.stop = Stop::max_time; return; }
    // eps = -V'_z/V_z (Eq. 1) is undefined at V_z = 0 exactly (solve_impact refuses it): counted as
    // no approach rather than thrown inside the parallel loop. Never seen; V_z = v0 - g t.
    if (V.z() == 0) { out.stop = Stop::no_approach; return; }
    const BodyImpact bi = body_impact(b, index, q, V, W, eps_n, law);
    if (!bi.result) { out.stop = Stop::no_approach; return; }
    const ImpactResult& res = *bi.result;
    if (-res.v_n < o.bounce.stop_speed) { out.stop = Stop::slow; return; }
    const Vec3& r = bi.contact.r;
    Record rec;
    rec.k = k, rec.u = u, rec.vn = -res.v_n, rec.eps = res.eps, rec.spin = static_cast<float>(W.norm());
    rec.wx = static_cast<float>(res.Omega_after.x());
    rec.r = r, rec.omega_after = res.Omega_after;
    rec.e_before = body_energy(b, q, V, W, z, g);
    rec.e_after = body_energy(b, q, res.V_after, res.Omega_after, z, g);
    rec.trans_after = 0.5 * b.mass * res.V_after.squaredNorm();
    rec.rot_after = body_energy(b, q, Vec3::Zero(), res.Omega_after, 0.0, g);
    const Vec3 v = V + W.cross(r), v2 = res.V_after + res.Omega_after.cross(r);
    rec.work = res.P.dot(0.5 * (v + v2));
    V = res.V_after, W = res.Omega_after;
    if (k == o.bounce.max_impacts) {  // no impact may follow: the flight is not needed
      rec.flight = kNaN, rec.eps_time = kNaN, rec.queries = 0;
      out.impacts.push_back(rec);
      out.stop = Stop::max_impacts;
      return;
    }
    const FreeRotation rot(b.inertia, q, W);
    const Landing L = next_landing(b, bb, index, rot, {z, V.z(), g}, o.landing);
    rec.queries = L.queries;
    if (!L.found) {
      rec.flight = kNaN, rec.eps_time = kNaN;
      out.impacts.push_back(rec);
      out.stop = Stop::max_steps;
      return;
    }
    rec.flight = L.time;
    rec.eps_time = L.time / T_prev;
    out.impacts.push_back(rec);
    T_prev = L.time, time += L.time;
    q = L.rotation.q.normalized(), W = L.rotation.omega, V.z() = L.vz, z = L.z;
  }
}

}  // namespace

BodyBounceSamples run_body_bounces(std::span<const RoughBody> bodies, const BodyBounceOptions& o, std::uint64_t seed,
                                   int threads, const Progress& progress) {
  validate(o);
  if (bodies.empty()) throw std::invalid_argument("bounce: no bodies");
  for (const auto& b : bodies)
    if (b.size() < 1) throw std::invalid_argument("bounce: body '" + b.name + "' has no asperities");
  const auto t0 = std::chrono::steady_clock::now();
  const int nt = threads > 0 ? threads : omp_get_max_threads();
  std::vector<std::unique_ptr<SupportQuery>> trees(bodies.size());
  std::vector<BodyBounds> bounds(bodies.size());
  const auto nb = static_cast<std::int64_t>(bodies.size());
  LowestIndexError index_error;
#pragma omp parallel for num_threads(nt) schedule(dynamic, 1)
  for (std::int64_t k = 0; k < nb; ++k)
    index_error.run(k, [&] {
      const auto& b = bodies[static_cast<std::size_t>(k)];
      trees[static_cast<std::size_t>(k)] = make_support_tree(b.centres, b.radii);
      bounds[static_cast<std::size_t>(k)] = BodyBounds::of(b);
    });
  index_error.rethrow();
  const double seconds_index = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto t1 = std::chrono::steady_clock::now();
  const auto eps_n = viscoelastic_pade14(o.bounce.beta);
  const std::uint64_t K = bodies.size(), n = o.bounce.sequences;

  BodyBounceSamples S;
  S.base.variant = BounceVariant::dynamic;
  S.base.sequences = n;
  const std::uint64_t chunk = 256;
  std::vector<SequenceOut> outs(static_cast<std::size_t>(std::min(chunk, n)));
  for (std::uint64_t start = 0; start < n; start += chunk) {
    const auto m = static_cast<std::int64_t>(std::min(chunk, n - start));
    // A sequence can throw (an impulse process that does not end): kept, not std::terminate.
    LowestIndexError sequence_error;
#pragma omp parallel for num_threads(nt) schedule(dynamic, 1)
    for (std::int64_t j = 0; j < m; ++j)
      sequence_error.run(j, [&] {
        const std::uint64_t s = start + static_cast<std::uint64_t>(j);
        auto& out = outs[static_cast<std::size_t>(j)];
        out.impacts.clear();
        run_sequence(s, bodies[s % K], bounds[s % K], *trees[s % K], o, *eps_n, seed, out);
      });
    sequence_error.rethrow();
    // Appended in sequence order: identical for any thread count and schedule.
    for (std::int64_t j = 0; j < m; ++j) {
      const auto& out = outs[static_cast<std::size_t>(j)];
      const auto s = static_cast<std::uint32_t>(start + static_cast<std::uint64_t>(j));
      for (const Record& x : out.impacts) {
        auto& B = S.base;
        B.sequence.push_back(s), B.number.push_back(x.k), B.speed.push_back(x.u), B.eps.push_back(x.eps);
        B.eps_time.push_back(x.eps_time), B.spin.push_back(x.spin), B.omega_x_after.push_back(x.wx), B.core.push_back(0);
        S.r.push_back(x.r), S.omega_after.push_back(x.omega_after);
        S.energy_before.push_back(x.e_before), S.energy_after.push_back(x.e_after);
        S.rot_energy_after.push_back(x.rot_after), S.trans_energy_after.push_back(x.trans_after);
        S.work.push_back(x.work), S.contact_speed.push_back(x.vn), S.flight.push_back(x.flight), S.queries.push_back(x.queries);
        S.support_queries += x.queries, S.flights += x.queries > 0;
      }
      S.first_energy.push_back(out.e0);
      auto& c = S.stops;
      switch (out.stop) {
        case Stop::slow: ++c.slow; break;
        case Stop::no_approach: ++c.no_approach; break;
        case Stop::max_impacts: ++c.max_impacts; break;
        case Stop::max_time: ++c.max_time; break;
        case Stop::max_steps: ++c.max_steps; break;
      }
      S.base.no_impacts += out.stop == Stop::no_approach;
    }
    if (progress) progress(start + static_cast<std::uint64_t>(m), n);
  }
  S.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  S.seconds_index = seconds_index;
  S.base.seconds = S.seconds;
  return S;
}

BodyBounceReport analyse_body_bounces(const BodyBounceSamples& s, const BounceExperiment& b, std::uint64_t seed) {
  BodyBounceReport r;
  {
    // Eq. 9's eps_n(u) of the speed windows and the lag-1 correlation needs u > 0: impacts with the
    // centre rising (rocking) have no impact speed and are left out of that analysis only.
    BounceSamples f;
    f.variant = s.base.variant, f.sequences = s.base.sequences, f.no_impacts = s.base.no_impacts, f.seconds = s.base.seconds;
    const auto& B = s.base;
    for (std::size_t j = 0; j < B.eps.size(); ++j) {
      if (!(B.speed[j] > 0)) continue;
      f.sequence.push_back(B.sequence[j]), f.number.push_back(B.number[j]), f.speed.push_back(B.speed[j]);
      f.eps.push_back(B.eps[j]), f.eps_time.push_back(B.eps_time[j]), f.spin.push_back(B.spin[j]);
      f.omega_x_after.push_back(B.omega_x_after[j]), f.core.push_back(B.core[j]);
    }
    r.base = analyse_bounces(f, b, seed);
    r.base.impacts = B.eps.size();
    r.base.impacts_per_sequence = static_cast<double>(B.eps.size()) / static_cast<double>(std::max<std::uint64_t>(1, B.sequences));
  }
  r.stops = s.stops;
  const auto& B = s.base;
  const std::size_t n = B.eps.size();
  std::vector<std::uint32_t> per(static_cast<std::size_t>(B.sequences), 0);
  for (std::size_t j = 0; j < n; ++j) per[B.sequence[j]] = std::max(per[B.sequence[j]], B.number[j]);
  double m = 0, m2 = 0;
  for (auto k : per) m += k, m2 += static_cast<double>(k) * k, r.impacts_max = std::max(r.impacts_max, k);
  const double ns = static_cast<double>(std::max<std::size_t>(1, per.size()));
  m /= ns;
  r.impacts_per_sequence_sd = std::sqrt(std::max(0.0, m2 / ns - m * m));
  r.queries_per_flight = s.flights ? static_cast<double>(s.support_queries) / static_cast<double>(s.flights) : kNaN;
  double below = 0, above = 0, rising = 0, rot = 0, last = 0, shortf = 0, flights = 0, gains = 0;
  for (std::size_t j = 0; j < n; ++j) {
    below += B.eps[j] < 0, above += B.eps[j] > 1, rising += B.speed[j] <= 0;
    const double E = std::abs(s.energy_before[j]);
    r.work_identity_max = std::max(r.work_identity_max, std::abs((s.energy_after[j] - s.energy_before[j]) - s.work[j]) / E);
    const bool last_of_seq = j + 1 == n || B.sequence[j + 1] != B.sequence[j];
    if (last_of_seq) {
      const double kin = s.rot_energy_after[j] + s.trans_energy_after[j];
      if (kin > 0) rot += s.rot_energy_after[j] / kin, ++last;
    } else {
      r.flight_energy_max = std::max(r.flight_energy_max, std::abs(s.energy_before[j + 1] - s.energy_after[j]) / E);
    }
    if (std::isfinite(s.flight[j])) shortf += s.flight[j] < 1e-3, ++flights;
    const double gain = (s.energy_after[j] - s.energy_before[j]) / E;
    gains += gain > 0, r.energy_gain_max = std::max(r.energy_gain_max, gain);
  }
  r.eps_below_0 = n ? below / static_cast<double>(n) : kNaN;
  r.rising_fraction = n ? rising / static_cast<double>(n) : kNaN;
  r.eps_above_1 = n ? above / static_cast<double>(n) : kNaN;
  r.rot_fraction_last = last ? rot / last : kNaN;
  r.short_flights = flights ? shortf / flights : kNaN;
  r.energy_gain_fraction = n ? gains / static_cast<double>(n) : kNaN;
  const int bins = 18;
  const double lo = b.stop_speed, hi = b.speed;
  std::vector<std::vector<double>> eb(bins), sb(bins);
  for (std::size_t j = 0; j < n; ++j) {
    int k = static_cast<int>((B.speed[j] - lo) / (hi - lo) * bins);
    if (B.speed[j] == hi) k = bins - 1;
    if (k < 0 || k >= bins) continue;
    eb[static_cast<std::size_t>(k)].push_back(B.eps[j]), sb[static_cast<std::size_t>(k)].push_back(B.spin[j]);
  }
  for (int k = 0; k < bins; ++k) {
    auto& v = eb[static_cast<std::size_t>(k)];
    SpeedBin x;
    x.lo = lo + k * (hi - lo) / bins, x.hi = lo + (k + 1) * (hi - lo) / bins, x.n = v.size();
    if (v.size() >= 2) {
      const Summary su = summarize_iid(v, std::vector<double>{0.1, 0.9});
      x.eps = su.mean, x.eps_q10 = su.quantiles[0].value, x.eps_q90 = su.quantiles[1].value;
      double sp = 0;
      for (double w : sb[static_cast<std::size_t>(k)]) sp += w;
      x.spin_mean = sp / static_cast<double>(v.size());
    } else {
      x.eps = {kNaN, kNaN}, x.eps_q10 = x.eps_q90 = x.spin_mean = kNaN;
    }
    r.by_speed.push_back(x);
  }
  return r;
}

void validate(const MeshBounceExperiment& e) {
  validate(e.options);
  if (!e.mesh.empty()) {
    if (!std::isfinite(e.scale) || !(e.scale > 0)) throw std::invalid_argument("mesh scale must be finite and > 0, got " + num(e.scale));
    if (!e.smooth.empty() && e.smooth.size() != 3 && e.smooth.size() != 4)
      throw std::invalid_argument("smooth surface needs 3 semi-axes and an optional exponent, got " + std::to_string(e.smooth.size()) +
                                  " numbers");
  } else if (!std::isfinite(e.sphere_radius) || !(e.sphere_radius > 0)) {
    throw std::invalid_argument("sphere radius must be finite and > 0 m, got " + num(e.sphere_radius));
  }
  check_asperity_count(e.asperities);
  validate(e.radii);
  if (!std::isfinite(e.density) || !(e.density > 0)) throw std::invalid_argument("density must be finite and > 0, got " + num(e.density));
  if (e.bodies < 1) throw std::invalid_argument("bodies must be >= 1, got 0");
}

namespace {



}  // namespace

std::string mesh_bounce_subtitle(const MeshBounceReport& r) {
  std::ostringstream sub;  // the body's name (a mesh file's) as written, not as figure markup
  sub << figure_text_literal(r.body_name) << ", N = " << r.experiment.asperities << ", " << r.experiment.options.bounce.sequences << " sequences";
  return sub.str();
}

MeshBounceReport run_mesh_bounces(const MeshBounceExperiment& e, const TriangleMesh* base, const Progress& progress) {
  validate(e);
  MeshBounceReport r;
  r.experiment = e;
  const auto t0 = std::chrono::steady_clock::now();
  auto since = [](auto t) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count(); };
  std::vector<RoughBody> bodies(static_cast<std::size_t>(e.bodies));
  if (!e.mesh.empty()) {
    const TriangleMesh& mesh = *base;
    const SurfaceMap onto = smooth_surface(e.smooth);
    r.body_name = e.mesh.stem().string();
    for (std::uint64_t k = 0; k < e.bodies; ++k)
      bodies[static_cast<std::size_t>(k)] = make_rough_mesh_body(mesh, e.asperities, e.radii, e.density, e.seed, k, onto, r.body_name);
  } else {
    SphereParams p;
    p.asperities = e.asperities, p.radius = e.sphere_radius;
    r.body_name = "sphere";
    for (std::uint64_t k = 0; k < e.bodies; ++k)
      bodies[static_cast<std::size_t>(k)] = make_rough_sphere_body(p, e.radii, e.seed, k, e.density);
  }
  r.mass = bodies[0].mass;
  r.principal_moments = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(bodies[0].inertia, Eigen::EigenvaluesOnly).eigenvalues();
  for (const auto& b : bodies) r.c_max = std::max(r.c_max, BodyBounds::of(b).c_max);
  r.seconds_build = since(t0);
  const BodyBounceSamples S = run_body_bounces(bodies, e.options, e.seed, e.threads, progress);
  r.seconds_run = S.seconds, r.seconds_index = S.seconds_index;
  const auto t2 = std::chrono::steady_clock::now();
  r.report = analyse_body_bounces(S, e.options.bounce, e.seed);
  r.seconds_analysis = since(t2);
  // Figures of the impacts per speed window need the samples: built here, written by app/.
  if (e.plots) {
    const std::string sub = mesh_bounce_subtitle(r);
    for (const auto& g : r.report.base.groups) {
      if (g.by != "speed" || g.n < 20) continue;
      std::vector<double> x;
      for (std::size_t j = 0; j < S.base.eps.size(); ++j)
        if (S.base.speed[j] >= g.lo && S.base.speed[j] <= g.hi) x.push_back(S.base.eps[j]);
      std::sort(x.begin(), x.end());
      // 0.1%..99.9%: a few impacts far out (eps ~ 10 when the stored spin kicks a slow centre) would
      // squeeze the law into a few bins; they are counted outside the range.
      const double lo = quantile_sorted(x, 0.001), hi = quantile_sorted(x, 0.999);
      const double pad = 0.02 * (hi - lo) + 1e-9;
      HistogramFigure fig;
      fig.title = "ε, u in [" + fmt("%.2f", g.lo) + ", " + fmt("%.2f", g.hi) + "] m/s: " + sub + " (n = " +
                  std::to_string(x.size()) + ")";
      fig.xlabel = "ε = -V'_z/V_z";
      fig.histogram = make_histogram(x, lo - pad, hi + pad, 40);
      const std::string name = "eps_u" + fmt("%.2f", g.lo) + "-" + fmt("%.2f", g.hi) + ".png";
      r.figures.push_back({name, std::move(fig)});
    }
  }
  return r;
}



}  // namespace asperity
