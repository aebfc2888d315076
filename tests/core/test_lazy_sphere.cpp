// SPDX-License-Identifier: GPL-3.0-or-later
// The lazy exact sphere: same centres and same answers as an explicit sphere, exactly N centres,
// uniform, and an exact binomial sampler.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "asperity/core/contact.hpp"
#include "asperity/core/lazy_sphere.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/random.hpp"
#include "asperity/laws/statistics.hpp"

using namespace asperity;

TEST(LazySphere, CountIsExactlyN) {
  for (std::uint64_t n : {1ull, 2ull, 7ull, 8ull, 9ull, 513ull, 10007ull, 100000ull}) {
    LazySphere s(n, 3, 1);
    const auto c = s.materialise();
    EXPECT_EQ(c.size(), n);
    for (const auto& u : c) ASSERT_NEAR(u.norm(), 1.0, 1e-15);
  }
  EXPECT_THROW(LazySphere(0, 1, 1), std::invalid_argument);
}

TEST(LazySphere, QueriesEqualBruteForceOnTheMaterialisedSphere) {
  // Random directions, directions at centres (key 0) and exact midpoints of centre pairs
  // (near-ties), queried on a fresh lazy sphere (cells generated on demand, in query order) and
  // compared bit for bit with brute_lowest over the same indexed centres.
  for (std::uint64_t n : {1ull, 5ull, 2000ull, 60000ull}) {
    LazySphere full(n, 11, 4);
    const auto centres = full.materialise();
    LazySphere lazy(n, 11, 4);
    Stream st(5, Purpose::test, n);
    std::vector<Vec3> dirs;
    for (int i = 0; i < 1500; ++i) dirs.push_back(body_down(random_rotation(st)));
    for (std::size_t i = 0; i < std::min<std::size_t>(n, 200); ++i) dirs.push_back(centres[(i * 7919) % n]);
    for (int i = 0; i < 200 && n > 1; ++i) {
      const Vec3 a = centres[(i * 31) % n], b = centres[(i * 31 + 1) % n];
      if ((a + b).norm() > 1e-3) dirs.push_back((a + b).normalized());
    }
    // The poles (dxy = 0) and the seam phi = 0 = 2 pi, where psi = atan2 jumps from pi to -pi
    // (the deferred centres' bound reduces phi - psi across it).
    for (double e : {0.0, 1e-300, 1e-15, 1e-9, 1e-4})
      for (double sz : {-1.0, 1.0}) {
        dirs.push_back(Vec3(e, 0, sz).normalized()), dirs.push_back(Vec3(-1, e, sz * 1e-3).normalized());
        dirs.push_back(Vec3(-1, -e, sz * 0.3).normalized()), dirs.push_back(Vec3(1, sz * e, 0.1).normalized());
      }
    for (const auto& d : dirs) {
      const auto got = lazy.lowest(d);
      const auto want = brute_lowest(centres, d);
      ASSERT_EQ(got.nearest, want) << "N = " << n;
      ASSERT_EQ(got.u, centres[want.index]);
    }
    // Queries only generated part of the big sphere, and what they generated is the same sphere.
    if (n == 60000) {
      EXPECT_LT(lazy.centres_generated(), n);
    }
    EXPECT_EQ(lazy.materialise(), centres);
  }
}

TEST(LazySphere, ResetGivesTheSameOrAnotherSphere) {
  LazySphere s(1000, 1, 1);
  const auto a = s.materialise();
  s.reset(1, 2);
  const auto b = s.materialise();
  s.reset(1, 1);
  EXPECT_EQ(s.materialise(), a);
  EXPECT_NE(a, b);
  // The tables of split-point functions carry over reset(): queries on a sphere that another one
  // filled them for see the same cells, bounds and answers as on a fresh object (N = 1e6, where the
  // tables matter; the cells generated would differ if a cached bound did).
  LazySphere fresh(1000000, 3, 7), used(1000000, 3, 6);
  Stream d(17, Purpose::test, 0);
  for (int k = 0; k < 40; ++k) used.lowest(random_rotation(d) * Vec3(0, 0, -1));
  used.reset(3, 7);
  for (int k = 0; k < 40; ++k) {
    const Vec3 dir = random_rotation(d) * Vec3(0, 0, -1);
    const auto x = fresh.lowest(dir), y = used.lowest(dir);
    ASSERT_EQ(x.nearest.index, y.nearest.index);
    ASSERT_EQ(x.nearest.key, y.nearest.key);
    ASSERT_EQ(x.nearest.runner_up_key, y.nearest.runner_up_key);
    ASSERT_EQ(x.u, y.u);
    ASSERT_EQ(fresh.cells_generated(), used.cells_generated());
  }
}

TEST(LazySphere, CentresAreUniform) {
  // KS of z against U(-1,1) and of phi against U(0, 2 pi) at N = 1e5 (alpha = 0.001 each).
  // Power check: the same test rejects the slightly wrong law F(z) = ((1+z)/2)^1.03.
  LazySphere s(100000, 2, 0);
  const auto c = s.materialise();
  std::vector<double> z, phi;
  for (const auto& u : c) z.push_back(u.z()), phi.push_back(std::atan2(u.y(), u.x()) + std::numbers::pi);
  std::sort(z.begin(), z.end());
  std::sort(phi.begin(), phi.end());
  const auto kz = ks_one_sample(z, [](double t) { return std::clamp((t + 1) / 2, 0.0, 1.0); });
  const auto kp = ks_one_sample(phi, [](double t) { return std::clamp(t / (2 * std::numbers::pi), 0.0, 1.0); });
  EXPECT_GT(kz.p, 1e-3) << kz.D;
  EXPECT_GT(kp.p, 1e-3) << kp.D;
  const auto wrong = ks_one_sample(z, [](double t) { return std::pow(std::clamp((t + 1) / 2, 0.0, 1.0), 1.03); });
  EXPECT_LT(wrong.p, 1e-3);
}

namespace {
double binom_cdf(std::uint64_t n, double x) {
  if (x < 0) return 0;
  const auto k = std::min<std::uint64_t>(n, static_cast<std::uint64_t>(std::floor(x)));
  double s = 0;
  for (std::uint64_t j = 0; j <= k; ++j)
    s += std::exp(std::lgamma(n + 1.0) - std::lgamma(j + 1.0) - std::lgamma(n - j + 1.0) - n * std::numbers::ln2);
  return std::min(1.0, s);
}
}  // namespace

TEST(LazySphere, BinomialHalfIsExact) {
  // Pearson chi-square against the exact pmf, 2e5 draws, for the popcount branch (n = 300) and
  // the inversion branch (n = 5000); both must accept at alpha = 0.001, and the same test must
  // reject the draws shifted by one (a deliberately wrong law).
  for (std::uint64_t n : {300ull, 5000ull}) {
    Stream s(9, Purpose::test, n);
    std::vector<double> x(200000);
    for (auto& v : x) v = static_cast<double>(binomial_half(n, s));
    const double sd = std::sqrt(n / 4.0);
    const double lo = std::floor(n / 2.0 - 6 * sd) - 0.5, hi = std::floor(n / 2.0 + 6 * sd) + 0.5;
    const auto h = make_histogram(x, lo, hi, static_cast<std::size_t>(hi - lo));
    const auto r = chi2_test(h, [n](double t) { return binom_cdf(n, t); });
    EXPECT_GT(r.p, 1e-3) << "n = " << n << " chi2 = " << r.chi2;
    for (auto& v : x) v += 1;
    const auto hw = make_histogram(x, lo, hi, static_cast<std::size_t>(hi - lo));
    EXPECT_LT(chi2_test(hw, [n](double t) { return binom_cdf(n, t); }).p, 1e-3);
  }
}

TEST(LazySphere, BinomialHalfDrawsAreFixed) {
  // The draws every lazy sphere (and so every explicit bounce result) depends on, pinned from the
  // scalar sampler before its walk used two-lane divisions and a mode cache: a hash of 1000 draws
  // per n across both branches; with a cache (covering n or not) the draws are the same.
  const std::pair<std::uint64_t, std::uint64_t> want[] = {
      {7, 2986603431759716219ull},     {300, 17951996477380051156ull},     {512, 386676000199209128ull},
      {513, 3220165823411206510ull},   {5000, 5938424092081481772ull},     {1000000, 2409488226478646944ull},
      {123456789, 5761329368348490557ull}};
  BinomialModeCache small(1000), big(2000000);
  for (const auto& [n, hash] : want)
    for (BinomialModeCache* cache : {static_cast<BinomialModeCache*>(nullptr), &small, &big, &big}) {
      Stream c(11, Purpose::test, n);
      std::uint64_t h = 0;
      for (int i = 0; i < 1000; ++i) h = h * 1000003ull + binomial_half(n, c, cache);
      EXPECT_EQ(h, hash) << "n = " << n;
    }
}

