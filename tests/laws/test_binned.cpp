// SPDX-License-Identifier: GPL-3.0-or-later
// Streaming statistics (laws/binned.hpp): merges are bit-identical to one pass, and every binned
// test is calibrated (a true law rejected at ~alpha over many seeds) and has power (a wrong law
// rejected at the sample size theory predicts). Each calibration states n, statistic and the
// binomial band it must fall in.
#include <gtest/gtest.h>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "asperity/core/random.hpp"
#include "asperity/laws/binned.hpp"

using namespace asperity;

namespace {

const Reference kRef{Reference::Kind::rayleigh, 1.0};

Cdf rayleigh(double sigma) {
  return [sigma](double x) { return x <= 0 ? 0.0 : -std::expm1(-x * x / (2 * sigma * sigma)); };
}

// Sample i of a seed: Rayleigh(scale) by inversion; `spread` != 0 gives block g the scale
// scale * (1 +- spread) (sign from the block's own stream): a quenched law per block whose mixture
// is the law of the pooled sample (mixture_cdf).
double draw(std::uint64_t seed, std::uint64_t i, double scale, std::size_t block = 0, double spread = 0) {
  double s = scale;
  if (spread != 0) s *= Stream(seed, Purpose::test, 1u << 30, block).uniform0() < 0.5 ? 1 - spread : 1 + spread;
  return Reference{Reference::Kind::rayleigh, s}.quantile(Stream(seed, Purpose::test, i).uniform0());
}

Cdf mixture_cdf(double spread) {
  return [spread](double x) { return 0.5 * (rayleigh(1 - spread)(x) + rayleigh(1 + spread)(x)); };
}

// n samples in G blocks of n / G consecutive drops; each block's moments from one pass.
BinnedStats fill(std::uint64_t seed, std::size_t n, std::size_t G, double scale, double spread = 0,
                 unsigned fine_log2 = 12) {
  BinnedStats s = make_binned(kRef, G, fine_log2, 10);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t g = i * G / n;
    const double x = draw(seed, i, scale, g, spread);
    add_sample(s, g, reference_u(kRef, x));
    s.block_moments[g].add(x);
  }
  return s;
}

double band(double alpha, std::size_t seeds) { return 3.5 * std::sqrt(alpha * (1 - alpha) / double(seeds)); }

}  // namespace

TEST(Binned, ChunkedMergeInIndexOrderIsBitIdenticalForAnyThreadCount) {
  // Units of 1000 drops, each accumulated by whichever thread, merged in index order: the same
  // bits with 1 and 2 threads, and the counts equal a single pass.
  const std::size_t n = 200000, unit = 1000, G = 8;
  auto run = [&](int threads) {
    omp_set_num_threads(threads);
    const std::size_t units = n / unit;
    std::vector<BinnedStats> parts(units, make_binned(kRef, G, 16, 10));
#pragma omp parallel for schedule(dynamic, 1)
    for (std::int64_t k = 0; k < std::int64_t(units); ++k)
      for (std::size_t i = std::size_t(k) * unit; i < (std::size_t(k) + 1) * unit; ++i) {
        const std::size_t g = i * G / n;
        const double x = draw(7, i, 1.0);
        add_sample(parts[std::size_t(k)], g, reference_u(kRef, x));
        parts[std::size_t(k)].block_moments[g].add(x);
      }
    BinnedStats all = make_binned(kRef, G, 16, 10);
    for (const auto& p : parts) all.merge(p);
    return all;
  };
  const BinnedStats one = run(1), two = run(2);
  EXPECT_TRUE(one == two);
  const BinnedStats single = fill(7, n, G, 1.0, 0, 16);
  EXPECT_EQ(single.fine, one.fine);
  EXPECT_EQ(single.coarse, one.coarse);
  // Moments of a merge agree with one Welford pass to rounding (merging is not bit-identical to a
  // different order: that is why the order is fixed).
  EXPECT_NEAR(single.moments().mean, one.moments().mean, 1e-14);
  EXPECT_NEAR(single.moments().variance(), one.moments().variance(), 1e-12);
  EXPECT_EQ(one.moments().n, n);
  // And they are right: Rayleigh(1) has mean sqrt(pi/2), variance (4 - pi)/2.
  EXPECT_NEAR(one.moments().mean, std::sqrt(M_PI / 2), 5 * std::sqrt((4 - M_PI) / 2 / double(n)));
}

TEST(Binned, ShiftedSumsAreWelfordsMoments) {
  // The streaming run's per-unit sums about the reference mean give Welford's moments to rounding,
  // for a shift anywhere within a few sd of the mean (Rayleigh(3e-6) samples, like r_xy in metres),
  // and the same bits for the same sequence.
  const double sigma = 3e-6, c = kRef.mean() * sigma;
  for (const double shift : {c, 0.0, c + 3 * sigma}) {
    Moments w;
    ShiftedSums a, b;
    for (std::uint64_t i = 0; i < 4096; ++i) {
      Stream st(3, Purpose::test, i);
      const double x = sigma * std::sqrt(-2 * std::log(st.uniform()));
      w.add(x);
      a.add(x, shift);
      b.add(x, shift);
    }
    const Moments m = a.moments(shift);
    EXPECT_EQ(m.n, w.n);
    EXPECT_NEAR(m.mean, w.mean, 1e-14 * sigma);
    EXPECT_NEAR(m.variance(), w.variance(), 1e-11 * w.variance());
    EXPECT_TRUE(m == b.moments(shift));
  }
  EXPECT_EQ(ShiftedSums{}.moments(1.0).n, 0u);
  EXPECT_EQ((Reference{Reference::Kind::normal, 2.0}.mean()), 0.0);
}

TEST(Binned, MergeRefusesDifferentLayouts) {
  BinnedStats a = make_binned(kRef, 4), b = make_binned(kRef, 8);
  EXPECT_THROW(a.merge(b), std::invalid_argument);
  EXPECT_THROW(make_binned(kRef, 4, 30), std::invalid_argument);
  EXPECT_THROW(reference_u(kRef, std::nan("")), std::invalid_argument);
}

TEST(Binned, ReferenceQuantileInvertsItsCdf) {
  for (const Reference r : {kRef, Reference{Reference::Kind::normal, 2.0}})
    for (double u : {1e-9, 0.001, 0.3, 0.5, 0.9, 0.999999}) EXPECT_NEAR(r.cdf(r.quantile(u)), u, 1e-12 + 1e-9 * u);
}

TEST(Binned, IidCalibrationAndPowerOfKsChi2AndLr) {
  // n = 20000 iid Rayleigh(1) drops per seed, 300 seeds, alpha = 0.05: each test rejects the true
  // law at a rate within 3.5 binomial sd of alpha. binned KS: 2^12 bins; chi^2: 256 cells; LR of
  // Rayleigh(1) against Rayleigh(1.02) on 2^10 cells with 40 blocks of drops.
  const std::size_t seeds = 300, n = 20000;
  const double alpha = 0.05;
  std::size_t ks = 0, chi = 0, lr = 0;
  const Cdf truth = rayleigh(1.0), other = rayleigh(1.02);
  for (std::size_t seed = 1; seed <= seeds; ++seed) {
    const BinnedStats s = fill(seed, n, 40, 1.0);
    ks += binned_ks(s, truth).p < alpha;
    chi += binned_chi2(s, truth, 256).p < alpha;
    lr += binned_lr(s, truth, other).law0.p < alpha;
  }
  const double b = band(alpha, seeds);
  std::printf("iid n = %zu, %zu seeds: rejection rates of the true law: binned KS %.3f, "
              "chi2 %.3f, LR %.3f (alpha %.2f +- %.3f)\n",
              n, seeds, double(ks) / seeds, double(chi) / seeds, double(lr) / seeds, alpha, b);
  EXPECT_NEAR(double(ks) / seeds, alpha, b);  // 1500 seeds gave 0.058 +- 0.006
  EXPECT_NEAR(double(chi) / seeds, alpha, b);
  EXPECT_NEAR(double(lr) / seeds, alpha, b);

  // Power: data from Rayleigh(1.02). The LR needs n* = lr_sample_size(alpha, power 0.9) drops; at
  // n* the true-law hypothesis (Rayleigh 1) must be rejected in >= 75 % of 60 seeds, and at n*/16
  // (a quarter of the effect in z) in far fewer: the size theory predicts is the size that works.
  const double nstar = lr_sample_size(kRef, truth, other, alpha, 0.1);
  std::printf("LR sample size for power 0.9 at alpha 0.05, Rayleigh 1 vs 1.02: %.0f drops\n", nstar);
  ASSERT_GT(nstar, 1000);
  ASSERT_LT(nstar, 20000);
  std::size_t hit = 0, hit_small = 0;
  for (std::size_t seed = 1; seed <= 60; ++seed) {
    hit += binned_lr(fill(1000 + seed, std::size_t(nstar), 40, 1.02), truth, other).law0.p < alpha;
    hit_small += binned_lr(fill(2000 + seed, std::size_t(nstar / 16), 40, 1.02), truth, other).law0.p < alpha;
  }
  std::printf("LR power at n* = %.0f: %zu/60; at n*/16: %zu/60\n", nstar, hit, hit_small);
  EXPECT_GE(hit, 45u);
  EXPECT_LT(hit_small, 25u);
  // The other side of the same test: law 1 (Rayleigh 1.02) is the truth here, so it is kept.
  const LrTest t = binned_lr(fill(99, std::size_t(4 * nstar), 40, 1.02), truth, other);
  EXPECT_LT(t.law0.p, alpha);
  EXPECT_GT(t.law1.p, alpha);
}

TEST(Binned, QuenchedBlocksTakeTheirErrorFromTheSpreadBetweenBlocks) {
  // 20 blocks of 2000 drops, block g with its own scale 1 +- 0.03: the pooled law is the mixture.
  // The LR's block se keeps the level (rate within 3.5 sd of alpha over 200 seeds); the iid binned
  // KS on the same data rejects the true mixture far more often (deliberately wrong use).
  const std::size_t seeds = 200, n = 40000, G = 20;
  const double alpha = 0.05, spread = 0.03;
  const Cdf truth = mixture_cdf(spread), other = rayleigh(1.01);
  std::size_t lr = 0, iid = 0;
  for (std::size_t seed = 1; seed <= seeds; ++seed) {
    const BinnedStats s = fill(seed, n, G, 1.0, spread, 10);
    lr += binned_lr(s, truth, other).law0.p < alpha;
    iid += binned_ks(s, truth).p < alpha;
  }
  std::printf("quenched blocks: LR-block rejection rate of the true law %.3f (alpha %.2f +- %.3f); iid KS %.3f\n",
              double(lr) / seeds, alpha, band(alpha, seeds), double(iid) / seeds);
  EXPECT_NEAR(double(lr) / seeds, alpha, band(alpha, seeds));
  EXPECT_GT(double(iid) / seeds, 0.3) << "the iid p must be wrong here, or this test shows nothing";
}

TEST(Binned, BlockBinsFeedTheSphereBootstrap) {
  const BinnedStats s = fill(5, 50000, 50, 1.0);
  const BlockBins b = to_block_bins(s);
  ASSERT_EQ(b.cells(), s.coarse_bins());
  ASSERT_EQ(b.n, 50000u);
  const std::vector<Cdf> laws{rayleigh(1.0), rayleigh(1.05)};
  const auto r = block_ks_tests(b, laws, 0.01, 5, 0);
  EXPECT_EQ(r[0].verdict, Verdict::accept);
  EXPECT_EQ(r[1].verdict, Verdict::reject);
  const CdfBand band = pooled_cdf(s);
  ASSERT_EQ(band.x.size(), s.coarse_bins() - 1);
  // The pooled cdf at edge j is j/C up to its error band (the reference is the true law).
  for (std::size_t j = 0; j < band.x.size(); j += 97)
    EXPECT_NEAR(band.cdf[j], double(j + 1) / double(s.coarse_bins()), 5 * band.se[j] + 1e-12) << j;
}

// FineBinner (the streaming path's binning): bin j is exactly x_j <= x < x_(j+1) with the edges
// the tests evaluate their laws at, and it agrees with fine_bin(cdf(x)) away from rounding of an
// edge: 2e5 random x per case (the law's bulk and far tails), at 2^10, 2^16 and 2^20 bins. A
// disagreement needs x within ~1e-16 relative of one of 2^20 edges: probability ~1e-10 per x.
TEST(Binned, FineBinnerIsTheEdgeComparisonAndAgreesWithTheCdf) {
  for (const Reference ref : {Reference{Reference::Kind::rayleigh, 3e-6}, Reference{Reference::Kind::normal, 3e-6}})
    for (unsigned k : {10u, 16u, 20u}) {
      const FineBinner bin(ref, k);
      const BinnedStats s = make_binned(ref, 1, k, 10);
      const std::size_t B = s.fine_bins();
      std::size_t disagree = 0;
      for (std::uint64_t i = 0; i < 200000; ++i) {
        Stream st(7, Purpose::test, i, k);
        const double u = st.uniform0(), w = st.uniform0();
        // Half from the law itself, half uniform over +-12 sigma (tails beyond the guess table).
        const double x = i % 2 ? ref.quantile(u) : (ref.kind == Reference::Kind::rayleigh ? 12 * w : 24 * w - 12) * ref.sigma;
        disagree += bin(x) != s.fine_bin(ref.cdf(x));
      }
      EXPECT_EQ(disagree, 0u) << ref.name() << " 2^" << k;
      // The shortcut (no edge read) applies to most samples at the default 2^16 bins.
      if (k <= 16) {
        EXPECT_LT(bin.slack(), 0.05) << ref.name() << " 2^" << k;
      }
      // At every 97th edge: x_j is in bin j, the double below it in bin j - 1 (edges are distinct here).
      for (std::size_t j = 1; j < B; j += 97) {
        const double e = ref.quantile(double(j) / double(B));
        ASSERT_EQ(bin(e), j) << ref.name() << " 2^" << k;
        ASSERT_EQ(bin(std::nextafter(e, -1.0)), j - 1) << ref.name() << " 2^" << k;
      }
      EXPECT_EQ(bin(std::numeric_limits<double>::infinity()), B - 1);
      EXPECT_EQ(bin(-std::numeric_limits<double>::infinity()), 0u);
      EXPECT_LT(bin(std::numeric_limits<double>::quiet_NaN()), B);
    }
}

// binned_ks's D by hand: the KS distance at the grid points x_j = ref.quantile(j / B), where the
// empirical cdf is the count of bins below j (bin j holds x_j <= x < x_(j+1)). At 2^16 bins and
// ~10^10 streamed drops a one-bin shift of that count is as large as the KS critical value, and the
// rejection-rate tests cannot see it: here every sample in fine bin 3 of 16 gives D =
// max(F(x_3), 1 - F(x_4)) = 12/16 exactly (a count shifted by one bin would give 13/16); and a
// sample of another law gives D equal to the direct count at every edge.
TEST(Binned, KsDistanceIsTheEcdfAtTheBinEdgesCountedByHand) {
  const Reference ref{Reference::Kind::rayleigh, 1.0};
  BinnedStats one = make_binned(ref, 1, 4, 4);
  one.fine[3] = 1000;
  EXPECT_NEAR(binned_ks(one, [&](double x) { return ref.cdf(x); }).value, 0.75, 1e-12);
  one.fine[3] = 0, one.fine[0] = 600, one.fine[15] = 400;  // D = max(1 - F(x_1) ... ) at j = 1
  EXPECT_NEAR(binned_ks(one, [&](double x) { return ref.cdf(x); }).value, 0.6 - 1.0 / 16, 1e-12);

  const unsigned k = 8;
  BinnedStats s = make_binned(ref, 1, k, 4);
  const std::size_t B = s.fine_bins(), n = 3000;
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = 1.15 * ref.quantile(Stream(5, Purpose::test, i).uniform0());  // a stretched law: D ~ 0.1
    add_sample(s, 0, reference_u(ref, x[i]));
  }
  std::sort(x.begin(), x.end());
  const Cdf truth = [](double v) { return v <= 0 ? 0.0 : 1.0 - std::exp(-v * v / 2.0); };
  double want = 0;
  for (std::size_t j = 1; j < B; ++j) {
    const double e = ref.quantile(double(j) / double(B));
    const auto below = std::lower_bound(x.begin(), x.end(), e) - x.begin();
    want = std::max(want, std::abs(double(below) / double(n) - truth(e)));
  }
  EXPECT_NEAR(binned_ks(s, truth).value, want, 1e-12);
  EXPECT_GT(want, 0.02);
}
