// SPDX-License-Identifier: GPL-3.0-or-later
// Exact laws of the contact with level radii, the O(1) fresh sampler, and explicit bodies agree;
// a deliberately wrong law is rejected by the same tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "asperity/core/random.hpp"
#include "asperity/laws/statistics.hpp"
#include "asperity/core/support.hpp"
#include "asperity/laws/theory.hpp"
#include "asperity/laws/theory_radii.hpp"

using namespace asperity;

namespace {
const RadiusDistribution kTwo = RadiusDistribution::discrete({7e-7, 6.5e-7}, {0.3, 0.7});

std::vector<double> fresh_rx(std::uint64_t n, double R, const RadiusDistribution& d, std::uint64_t drops,
                             std::uint64_t seed) {
  std::vector<double> x(drops);
  for (std::uint64_t k = 0; k < drops; ++k) x[k] = fresh_levels_contact(n, R, d, seed, k).r.x();
  std::sort(x.begin(), x.end());
  return x;
}
}  // namespace

TEST(TheoryRadii, OneLevelIsTheEqualRadiusLaw) {
  const Law a = levels_sphere_rxy(1000, 3e-3, RadiusDistribution::fixed(6.5e-7));
  const Law b = exact_sphere_rxy(1000, 3e-3);
  for (double t = 0; t < 4e-4; t += 1e-5) ASSERT_NEAR(a.cdf(t), b.cdf(t), 1e-12) << t;
  // Two levels of the same radius are one level.
  const Law c = levels_sphere_rxy(1000, 3e-3, RadiusDistribution::discrete({6.5e-7, 6.5e-7}, {0.4, 0.6}));
  for (double t = 0; t < 4e-4; t += 1e-5) ASSERT_NEAR(c.cdf(t), b.cdf(t), 1e-12) << t;
  const Law rx = levels_sphere_rx(1000, 3e-3, RadiusDistribution::fixed(6.5e-7));
  const Law rx0 = exact_sphere_rx(1000, 3e-3);
  for (double t = -3e-4; t < 3e-4; t += 1e-5) ASSERT_NEAR(rx.cdf(t), rx0.cdf(t), 1e-7) << t;
}

TEST(TheoryRadii, FreshSamplerFollowsTheExactLawAndAWrongLawIsRejected) {
  // n = 20000 iid fresh drops, one-sample KS at alpha = 0.01 (fixed seed). Power: the same test
  // at the same n must reject the law stretched by 5% (the cdf moves by ~0.05 x 0.24 = 0.012 at
  // one sigma, above the 1% critical D = 1.63/sqrt(n) = 0.0115).
  const std::uint64_t N = 100000;
  const double R = 3e-3;
  const auto x = fresh_rx(N, R, kTwo, 20000, 11);
  const KsResult good = ks_one_sample(x, levels_sphere_rx(N, R, kTwo).cdf);
  EXPECT_GT(good.p, 0.01) << "D = " << good.D;
  const KsResult wrong = ks_one_sample(x, levels_sphere_rx(N, R, kTwo, 1.05).cdf);
  EXPECT_LT(wrong.p, 0.01) << "D = " << wrong.D;
}

TEST(TheoryRadii, FreshSamplerEqualsExplicitBodies) {
  // The O(1) sampler and explicit spheres (support tree) give the same law of r_xy: two-sample KS,
  // 1000 explicit spheres of N = 1000 with one random orientation each vs 1000 fresh drops.
  const std::uint64_t N = 1000, K = 1000;
  const double R = 3e-3;
  SphereParams p;
  p.asperities = N;
  p.radius = R;
  std::vector<double> ex(K), fr(K);
  for (std::uint64_t k = 0; k < K; ++k) {
    const RoughBody b = make_rough_sphere_body(p, kTwo, 5, k);
    const auto q = make_support_tree(b.centres, b.radii);
    Stream st(5, Purpose::orientation, k);
    const Rotation rot = random_rotation(st);
    const BodyContact c = make_body_contact(q->support(body_down(rot)), b, rot);
    ex[k] = std::hypot(c.r.x(), c.r.y());
    const Vec3 r = fresh_levels_contact(N, R, kTwo, 6, k).r;
    fr[k] = std::hypot(r.x(), r.y());
  }
  std::sort(ex.begin(), ex.end());
  std::sort(fr.begin(), fr.end());
  EXPECT_GT(ks_two_sample(ex, fr).p, 0.01);
  EXPECT_GT(ks_one_sample(ex, levels_sphere_rxy(N, R, kTwo).cdf).p, 0.01);
  // Power at this size: a sampler with the wrong density (N x 1.5, r_xy 18% smaller: what a
  // mistaken area or count would do) must be told apart from the explicit bodies by the same
  // two-sample test; so must the law for that N by the one-sample test.
  std::vector<double> wrong(K);
  for (std::uint64_t k = 0; k < K; ++k) {
    const Vec3 r = fresh_levels_contact(N * 3 / 2, R, kTwo, 6, k).r;
    wrong[k] = std::hypot(r.x(), r.y());
  }
  std::sort(wrong.begin(), wrong.end());
  EXPECT_LT(ks_two_sample(ex, wrong).p, 0.01);
  EXPECT_LT(ks_one_sample(ex, levels_sphere_rxy(N * 3 / 2, R, kTwo).cdf).p, 0.01);
}

TEST(TheoryRadii, BadInputIsRefused) {
  EXPECT_THROW(fresh_levels_contact(100, 3e-3, RadiusDistribution::lognormal(1e-6, 0.3), 1, 1), std::invalid_argument);
  EXPECT_THROW(levels_sphere_rxy(0, 3e-3, kTwo), std::invalid_argument);
  EXPECT_THROW(levels_sphere_rxy(10, 1e-7, kTwo), std::invalid_argument);
  EXPECT_THROW(gaussian_rx(-1, "x"), std::invalid_argument);
}
