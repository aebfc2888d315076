// SPDX-License-Identifier: GPL-3.0-or-later
// The streaming path (experiments/streaming.hpp): the same drops as the raw path, the same bits for
// any thread count, and an interrupted-and-resumed run ends with the same bits as an uninterrupted one.
#include <gtest/gtest.h>

#include <omp.h>

#include "sanitized.hpp"
#include "asperity/experiments/streaming.hpp"

using namespace asperity;

namespace {

EnsembleConfig config(Mode mode, std::uint64_t spheres, std::uint64_t drops, std::uint64_t n = 1000) {
  EnsembleConfig c;
  c.sphere.asperities = n;
  c.mode = mode;
  c.spheres = spheres;
  c.drops = drops;
  c.seed = 11;
  c.statistics = Statistics::streaming;
  return c;
}

StreamState run(EnsembleConfig c, int threads) {
  c.threads = threads;
  return run_contact_stream(c).state;
}

}  // namespace

TEST(Streaming, CountsTheSameDropsAsTheRawPath) {
  for (const auto& c : {config(Mode::explicit_spheres, 40, 40 * 500), config(Mode::sampled, 1, 30000)}) {
    EnsembleConfig raw = c;
    raw.statistics = Statistics::raw;
    const ContactSamples s = run_contact_ensemble(raw);
    const ContactStream st = run_contact_stream(c);
    ASSERT_TRUE(st.complete);
    const std::vector<const std::vector<double>*> cols{&s.r_xy, &s.r_x, &s.r_y};
    for (std::size_t q = 0; q < 3; ++q) {
      BinnedStats b = initial_stream_state(c).stats[q];
      const std::size_t K = c.mode == Mode::sampled ? c.drops : c.spheres, m = c.drops / K;
      for (std::size_t i = 0; i < cols[q]->size(); ++i) {
        const std::size_t g = (i / m) * b.blocks / K;
        add_sample(b, g, b.ref.cdf((*cols[q])[i]));
      }
      EXPECT_EQ(b.fine, st.state.stats[q].fine) << q;
      EXPECT_EQ(b.coarse, st.state.stats[q].coarse) << q;
      double mean = 0;
      for (double x : *cols[q]) mean += x;
      mean /= double(cols[q]->size());
      EXPECT_NEAR(st.state.stats[q].moments().mean, mean, 1e-12 * (std::abs(mean) + 1e-6)) << q;
      EXPECT_EQ(st.state.stats[q].moments().n, c.drops);
    }
    EXPECT_EQ(st.state.core_contacts, s.core_contacts);
    if (c.mode == Mode::explicit_spheres) {
      EXPECT_GT(st.cross_check.queries, 0u);
      EXPECT_EQ(st.cross_check.queries, st.cross_check.agreed);
    }
  }
}

TEST(Streaming, SameBitsForOneAndTwoThreads) {
  // Small spheres (whole spheres per thread), big spheres (one sphere's units in parallel), big
  // spheres but enough of them (whole spheres per thread: 18 units each), sampled.
  for (const auto& c : {config(Mode::explicit_spheres, 64, 64 * 300), config(Mode::explicit_spheres, 2, 2 * 80000),
                        config(Mode::explicit_spheres, 8, 8 * 70000),
                        config(Mode::sampled, 1, 50000)})
    EXPECT_TRUE(run(c, 1) == run(c, 2)) << to_string(c.mode) << " K = " << c.spheres;
}

TEST(Streaming, SameBitsForScalarAndSimdKernels) {
  // The drop kernel's instantiations (core/drop_kernel.hpp): scalar on one thread, simd on two.
  for (const auto& base : {config(Mode::explicit_spheres, 16, 16 * 1000), config(Mode::explicit_spheres, 2, 2 * 20000, 30000)}) {
    EnsembleConfig scalar = base, simd = base;
    scalar.kernel = Kernel::scalar, simd.kernel = Kernel::simd;
    EXPECT_TRUE(run(scalar, 1) == run(simd, 2)) << " K = " << base.spheres;
  }
}

TEST(Streaming, InterruptedAndResumedEqualsUninterrupted) {
  for (const auto& c : {config(Mode::explicit_spheres, 2, 2 * 80000), config(Mode::sampled, 1, 70000)}) {
    const StreamState whole = run(c, 2);
    StreamState saved;
    int waves = 0, checkpoints = 0;
    StreamHooks h;
    h.stop = [&] { return ++waves == 1; };
    h.checkpoint = [&](const StreamState& s) { saved = s, ++checkpoints; };
    const ContactStream first = run_contact_stream(c, {}, h);
    ASSERT_FALSE(first.complete);
    ASSERT_EQ(checkpoints, 1);
    EXPECT_TRUE(saved == first.state);
    EnsembleConfig one = c;
    one.threads = 1;  // resumed with another thread count
    const ContactStream rest = run_contact_stream(one, {}, {}, &saved);
    ASSERT_TRUE(rest.complete);
    EXPECT_TRUE(rest.state == whole) << to_string(c.mode);
  }
}

TEST(Streaming, RefusesImpactsAndMismatchedCheckpoints) {
  EnsembleConfig c = config(Mode::explicit_spheres, 4, 400);
  c.impact.enabled = true;
  EXPECT_THROW(run_contact_stream(c), std::invalid_argument);
  c.impact.enabled = false;
  StreamState other = initial_stream_state(config(Mode::explicit_spheres, 4, 400));
  c.bins_log2 = 18;
  EXPECT_THROW(run_contact_stream(c, {}, {}, &other), std::invalid_argument);
}

TEST(Streaming, AutomaticStatisticsStreamOnlyLargeContactRuns) {
  EnsembleConfig c = config(Mode::explicit_spheres, 50, 50 * 1000);
  c.statistics = Statistics::automatic;
  EXPECT_FALSE(uses_streaming(c));
  c.drops = kStreamingAutoDrops + 50 - kStreamingAutoDrops % 50;
  EXPECT_TRUE(uses_streaming(c));
  c.impact.enabled = true;  // impacts need every drop: raw samples
  EXPECT_FALSE(uses_streaming(c));
  c.impact.enabled = false;
  c.statistics = Statistics::raw;
  c.drops = (std::uint64_t{1} << 31) + 50;
  c.spheres = 2;
  EXPECT_THROW(validate(c), std::invalid_argument);  // raw samples stop at 2^31
  c.statistics = Statistics::streaming;
  EXPECT_NO_THROW(validate(c));
  c.bins_log2 = 25;
  EXPECT_THROW(validate(c), std::invalid_argument);
  EXPECT_EQ(parse_statistics("streaming"), Statistics::streaming);
  EXPECT_THROW(parse_statistics("fast"), std::invalid_argument);
}

// A run split across P processes (validate-geometry under mpirun): the shares tile the run's units
// in whole blocks of spheres, and merging them, in any order, gives the bits of one process's run.
TEST(Streaming, SharesMergeToTheSameBitsAsOneProcess) {
  // G = K blocks of one sphere; G = 256 blocks of several spheres; big spheres (K < P for P = 3, 5:
  // some processes have nothing to do); sampled drops. Under the sanitizers P = 3 alone (K = 2 < P
  // still leaves a process without work; 11 runs per configuration become 4).
  const std::vector<int> process_counts = asperity::testing::kSanitized ? std::vector<int>{3} : std::vector<int>{2, 3, 5};
  for (const auto& c : {config(Mode::explicit_spheres, 64, 64 * 300), config(Mode::explicit_spheres, 600, 600 * 40),
                        config(Mode::explicit_spheres, 2, 2 * 80000), config(Mode::sampled, 1, 50000)}) {
    const StreamState whole = run(c, 2);
    for (int P : process_counts) {
      std::vector<StreamState> parts;
      std::uint64_t next = 0, drops = 0;
      for (int r = 0; r < P; ++r) {
        const auto [u0, u1] = share_units(c, {r, P});
        EXPECT_EQ(u0, next) << "shares tile the units in order";
        next = u1;
        drops += share_drops(c, {r, P});
        EnsembleConfig one = c;
        one.threads = 1 + r % 2;
        parts.push_back(run_contact_stream(one, {}, {}, nullptr, {r, P}).state);
      }
      EXPECT_EQ(drops, c.drops);
      StreamState forward = parts[0], backward = parts[std::size_t(P - 1)];
      for (int r = 1; r < P; ++r) merge_shares(forward, parts[std::size_t(r)]);
      for (int r = P - 2; r >= 0; --r) merge_shares(backward, parts[std::size_t(r)]);
      EXPECT_TRUE(forward == whole) << to_string(c.mode) << " K = " << c.spheres << ", P = " << P;
      EXPECT_TRUE(backward == whole) << to_string(c.mode) << " K = " << c.spheres << ", P = " << P;
    }
  }
  EXPECT_THROW(share_units(config(Mode::sampled, 1, 100), {2, 2}), std::invalid_argument);
}
