#include "asperity/body_bounce.hpp"

#include <omp.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "asperity/body_impact.hpp"
#include "asperity/random.hpp"
#include "asperity/restitution.hpp"
#include "format.hpp"

namespace asperity {

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
  if (o.bounce.variants != std::vector<BounceVariant>{BounceVariant::dynamic})
    throw std::invalid_argument("bounce: variants must be \"dynamic\" for a body (orientation carried by the free rotation), got " +
                                std::to_string(o.bounce.variants.size()) + " variant(s) starting with " +
                                std::string(to_string(o.bounce.variants.front())));
  if (!o.omega.allFinite()) throw std::invalid_argument("bounce: Omega must be finite");
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
  double u, eps, eps_time;
  float spin, wx;
  Vec3 r, omega_after;
  double e_before, e_after, rot_after, trans_after, work, flight;
  std::uint32_t queries;
};

enum class Stop : std::uint8_t { slow, rising, no_approach, max_impacts, max_time, max_steps };

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
  Vec3 V(0, 0, -o.bounce.speed), W = o.omega;
  double z = index.support(body_down(q)).h;  // touching at t = 0
  out.e0 = body_energy(b, q, V, W, z, g);
  double T_prev = kNaN, time = 0;
  for (std::uint32_t k = 1;; ++k) {
    const double u = -V.z();
    if (u <= 0) { out.stop = Stop::rising; return; }
    if (u < o.bounce.stop_speed) { out.stop = Stop::slow; return; }
    if (time > o.max_time) { out.stop = Stop::max_time; return; }
    const BodyImpact bi = body_impact(b, index, q, V, W, eps_n, o.bounce.eps_t);
    if (!bi.result) { out.stop = Stop::no_approach; return; }
    const ImpactResult& res = *bi.result;
    const Vec3& r = bi.contact.r;
    Record rec;
    rec.k = k, rec.u = u, rec.eps = res.eps, rec.spin = static_cast<float>(W.norm());
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
                                   int threads) {
  validate(o);
  if (bodies.empty()) throw std::invalid_argument("bounce: no bodies");
  for (const auto& b : bodies)
    if (b.size() < 1) throw std::invalid_argument("bounce: body '" + b.name + "' has no asperities");
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::unique_ptr<SupportQuery>> trees;
  std::vector<BodyBounds> bounds;
  for (const auto& b : bodies) trees.push_back(make_support_tree(b.centres, b.radii)), bounds.push_back(BodyBounds::of(b));
  const auto eps_n = viscoelastic_pade14(o.bounce.beta);
  const std::uint64_t K = bodies.size(), n = o.bounce.sequences;

  BodyBounceSamples S;
  S.base.variant = BounceVariant::dynamic;
  S.base.sequences = n;
  const std::uint64_t chunk = 1024;
  std::vector<SequenceOut> outs(static_cast<std::size_t>(std::min(chunk, n)));
  const int nt = threads > 0 ? threads : omp_get_max_threads();
  for (std::uint64_t start = 0; start < n; start += chunk) {
    const auto m = static_cast<std::int64_t>(std::min(chunk, n - start));
#pragma omp parallel for num_threads(nt) schedule(dynamic, 1)
    for (std::int64_t j = 0; j < m; ++j) {
      const std::uint64_t s = start + static_cast<std::uint64_t>(j);
      auto& out = outs[static_cast<std::size_t>(j)];
      out.impacts.clear();
      run_sequence(s, bodies[s % K], bounds[s % K], *trees[s % K], o, *eps_n, seed, out);
    }
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
        S.work.push_back(x.work), S.flight.push_back(x.flight), S.queries.push_back(x.queries);
        S.support_queries += x.queries, S.flights += x.queries > 0;
      }
      S.first_energy.push_back(out.e0);
      auto& c = S.stops;
      switch (out.stop) {
        case Stop::slow: ++c.slow; break;
        case Stop::rising: ++c.rising; break;
        case Stop::no_approach: ++c.no_approach; break;
        case Stop::max_impacts: ++c.max_impacts; break;
        case Stop::max_time: ++c.max_time; break;
        case Stop::max_steps: ++c.max_steps; break;
      }
      S.base.no_impacts += out.stop == Stop::no_approach;
    }
  }
  S.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  S.base.seconds = S.seconds;
  return S;
}

BodyBounceReport analyse_body_bounces(const BodyBounceSamples& s, const BounceExperiment& b, std::uint64_t seed) {
  BodyBounceReport r;
  r.base = analyse_bounces(s.base, b, seed);
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
  double below = 0, above = 0, rot = 0, last = 0, shortf = 0, flights = 0;
  for (std::size_t j = 0; j < n; ++j) {
    below += B.eps[j] < 0, above += B.eps[j] > 1;
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
  }
  r.eps_below_0 = n ? below / static_cast<double>(n) : kNaN;
  r.eps_above_1 = n ? above / static_cast<double>(n) : kNaN;
  r.rot_fraction_last = last ? rot / last : kNaN;
  r.short_flights = flights ? shortf / flights : kNaN;
  return r;
}

}  // namespace asperity
