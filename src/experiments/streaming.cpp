// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/experiments/streaming.hpp"
#include "asperity/core/thread_count.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <stdexcept>

#include "asperity/core/orientation.hpp"
#include "asperity/core/parallel_errors.hpp"
#include "asperity/core/random.hpp"
#include "asperity/laws/theory.hpp"
#include "experiments/ensemble_detail.hpp"

namespace asperity {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

constexpr std::uint64_t kUnit = 4096;         // rotations per unit (moments merged per unit, in order)
constexpr std::uint64_t kWaveUnits = 16384;   // units per wave (merge, progress, stop, checkpoint between waves)
// Spheres of >= kBigSphereUnits units run their units in parallel (one sphere at a time, built
// between waves) when there are few of them or they are huge; otherwise, as small spheres, one
// whole sphere per thread, so that building one sphere overlaps the queries of the others (at
// N = 1e5 a serial build took ~40% of the run). The statistics do not depend on the path.
constexpr std::uint64_t kBigSphereUnits = 16;
constexpr std::uint64_t kFewSpheres = 8;                  // fewer spheres than this: big path
constexpr std::uint64_t kHugeSphere = 2'000'000;          // more asperities than this: big path (memory per thread)
constexpr std::uint64_t kLongSphereUnits = 1024;          // more units (4e6 rotations) than this: big path (progress)
constexpr std::uint64_t kWaveDrops = 1 << 18; // small spheres: at most this many drops per wave (or one sphere)
constexpr std::size_t kQ = 3;                 // r_xy, r_x, r_y

// One unit's moments, as sums about each quantity's reference mean (Sink::ref_mean): no division per drop.
struct Slot {
  ShiftedSums m[kQ];
  std::uint64_t core = 0;
};

// What the threads of a wave write into: fine counts into their own histograms (folded into the
// state at checkpoints and at the end), coarse counts of their current block into their own cells
// (added atomically -- integers: any order -- when the block changes and at fold()), moments into
// their slot. So a drop costs no atomic operation and no transcendental function. The fine
// histograms (3 x 2^16 x 8 bytes per thread) do not fit in L2 with the index: a drop's three
// increments are made kLag drops later, after a prefetch of their lines (integer counts: the
// order does not matter). Whoever counts on thread t calls drain(t) before its counts are read.
struct Sink {
  static constexpr std::size_t kNoBlock = ~std::size_t{0};
  static constexpr std::size_t kLag = 16;
  struct alignas(64) Pending {
    std::uint32_t f[kLag][kQ];
    std::size_t n = 0;  // drops staged since the last drain
  };
  std::vector<BinnedStats>& stats;
  std::vector<const FineBinner*> bin;            // per quantity
  std::vector<std::vector<std::uint64_t>> fine;  // thread t, quantity q at t * kQ + q
  std::vector<std::vector<std::uint64_t>> cell;  // thread t: quantity q's coarse bin c at q C + c
  std::vector<std::size_t> cell_block;           // thread t: the block its cells count, or kNoBlock
  std::vector<Pending> pending;                  // thread t: fine bins not yet counted
  double ref_mean[kQ];                           // per quantity: its reference law's mean (moments shift)
  std::uint64_t K = 0, G = 0;
  std::size_t block(std::uint64_t k) const { return static_cast<std::size_t>(k * G / K); }

  Sink(std::vector<BinnedStats>& s, std::vector<const FineBinner*> b, std::size_t threads, std::uint64_t spheres)
      : stats(s), bin(std::move(b)), fine(threads * kQ, std::vector<std::uint64_t>(s[0].fine_bins(), 0)),
        cell(threads, std::vector<std::uint64_t>(kQ * s[0].coarse_bins(), 0)), cell_block(threads, kNoBlock),
        pending(threads), K(spheres), G(s[0].blocks) {
    for (std::size_t q = 0; q < kQ; ++q) ref_mean[q] = s[q].ref.mean();
  }

  void count(int t, std::size_t g, const Contact& ct, Slot& slot) {
    const auto ti = static_cast<std::size_t>(t);
    if (cell_block[ti] != g) flush(ti), cell_block[ti] = g;
    std::uint64_t* cells = cell[ti].data();
    const unsigned shift = stats[0].fine_log2 - stats[0].coarse_log2;
    const std::size_t C = stats[0].coarse_bins();
    const double x[kQ] = {ct.r_xy, ct.r.x(), ct.r.y()};
    Pending& p = pending[ti];
    std::uint32_t* staged = p.f[p.n % kLag];
    for (std::size_t q = 0; q < kQ; ++q) {
      const std::size_t f = (*bin[q])(x[q]);
      std::uint64_t* h = fine[ti * kQ + q].data();
      if (p.n >= kLag) ++h[staged[q]];
      staged[q] = static_cast<std::uint32_t>(f);
      __builtin_prefetch(h + f, 1);
      ++cells[q * C + (f >> shift)];
      slot.m[q].add(x[q], ref_mean[q]);
    }
    ++p.n;
    slot.core += ct.core ? 1 : 0;
  }
  void drain(int t) {
    const auto ti = static_cast<std::size_t>(t);
    Pending& p = pending[ti];
    for (std::size_t i = 0; i < std::min(p.n, kLag); ++i)
      for (std::size_t q = 0; q < kQ; ++q) ++fine[ti * kQ + q][p.f[i][q]];
    p.n = 0;
  }
  void flush(std::size_t t) {
    const std::size_t g = cell_block[t], C = stats[0].coarse_bins();
    if (g == kNoBlock) return;
    for (std::size_t q = 0; q < kQ; ++q)
      for (std::size_t c = 0; c < C; ++c)
        if (std::uint64_t& v = cell[t][q * C + c]; v != 0) {
          std::atomic_ref<std::uint64_t>(stats[q].coarse[g * C + c]).fetch_add(v, std::memory_order_relaxed);
          v = 0;
        }
    cell_block[t] = kNoBlock;
  }
  void fold() {
    for (std::size_t t = 0; t < cell.size(); ++t) flush(t);
    for (std::size_t i = 0; i < fine.size(); ++i) {
      auto& dst = stats[i % kQ].fine;
      for (std::size_t b = 0; b < dst.size(); ++b) dst[b] += fine[i][b];
      std::fill(fine[i].begin(), fine[i].end(), 0);
    }
  }
};

// One explicit sphere, built and indexed (timed by the caller).
struct Built {
  RoughSphere body;
  std::unique_ptr<ContactQuery> index;
};

struct Driver {
  const EnsembleConfig& c;
  Sink& sink;
  detail::CheckPlan plan;
  std::uint64_t K, m, units_per_sphere;
  double gen = 0, idx = 0;
  std::size_t bytes = 0;

  Built build(std::uint64_t k, double& g, double& i) const {
    auto t = Clock::now();
    Built b{make_rough_sphere(c.sphere, c.seed, k), nullptr};
    g += since(t);
    t = Clock::now();
    b.index = make_contact_query(c.backend, b.body.centres);
    i += since(t);
    return b;
  }

  // Rotations [j kUnit, ...) of sphere k: the same streams as run_contact_ensemble's.
  void explicit_unit(const Built& b, std::uint64_t k, std::uint64_t j, int t, Slot& slot) const {
    const std::uint64_t lo = j * kUnit, hi = std::min(m, lo + kUnit);
    const std::size_t g = sink.block(k);
    detail::query_drops(c, m, b.body.centres, *b.index, k, lo, hi, detail::Answers::winners,
                            [&](std::uint64_t, const Contact& contact, const Vec3&, const Nearest&) {
                              sink.count(t, g, contact, slot);
                            });
    sink.drain(t);
  }

  // Sampled: "sphere" k is drop k, from the exact law of the lowest asperities (no geometry).
  void sampled_unit(std::uint64_t k, int t, Slot& slot) const {
    const auto cap = fresh_cap(c.sphere.asperities, k, c.seed);
    const Nearest nn = brute_lowest(cap, Vec3(0, 0, -1));
    sink.count(t, sink.block(k),
               make_contact(nn, cap[nn.index], Rotation::Identity(), c.sphere.radius, c.sphere.asperity_radius), slot);
    sink.drain(t);
  }

  // The run's queries of a checked sphere (rotations j % stride == 0, the first per_sphere), asked
  // again of its index (deterministic: the answers the run uses) and of the other backends. The
  // run uses the winners path (lowest_winners): its winner with the full path's runner-up is what
  // the other backends must answer.
  detail::SphereCheck check(const Built& b, std::uint64_t k) const {
    std::vector<std::pair<Vec3, Nearest>> answers;
    for (std::uint64_t r = 0; r < m && answers.size() < plan.per_sphere; r += plan.stride) {
      const Vec3 d = detail::drop_direction(c, k * m + r);
      Nearest full = b.index->lowest(d), win;
      b.index->lowest_winners(std::span<const Vec3>(&d, 1), std::span<Nearest>(&win, 1));
      full.index = win.index, full.key = win.key;
      answers.emplace_back(d, full);
    }
    return detail::cross_check_sphere(c, b.body.centres, answers, plan.others, k);
  }
};

// One FineBinner per distinct reference (r_x and r_y share theirs) and, per quantity, its binner.
struct Binners {
  std::vector<FineBinner> distinct;
  std::vector<const FineBinner*> per_quantity;
  explicit Binners(const std::vector<BinnedStats>& stats) {
    std::vector<std::size_t> which;
    for (std::size_t q = 0; q < stats.size(); ++q) {
      std::size_t w = 0;
      while (w < q && stats[w].ref != stats[q].ref) ++w;
      if (w == q) w = distinct.size(), distinct.emplace_back(stats[q].ref, stats[q].fine_log2);
      else w = which[w];
      which.push_back(w);
    }
    for (std::size_t w : which) per_quantity.push_back(&distinct[w]);  // distinct no longer grows
  }
  Binners(const Binners&) = delete;  // per_quantity points into distinct
  Binners& operator=(const Binners&) = delete;
};

void merge_slots(StreamState& st, const Sink& sink, const std::vector<Slot>& slots, std::uint64_t first_unit,
                 std::uint64_t units_per_sphere) {
  for (std::size_t i = 0; i < slots.size(); ++i) {
    const std::size_t g = sink.block((first_unit + i) / units_per_sphere);
    for (std::size_t q = 0; q < kQ; ++q) st.stats[q].block_moments[g].merge(slots[i].m[q].moments(sink.ref_mean[q]));
    st.core_contacts += slots[i].core;
  }
}

void add_check(StreamState& st, const detail::SphereCheck& ch, std::string& first_error) {
  st.check_queries += ch.queries, st.check_agreed += ch.agreed;
  if (first_error.empty()) first_error = ch.first_disagreement;
}

// Whole spheres [u0 / us, u1 / us) in parallel, each on one thread: build, check, its units in order.
void small_sphere_wave(Driver& dr, StreamState& st, std::uint64_t u0, std::uint64_t u1, std::vector<Slot>& slots,
                       std::string& error) {
  const std::uint64_t us = dr.units_per_sphere, k0 = u0 / us, k1 = u1 / us;
  const bool sampled = dr.c.mode == Mode::sampled;
  double gen = 0, idx = 0;
  std::size_t bytes = 0;
  std::vector<detail::SphereCheck> checks(k1 - k0);
  LowestIndexError errors;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : gen, idx) reduction(max : bytes)
  for (std::int64_t kk = std::int64_t(k0); kk < std::int64_t(k1); ++kk) errors.run(kk, [&] {
    const auto k = static_cast<std::uint64_t>(kk);
    const int t = omp_get_thread_num();
    if (sampled) {
      dr.sampled_unit(k, t, slots[k - k0]);
      return;
    }
    const Built b = dr.build(k, gen, idx);
    bytes = std::max(bytes, b.index->memory_bytes());
    if (dr.plan.checked(k)) checks[k - k0] = dr.check(b, k);
    for (std::uint64_t j = 0; j < us; ++j) dr.explicit_unit(b, k, j, t, slots[(k - k0) * us + j]);
  });
  errors.rethrow();
  dr.gen += gen, dr.idx += idx, dr.bytes = std::max(dr.bytes, bytes);
  for (const auto& ch : checks) add_check(st, ch, error);
}

// Units [u0, u1) of one big sphere in parallel (the sphere is built once, kept across waves).
void big_sphere_wave(Driver& dr, StreamState& st, std::uint64_t u0, std::uint64_t u1, std::vector<Slot>& slots,
                     std::unique_ptr<Built>& current, std::uint64_t& current_k, std::string& error) {
  const std::uint64_t us = dr.units_per_sphere, k = u0 / us;
  if (!current || current_k != k) {
    current = std::make_unique<Built>(dr.build(k, dr.gen, dr.idx));
    current_k = k;
    dr.bytes = std::max(dr.bytes, current->index->memory_bytes());
    // Checked once per sphere, at its first unit (a resumed run past it has its counts already).
    if (u0 % us == 0 && dr.plan.checked(k)) add_check(st, dr.check(*current, k), error);
  }
  const Built& b = *current;
  LowestIndexError errors;
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t u = std::int64_t(u0); u < std::int64_t(u1); ++u)
    errors.run(u, [&] { dr.explicit_unit(b, k, std::uint64_t(u) % us, omp_get_thread_num(), slots[std::uint64_t(u) - u0]); });
  errors.rethrow();
}

// Units per sphere and in all: explicit runs K spheres of ceil(m / kUnit) units; sampled runs one
// unit per drop.
struct Layout {
  std::uint64_t K, m, us;
};
Layout layout(const EnsembleConfig& c) {
  const bool sampled = c.mode == Mode::sampled;
  const std::uint64_t K = sampled ? c.drops : c.spheres, m = sampled ? 1 : c.drops / c.spheres;
  return {K, m, (m + kUnit - 1) / kUnit};
}

}  // namespace

std::pair<std::uint64_t, std::uint64_t> share_units(const EnsembleConfig& c, const StreamShare& share) {
  if (!(share.ranks >= 1 && share.rank >= 0 && share.rank < share.ranks))
    throw std::invalid_argument("stream share: rank " + std::to_string(share.rank) + " of " +
                                std::to_string(share.ranks) + " processes");
  const Layout l = layout(c);
  const std::uint64_t G = std::min<std::uint64_t>(l.K, kStreamBlocks), P = std::uint64_t(share.ranks);
  // The first sphere of block g (block(k) = floor(k G / K)) is ceil(g K / G); g K < 2^58.
  auto first_sphere = [&](std::uint64_t g) { return (g * l.K + G - 1) / G; };
  const std::uint64_t r = std::uint64_t(share.rank);
  return {first_sphere(r * G / P) * l.us, first_sphere((r + 1) * G / P) * l.us};
}

std::uint64_t share_drops(const EnsembleConfig& c, const StreamShare& share) {
  const Layout l = layout(c);
  const auto [u0, u1] = share_units(c, share);
  return (u1 - u0) / l.us * l.m;
}

void merge_shares(StreamState& into, const StreamState& o) {
  if (into.stats.size() != o.stats.size()) throw std::invalid_argument("merge_shares: different statistics");
  for (std::size_t q = 0; q < into.stats.size(); ++q) into.stats[q].merge(o.stats[q]);
  into.next_unit = std::max(into.next_unit, o.next_unit);
  into.core_contacts += o.core_contacts;
  into.check_queries += o.check_queries, into.check_agreed += o.check_agreed;
  into.index_bytes = std::max(into.index_bytes, o.index_bytes);
}

namespace {

// The references of kStreamQuantities (Eq. 14's Rayleigh, Eq. 18's normal twice) and the blocks.
struct Shape {
  std::vector<Reference> refs;
  std::size_t G;
};
Shape shape(const EnsembleConfig& c) {
  const double sigma = 1.0 / std::sqrt(2.0 * std::numbers::pi * areal_density(c.sphere.asperities, c.sphere.radius));
  const std::uint64_t K = c.mode == Mode::sampled ? c.drops : c.spheres;
  return {{{Reference::Kind::rayleigh, sigma}, {Reference::Kind::normal, sigma}, {Reference::Kind::normal, sigma}},
          static_cast<std::size_t>(std::min<std::uint64_t>(K, kStreamBlocks))};
}

// Drops of spheres [a, b) done once units [u0, u1) are (u0 at a sphere's start): the whole spheres
// and the units of the sphere in progress (4096 rotations each; it has more than that left).
std::uint64_t drops_done(const Layout& l, std::uint64_t a, std::uint64_t b, std::uint64_t u0, std::uint64_t u1) {
  const std::uint64_t lo = std::max(a, u0 / l.us), whole_end = std::min(b, u1 / l.us), k = u1 / l.us;
  std::uint64_t n = whole_end > lo ? (whole_end - lo) * l.m : 0;
  if (u1 % l.us != 0 && k >= lo && k < b) n += (u1 % l.us) * kUnit;
  return n;
}

// The layout of initial_stream_state(c), compared without allocating one.
std::string layout_problem(const EnsembleConfig& c, const StreamState& st) {
  const Shape sh = shape(c);
  if (st.stats.size() != sh.refs.size()) return "it holds " + std::to_string(st.stats.size()) + " quantities, not 3";
  for (std::size_t q = 0; q < sh.refs.size(); ++q) {
    const BinnedStats& b = st.stats[q];
    if (b.ref != sh.refs[q] || b.fine_log2 != c.bins_log2 || b.coarse_log2 != kStreamCoarseLog2 || b.blocks != sh.G ||
        b.fine.size() != b.fine_bins() || b.coarse.size() != sh.G * b.coarse_bins() || b.block_moments.size() != sh.G)
      return "the histograms of " + kStreamQuantities[q] + " do not have this run's layout";
  }
  return "";
}

// Block g's moments of quantity q: its count is the drops done, its mean and spread within reach
// of a contact point (|r| <= R + a).
std::string moments_problem(const EnsembleConfig& c, std::size_t q, std::size_t g, const Moments& m, std::uint64_t n) {
  const double reach = 1.01 * (c.sphere.radius + c.sphere.asperity_radius);
  const std::string where = kStreamQuantities[q] + " block " + std::to_string(g);
  if (m.n != n) return where + " counts " + std::to_string(m.n) + " drops in its moments, not " + std::to_string(n);
  if (n == 0 && (m.mean != 0 || m.m2 != 0)) return where + " has moments but no drops";
  if (!(std::abs(m.mean) <= reach && m.m2 >= 0 && m.m2 <= double(n) * 4 * reach * reach))
    return where + " has moments out of range (mean " + std::to_string(m.mean) + ", m2 " + std::to_string(m.m2) + ")";
  return "";
}

// The sum of n counts; all ones on overflow (no run counts that many drops), so that wrapped
// counts never pass for the right total.
std::uint64_t sum(const std::uint64_t* p, std::size_t n) {
  std::uint64_t s = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (__builtin_add_overflow(s, p[i], &s)) return ~std::uint64_t{0};
  return s;
}

}  // namespace

StreamState initial_stream_state(const EnsembleConfig& c) {
  const Shape sh = shape(c);
  StreamState s;
  for (const Reference& ref : sh.refs) s.stats.push_back(make_binned(ref, sh.G, c.bins_log2, kStreamCoarseLog2));
  return s;
}

std::string stream_state_problem(const EnsembleConfig& c, const StreamShare& share, const StreamState& st) {
  if (std::string why = layout_problem(c, st); !why.empty()) return why;
  const Layout l = layout(c);
  const auto [u0, u1] = share_units(c, share);
  if (st.next_unit < u0 || st.next_unit > u1)
    return "its next unit " + std::to_string(st.next_unit) + " lies outside this process's share [" + std::to_string(u0) +
           ", " + std::to_string(u1) + "]";
  const std::uint64_t G = st.stats[0].blocks, C = st.stats[0].coarse_bins();
  const std::uint64_t drops = drops_done(l, 0, l.K, u0, st.next_unit);
  for (std::size_t q = 0; q < kQ; ++q) {
    const BinnedStats& b = st.stats[q];
    if (sum(b.fine.data(), b.fine.size()) != drops)
      return "the fine histogram of " + kStreamQuantities[q] + " does not count the " + std::to_string(drops) + " drops done";
    for (std::uint64_t g = 0; g < G; ++g) {
      const std::uint64_t n = drops_done(l, (g * l.K + G - 1) / G, ((g + 1) * l.K + G - 1) / G, u0, st.next_unit);
      if (sum(b.coarse.data() + g * C, C) != n)
        return "block " + std::to_string(g) + " of " + kStreamQuantities[q] + " does not count its " + std::to_string(n) + " drops";
      if (std::string why = moments_problem(c, q, g, b.block_moments[g], n); !why.empty()) return why;
    }
  }
  const std::uint64_t started = (st.next_unit - u0 + l.us - 1) / l.us;  // spheres begun (each checked at its start)
  if (st.core_contacts > drops) return "it counts more core contacts than drops";
  if (st.check_agreed > st.check_queries || st.check_queries > started * l.m) return "its cross-check counts are impossible";
  if (st.index_bytes > (std::uint64_t{1} << 50)) return "its index size is impossible";
  return "";
}

ContactStream run_contact_stream(const EnsembleConfig& c, const Progress& progress, const StreamHooks& hooks,
                                 const StreamState* resume, const StreamShare& share) {
  validate(c);
  if (c.impact.enabled) throw std::invalid_argument("streaming statistics: contact statistics only (no impact experiment)");
  const ThreadCountScope thread_scope(c.threads);
  ContactStream out;
  out.state = resume ? *resume : initial_stream_state(c);
  if (resume && !(initial_stream_state(c).stats.size() == resume->stats.size() &&
                  resume->stats[0].blocks == initial_stream_state(c).stats[0].blocks &&
                  resume->stats[0].fine_log2 == c.bins_log2))
    throw std::invalid_argument("resume: the checkpoint's statistics do not match this run's configuration");
  StreamState& st = out.state;
  const bool sampled = c.mode == Mode::sampled;
  const auto [K, m, us] = layout(c);
  const auto [first_unit, total_units] = share_units(c, share);
  if (!resume) st.next_unit = first_unit;
  if (st.next_unit < first_unit || st.next_unit > total_units)
    throw std::invalid_argument("resume: the checkpoint's next drop lies outside this process's share of the run");
  const std::uint64_t share_total = share_drops(c, share);
  out.spheres = K, out.rotations = m;
  const Binners binners(st.stats);
  const auto threads = std::size_t(omp_get_max_threads());
  Sink sink(st.stats, binners.per_quantity, threads, K);
  Driver dr{c, sink, sampled ? detail::CheckPlan{} : detail::check_plan(c), K, m, us};
  for (Backend b : dr.plan.others) out.cross_check.backends.emplace_back(to_string(b));
  const bool big = !sampled && us >= kBigSphereUnits && (K < kFewSpheres || c.sphere.asperities > kHugeSphere || us > kLongSphereUnits);
  std::unique_ptr<Built> current;
  std::uint64_t current_k = 0;
  std::string error;
  std::vector<Slot> slots;
  const auto t0 = Clock::now();
  std::uint64_t u = st.next_unit;  // in units (sampled: drops)
  while (u < total_units) {
    // A wave: up to kWaveUnits units; whole spheres (at least two per thread) unless the spheres are
    // big, or a resumed run continues inside a sphere (a checkpoint of the big path): then up to
    // that sphere's end.
    const bool big_wave = big || (!sampled && u % us != 0);
    const std::uint64_t spheres_per_wave = std::max<std::uint64_t>(2 * threads, std::min(kWaveUnits / us, kWaveDrops / m));
    const std::uint64_t u1 = big_wave ? std::min({total_units, u + kWaveUnits, (u / us + 1) * us})
                                      : std::min(total_units, u + spheres_per_wave * us);
    slots.assign(u1 - u, Slot{});
    if (big_wave) big_sphere_wave(dr, st, u, u1, slots, current, current_k, error);
    else small_sphere_wave(dr, st, u, u1, slots, error);
    if (!error.empty())
      throw std::runtime_error("cross-check failed: " + std::to_string(st.check_queries - st.check_agreed) + " of " +
                               std::to_string(st.check_queries) +
                               " re-answered queries disagree with the run's backend; first: " + error);
    merge_slots(st, sink, slots, u, us);
    st.index_bytes = std::max<std::uint64_t>(st.index_bytes, dr.bytes);
    u = st.next_unit = u1;
    if (progress) progress(std::min(share_total, ((u - first_unit) / us) * m + (u % us) * kUnit), share_total);
    const bool stop = u < total_units && hooks.stop && hooks.stop();
    if (stop || (u < total_units && hooks.checkpoint_due && hooks.checkpoint_due())) {
      sink.fold();
      if (hooks.checkpoint) hooks.checkpoint(st);
    }
    if (stop) break;
  }
  sink.fold();
  out.complete = st.next_unit >= total_units;
  out.seconds_generate = dr.gen, out.seconds_index = dr.idx, out.seconds_query = since(t0);
  st.index_bytes = std::max<std::uint64_t>(st.index_bytes, dr.bytes);
  out.index_bytes = static_cast<std::size_t>(st.index_bytes);
  out.cross_check.queries = st.check_queries, out.cross_check.agreed = st.check_agreed;
  for (const auto& s : st.stats) out.memory_bytes += (s.fine.size() * (1 + threads) + s.coarse.size() + threads * s.coarse_bins()) * 8;
  for (const auto& b : binners.distinct) out.memory_bytes += b.memory_bytes();
  return out;
}

}  // namespace asperity
