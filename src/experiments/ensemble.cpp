// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/experiments/ensemble.hpp"
#include "asperity/core/thread_count.hpp"
#include "asperity/core/parallel_errors.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <numbers>
#include <stdexcept>

#include "asperity/config.hpp"
#include "asperity/core/impact.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/random.hpp"
#include "core/format.hpp"
#include "experiments/ensemble_detail.hpp"

namespace asperity {

using detail::num;

std::string_view to_string(Mode m) { return m == Mode::explicit_spheres ? "explicit" : "sampled"; }

Mode parse_mode(std::string_view s) {
  if (s == "explicit") return Mode::explicit_spheres;
  if (s == "sampled") return Mode::sampled;
  if (const std::string why = removed_mode(s); !why.empty()) throw std::invalid_argument(why);
  throw std::invalid_argument("unknown mode '" + std::string(s) + "' (expected explicit or sampled)");
}

std::string removed_mode(std::string_view s) {
  if (s == "fixed")
    return "mode \"fixed\" was removed in 2.0.0: use \"explicit\" (K explicit spheres x M rotations, the same run)";
  if (s == "fresh")
    return "mode \"fresh\" was removed in 2.0.0: use \"explicit\" (explicit spheres, contacts by spatial query, "
           "as \"fresh\" ran in 1.x) or \"sampled\" (the exact sampler of the lowest asperities, no geometry)";
  return {};
}

std::uint64_t auto_spheres(std::uint64_t asperities, std::uint64_t drops) {
  if (drops <= kAutoMinSpheres) return drops;
  const double c2 = kQuenchedKs * kQuenchedKs;
  const auto m_max = static_cast<std::uint64_t>(std::max(1.0, std::floor(double(asperities) / (10.0 * c2))));
  const std::uint64_t k_min = std::max<std::uint64_t>(kAutoMinSpheres, (drops + m_max - 1) / m_max);
  for (std::uint64_t k = k_min; k < drops; ++k)
    if (drops % k == 0) return k;
  return drops;
}

DesignScales design_scales(Mode mode, std::uint64_t asperities, std::uint64_t spheres, std::uint64_t drops) {
  DesignScales s;
  s.statistical = 0.8687 / std::sqrt(double(drops));  // mean of sqrt(n) D under iid: sqrt(pi/2) ln 2
  if (mode == Mode::explicit_spheres)
    s.quenched = kQuenchedKs / std::sqrt(double(asperities) * double(std::max<std::uint64_t>(spheres, 1)));
  return s;
}

std::string_view to_string(Statistics s) {
  switch (s) {
    case Statistics::automatic: return "auto";
    case Statistics::raw: return "raw";
    case Statistics::streaming: return "streaming";
  }
  return "?";
}

Statistics parse_statistics(std::string_view s) {
  if (s == "auto") return Statistics::automatic;
  if (s == "raw") return Statistics::raw;
  if (s == "streaming") return Statistics::streaming;
  throw std::invalid_argument("unknown statistics '" + std::string(s) + "' (expected auto, raw or streaming)");
}

bool uses_streaming(const EnsembleConfig& c) {
  if (c.statistics == Statistics::streaming) return true;
  return c.statistics == Statistics::automatic && !c.impact.enabled && c.drops > kStreamingAutoDrops;
}

void validate(const EnsembleConfig& c) {
  validate(c.sphere);
  if (c.drops < 2)
    throw std::invalid_argument("drops must be >= 2 (a standard error needs two samples), got " + std::to_string(c.drops));
  if (c.statistics == Statistics::streaming && c.impact.enabled)
    throw std::invalid_argument("statistics = streaming keeps contact statistics only; the impact experiment needs "
                                "statistics = raw (or auto)");
  if (!kernel_available(c.kernel))
    throw std::invalid_argument("kernel = \"" + std::string(to_string(c.kernel)) +
                                "\": the explicit drops have no CUDA backend yet (kernels: scalar, simd)");
  if (c.bins_log2 < 10 || c.bins_log2 > 24)
    throw std::invalid_argument("bins_log2 (2^k streaming bins) must be in [10, 24], got " + std::to_string(c.bins_log2));
  if (uses_streaming(c) && c.drops > kMaxStreamingDrops)
    throw std::invalid_argument("drops must be <= 2^50 for streaming statistics, got " + std::to_string(c.drops));
  // Beyond 2^31 only when streaming was asked for: a run of that size is a decision, never automatic.
  if (c.statistics != Statistics::streaming && c.drops > kMaxRawDrops)
    throw std::invalid_argument("drops must be <= 2^31 unless statistics = streaming (--statistics streaming), got " +
                                std::to_string(c.drops));
  if (c.mode == Mode::explicit_spheres) {
    if (c.spheres < 1) throw std::invalid_argument("spheres must be >= 1, got 0");
    if (c.drops % c.spheres != 0)
      throw std::invalid_argument("drops (" + std::to_string(c.drops) + ") must be a multiple of spheres (" +
                                  std::to_string(c.spheres) + ")");
  }
  if (c.threads < 0 || c.threads > kMaxThreads)
    throw std::invalid_argument("threads must be in [0, " + std::to_string(kMaxThreads) + "], got " +
                                std::to_string(c.threads));
  if (c.impact.enabled) {
    const auto& x = c.impact;
    if (!std::isfinite(x.speed) || !(x.speed > 0))
      throw std::invalid_argument("impact speed must be finite and > 0 m/s, got " + std::to_string(x.speed));
    if (x.speed > kMaxSpeed)
      throw std::invalid_argument("impact speed must be <= " + num(kMaxSpeed) + " m/s (supported range), got " + num(x.speed));
    if (!x.omega.allFinite()) throw std::invalid_argument("impact omega must be finite");
    const double surface = x.omega.norm() * (c.sphere.radius + c.sphere.asperity_radius);
    if (!(surface <= kMaxSpeed))
      throw std::invalid_argument("impact spin |omega| = " + num(x.omega.norm()) + " rad/s gives a surface speed of " +
                                  num(surface) + " m/s; must be <= " + num(kMaxSpeed) + " m/s (supported range)");
    if (!std::isfinite(x.density) || !(x.density > 0))
      throw std::invalid_argument("density must be finite and > 0 kg/m^3, got " + std::to_string(x.density));
    if (!std::isfinite(x.beta) || !(x.beta > 0))
      throw std::invalid_argument("beta must be finite and > 0, got " + std::to_string(x.beta));
    if (!std::isfinite(x.eps_t) || x.eps_t < -1 || x.eps_t > 1)
      throw std::invalid_argument("eps_t must be in [-1, 1], got " + std::to_string(x.eps_t));
    const double R = c.sphere.radius, mass = 4.0 / 3.0 * std::numbers::pi * R * R * R * x.density;
    if (!std::isnormal(mass) || !std::isnormal(0.4 * mass * R * R))
      throw std::invalid_argument("density " + num(x.density) + " kg/m^3 with radius " + num(R) +
                                  " m gives a mass or moment of inertia outside the range of double");
  }
}

std::vector<Vec3> fresh_cap(std::uint64_t n, std::uint64_t drop, std::uint64_t seed, unsigned k) {
  Stream s(seed, Purpose::fresh, drop);
  const unsigned m = static_cast<unsigned>(std::min<std::uint64_t>(k, n));
  std::vector<Vec3> cap;
  cap.reserve(m);
  double x = 0.0;  // X_(j) so far
  for (unsigned j = 0; j < m; ++j) {
    const double u = s.uniform(), v = s.uniform0();
    // Minimum of n - j uniforms on (x, 1): x + (1 - x)(1 - u^(1/(n-j))); expm1/log keep it
    // accurate when the cap is tiny (x ~ 1/N).
    x = x + (1.0 - x) * -std::expm1(std::log(u) / static_cast<double>(n - j));
    // Direction at polar angle theta from the SOUTH pole (-z): cos theta = 1 - 2x.
    const double sin_t = 2.0 * std::sqrt(x * (1.0 - x));
    const double phi = 2.0 * std::numbers::pi * v;
    cap.emplace_back(sin_t * std::cos(phi), sin_t * std::sin(phi), -(1.0 - 2.0 * x));
  }
  return cap;
}

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void resize(ContactSamples& s, std::size_t n) {
  s.r_x.resize(n), s.r_y.resize(n), s.r_z.resize(n), s.r_xy.resize(n), s.gap.resize(n), s.core.resize(n);
}

void store(ContactSamples& s, std::size_t i, const Contact& c) {
  s.r_x[i] = c.r.x(), s.r_y[i] = c.r.y(), s.r_z[i] = c.r.z(), s.r_xy[i] = c.r_xy;
  s.gap[i] = c.gap, s.core[i] = c.core ? 1 : 0;
}

// Work is cut into fixed chunks so that progress can be reported; results land at their drop
// index, so the chunking never changes a result.
constexpr std::uint64_t kChunk = 4096;

// A progress callback may throw (a cancel request, a Python binding's KeyboardInterrupt). An
// exception must not leave an OpenMP region, so it is caught on the thread that called progress,
// the remaining chunks are skipped, and it is rethrown after the region by rethrow().
class GuardedProgress {
 public:
  explicit GuardedProgress(const Progress& p) : p_(p) {}
  bool stopped() const noexcept { return stop_.load(std::memory_order_relaxed); }
  /// Called by one thread at a time (thread 0 of the team).
  void operator()(std::uint64_t done, std::uint64_t total) noexcept {
    if (!p_ || stopped()) return;
    try {
      p_(done, total);
    } catch (...) {
      error_ = std::current_exception();
      stop_.store(true, std::memory_order_relaxed);
    }
  }
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  const Progress& p_;
  std::atomic<bool> stop_{false};
  std::exception_ptr error_;
};

template <class Body>
void for_chunks(std::uint64_t total, std::uint64_t offset, std::uint64_t grand_total, GuardedProgress& progress,
                Body body) {
  const std::int64_t chunks = static_cast<std::int64_t>((total + kChunk - 1) / kChunk);
  std::atomic<std::uint64_t> done{0};
  LowestIndexError errors;
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t c = 0; c < chunks; ++c) {
    if (progress.stopped() || errors.failed()) continue;
    const std::uint64_t b = static_cast<std::uint64_t>(c) * kChunk, e = std::min(total, b + kChunk);
    errors.run(c, [&] { body(b, e); });
    const std::uint64_t now = done.fetch_add(e - b) + (e - b);
    if (omp_get_thread_num() == 0) progress(offset + now, grand_total);
  }
  errors.rethrow();
  progress.rethrow();
}

// One impact per drop with the closed-form impulse (tested against the general 3x3 solve).
void run_impacts(const EnsembleConfig& c, ContactSamples& s) {
  const auto t0 = Clock::now();
  const auto& x = c.impact;
  const double R = c.sphere.radius;
  const double mass = 4.0 / 3.0 * std::numbers::pi * R * R * R * x.density;
  const double inertia = 0.4 * mass * R * R;  // central sphere only (paper Sec. II)
  const auto eps_n = viscoelastic_pade14(x.beta);
  const std::size_t n = s.r_x.size();
  std::vector<double> eps(n), wx(n), en(n);
  std::vector<std::uint8_t> hit(n);
  const std::int64_t ni = static_cast<std::int64_t>(n);
  LowestIndexError error;  // the error of the lowest drop: the same for any thread count
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < ni; ++i) error.run(i, [&] {
    const std::size_t k = static_cast<std::size_t>(i);
    ImpactState st;
    st.V = Vec3(0, 0, -x.speed);
    st.Omega = x.omega;
    st.r = s.core[k] ? Vec3(0, 0, -R) : Vec3(s.r_x[k], s.r_y[k], s.r_z[k]);
    st.n = Vec3(0, 0, 1);
    const double vn = (st.V + st.Omega.cross(st.r)).dot(st.n);
    if (!(vn < 0)) return;
    const double e = (*eps_n)(-vn);
    // The paper's kinematic law in closed form; another tangential law by its impulse process.
    const auto out = x.tangential.model == TangentialLaw::Model::kinematic
                         ? solve_impact_isotropic(mass, inertia, st, e, x.eps_t)
                         : solve_impact(RigidBody{mass, Eigen::Matrix3d::Identity() * inertia}, st, e, x.tangential);
    if (!out) return;
    hit[k] = 1, eps[k] = out->eps, wx[k] = out->Omega_after.x(), en[k] = e;
  });
  error.rethrow();
  // Compact in drop order: deterministic for any thread count.
  for (std::size_t k = 0; k < n; ++k) {
    if (!hit[k]) {
      ++s.no_impacts;
      continue;
    }
    s.eps.push_back(eps[k]), s.omega_x_after.push_back(wx[k]), s.eps_n.push_back(en[k]);
    s.eps_core.push_back(s.core[k]);
  }
  s.seconds_impact = since(t0);
}

}  // namespace

namespace detail {

SphereCheck cross_check_sphere(const EnsembleConfig& c, std::span<const Vec3> centres,
                               const std::vector<std::pair<Vec3, Nearest>>& answers,
                               const std::vector<Backend>& others, std::uint64_t sphere) {
  SphereCheck r;
  std::vector<std::unique_ptr<ContactQuery>> idx;
  for (Backend b : others)
    if (b != Backend::brute) idx.push_back(make_contact_query(b, centres));
  for (const auto& [d, main] : answers) {
    ++r.queries;
    bool ok = brute_lowest(centres, d) == main;
    for (const auto& q : idx) ok = ok && q->lowest(d) == main;
    if (ok) {
      ++r.agreed;
    } else if (r.first_disagreement.empty()) {
      r.first_disagreement = "sphere " + std::to_string(sphere) + ", direction (" + num(d.x()) + ", " + num(d.y()) +
                             ", " + num(d.z()) + "): backend " + std::string(to_string(c.backend)) + " answered asperity " +
                             std::to_string(main.index) + ", brute force " + std::to_string(brute_lowest(centres, d).index);
    }
  }
  return r;
}

}  // namespace detail

namespace detail {

CheckPlan check_plan(const EnsembleConfig& c) {
  CheckPlan p;
  const std::uint64_t n = c.sphere.asperities, K = c.spheres, m = c.drops / K;
  p.others = cross_check_backends(c.backend, n);
  const double budget = std::max(100.0, std::floor(kCrossCheckScanBudget / double(n)));
  const auto total_checks = static_cast<std::uint64_t>(
      std::min({double(c.drops), 1e4, std::max(100.0, std::min(0.01 * double(c.drops), budget))}));
  // Spheres 0, s, 2s, ...: as many as the quota needs (one when a sphere has enough rotations: each
  // checked sphere costs a kd-tree build, ~25 ms at N = 10^5).
  p.spheres = std::min<std::uint64_t>(K, (total_checks + m - 1) / m);
  p.sphere_stride = K / p.spheres;
  p.per_sphere = std::max<std::uint64_t>(1, (total_checks + p.spheres - 1) / p.spheres);
  p.stride = std::max<std::uint64_t>(1, m / p.per_sphere);
  return p;
}

}  // namespace detail

std::vector<Backend> cross_check_backends(Backend main, std::uint64_t asperities) {
  std::vector<Backend> b;
  for (Backend x : {Backend::brute, Backend::kdtree})
    if (x != main) b.push_back(x);
#if ASPERITY_WITH_FCL
  if (main != Backend::fcl && asperities <= kCrossCheckFclMax) b.push_back(Backend::fcl);
#else
  (void)asperities;
#endif
  return b;
}

namespace {

// Sampled drops: the lowest asperities of a fresh sphere per drop from the exact order statistics.
void sample_drops(const EnsembleConfig& c, GuardedProgress& progress, ContactSamples& s) {
  const double R = c.sphere.radius, a = c.sphere.asperity_radius;
  const std::uint64_t n = c.sphere.asperities;
  s.batches = c.drops;
  const auto t0 = Clock::now();
  for_chunks(c.drops, 0, c.drops, progress, [&](std::uint64_t b, std::uint64_t e) {
    const Rotation identity = Rotation::Identity();  // a fresh random sphere needs no rotation
    const Vec3 down(0, 0, -1);
    for (std::uint64_t i = b; i < e; ++i) {
      const auto cap = fresh_cap(n, i, c.seed);
      const Nearest nn = brute_lowest(cap, down);
      store(s, i, make_contact(nn, cap[nn.index], identity, R, a));
    }
  });
  s.seconds_query = since(t0);
}

using Answers = std::vector<std::pair<Vec3, Nearest>>;

// Rotations [b, e) of sphere k, drops [k m + b, k m + e): the same streams whichever loop runs
// them. Every `stride`-th answer goes to `checks` (up to per_sphere) for the cross-check.
void rotate(const EnsembleConfig& c, const detail::CheckPlan& plan, const RoughSphere& body, const ContactQuery& index,
            std::uint64_t k, std::uint64_t b, std::uint64_t e, Answers* checks, ContactSamples& s) {
  const std::uint64_t m = c.drops / c.spheres;
  detail::query_drops(c, m, body.centres, index, k, b, e, detail::Answers::full,
                          [&](std::uint64_t j, const Contact& contact, const Vec3& down, const Nearest& r) {
                            store(s, k * m + j, contact);
                            if (checks && j % plan.stride == 0 && checks->size() < plan.per_sphere)
                              checks->emplace_back(down, r);
                          });
}

// One sphere: its rotations in parallel. Returns the cross-check's seconds.
double one_sphere(const EnsembleConfig& c, const detail::CheckPlan& plan, GuardedProgress& progress, ContactSamples& s,
                  std::vector<detail::SphereCheck>& checks) {
  const std::uint64_t m = c.drops;
  auto t0 = Clock::now();
  const RoughSphere body = make_rough_sphere(c.sphere, c.seed, 0);
  s.seconds_generate += since(t0);
  t0 = Clock::now();
  const auto index = make_contact_query(c.backend, body.centres);
  s.seconds_index += since(t0);
  s.index_bytes = index->memory_bytes();
  t0 = Clock::now();
  std::vector<Answers> found((m + kChunk - 1) / kChunk);
  for_chunks(m, 0, c.drops, progress,
             [&](std::uint64_t b, std::uint64_t e) { rotate(c, plan, body, *index, 0, b, e, &found[b / kChunk], s); });
  s.seconds_query += since(t0);
  t0 = Clock::now();
  Answers answers;
  for (const auto& f : found)
    for (const auto& x : f)
      if (answers.size() < plan.per_sphere) answers.push_back(x);
  checks[0] = detail::cross_check_sphere(c, body.centres, answers, plan.others, 0);
  return since(t0);
}

// Spheres in parallel, each generated, indexed and queried by one thread: no parallel region per
// sphere (OpenMP barriers cost much on a shared machine). Stage times are summed over threads;
// `query` is the wall time of the whole loop. Returns the cross-check's seconds.
double many_spheres(const EnsembleConfig& c, const detail::CheckPlan& plan, GuardedProgress& progress, ContactSamples& s,
                    std::vector<detail::SphereCheck>& checks) {
  const std::uint64_t m = c.drops / c.spheres;
  const auto t0 = Clock::now();
  const std::int64_t spheres = static_cast<std::int64_t>(c.spheres);
  std::atomic<std::uint64_t> done{0};
  double gen = 0, idx = 0, chk = 0;
  std::size_t bytes = 0;
  LowestIndexError errors;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : gen, idx, chk) reduction(max : bytes)
  for (std::int64_t kk = 0; kk < spheres; ++kk) errors.run(kk, [&] {
    const auto k = static_cast<std::uint64_t>(kk);
    if (progress.stopped() || errors.failed()) return;
    auto t = Clock::now();
    const RoughSphere body = make_rough_sphere(c.sphere, c.seed, k);
    gen += since(t);
    t = Clock::now();
    const auto index = make_contact_query(c.backend, body.centres);
    idx += since(t);
    bytes = std::max(bytes, index->memory_bytes());
    Answers answers;
    const bool checked = plan.checked(k);
    for (std::uint64_t b = 0; b < m; b += kChunk)
      rotate(c, plan, body, *index, k, b, std::min(m, b + kChunk), checked ? &answers : nullptr, s);
    if (checked) {
      t = Clock::now();
      checks[k / plan.sphere_stride] = detail::cross_check_sphere(c, body.centres, answers, plan.others, k);
      chk += since(t);
    }
    const std::uint64_t now = done.fetch_add(m) + m;
    if (omp_get_thread_num() == 0) progress(now, c.drops);
  });
  errors.rethrow();
  progress.rethrow();
  s.seconds_generate = gen, s.seconds_index = idx, s.index_bytes = bytes;
  s.seconds_query = since(t0);  // wall time of the whole loop, generation and indexing included
  return chk;
}

// The cross-check's totals; a disagreement is an error (every backend is exact).
void collect_cross_check(const std::vector<Backend>& others, const std::vector<detail::SphereCheck>& checks, double seconds,
                         ContactSamples& s) {
  s.cross_check.seconds = seconds;
  for (Backend b : others) s.cross_check.backends.emplace_back(to_string(b));
  for (const auto& ch : checks) {
    s.cross_check.queries += ch.queries;
    s.cross_check.agreed += ch.agreed;
  }
  for (const auto& ch : checks)
    if (!ch.first_disagreement.empty())
      throw std::runtime_error("cross-check failed: " + std::to_string(s.cross_check.queries - s.cross_check.agreed) +
                               " of " + std::to_string(s.cross_check.queries) +
                               " re-answered queries disagree with the run's backend; first: " + ch.first_disagreement);
}

// K explicit spheres x M Haar rotations, contacts by the spatial query, a subsample cross-checked.
void explicit_drops(const EnsembleConfig& c, GuardedProgress& progress, ContactSamples& s) {
  s.batches = c.spheres;
  const detail::CheckPlan plan = detail::check_plan(c);
  std::vector<detail::SphereCheck> checks(plan.spheres);
  const double seconds = c.spheres == 1 ? one_sphere(c, plan, progress, s, checks) : many_spheres(c, plan, progress, s, checks);
  collect_cross_check(plan.others, checks, seconds, s);
}

}  // namespace

ContactSamples run_contact_ensemble(const EnsembleConfig& c, const Progress& user_progress) {
  validate(c);
  GuardedProgress progress(user_progress);
  const ThreadCountScope thread_scope(c.threads);
  ContactSamples s;
  s.mode = c.mode;
  resize(s, c.drops);
  if (c.mode == Mode::sampled) sample_drops(c, progress, s);
  else explicit_drops(c, progress, s);
  s.core_contacts = static_cast<std::uint64_t>(std::count(s.core.begin(), s.core.end(), std::uint8_t{1}));
  if (c.impact.enabled) run_impacts(c, s);
  return s;
}

}  // namespace asperity
