// SPDX-License-Identifier: GPL-3.0-or-later
// The exact support query with unequal radii: the tree returns bit-for-bit what the brute-force
// scan returns, on random, tied and nearly tied directions.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "asperity/core/body.hpp"
#include "asperity/core/contact.hpp"
#include "asperity/core/random.hpp"
#include "asperity/core/support.hpp"

using namespace asperity;

namespace {

Vec3 random_direction(Stream& s) { return uniform_on_sphere(s.uniform0(), s.uniform0()); }

void expect_same(const SupportQuery& q, const RoughBody& b, const Vec3& d) {
  const Support want = brute_support(b.centres, b.radii, d);
  const Support got = q.support(d);
  ASSERT_EQ(got, want) << "d = (" << d.x() << ", " << d.y() << ", " << d.z() << ")";
}

RoughBody two_level_sphere(std::uint64_t n, std::uint64_t id) {
  SphereParams p;
  p.asperities = n;
  p.radius = 3e-3;
  return make_rough_sphere_body(p, RadiusDistribution::discrete({2e-6, 5e-7}, {0.2, 0.8}), 7, id);
}

}  // namespace

TEST(Radii, DistributionsAreValidatedAndSampled) {
  EXPECT_THROW(validate(RadiusDistribution::fixed(-1)), std::invalid_argument);
  EXPECT_THROW(validate(RadiusDistribution::lognormal(1e-6, NAN)), std::invalid_argument);
  EXPECT_THROW(validate(RadiusDistribution::discrete({1e-6, 2e-6}, {0.5, 0.6})), std::invalid_argument);
  EXPECT_THROW(validate(RadiusDistribution::discrete({1e-6}, {0.5, 0.5})), std::invalid_argument);
  try {
    validate(RadiusDistribution::discrete({1e-6, 0.0}, {0.5, 0.5}));
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("radius level 1"), std::string::npos) << e.what();
  }
  // Level fractions: binomial check of 10^5 draws, 5 sigma.
  const auto d = RadiusDistribution::discrete({2e-6, 5e-7}, {0.2, 0.8});
  int big = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    Stream s(3, Purpose::test, i);
    big += sample_radius(d, s) == 2e-6;
  }
  EXPECT_NEAR(big, 0.2 * n, 5 * std::sqrt(n * 0.2 * 0.8));
  // Lognormal: median and sd of ln rho (10^5 draws, 5 se).
  const auto ln = RadiusDistribution::lognormal(1e-6, 0.3);
  double m = 0, m2 = 0;
  for (int i = 0; i < n; ++i) {
    Stream s(4, Purpose::test, i);
    const double x = std::log(sample_radius(ln, s) / 1e-6);
    m += x;
    m2 += x * x;
  }
  m /= n;
  EXPECT_NEAR(m, 0.0, 5 * 0.3 / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(m2 / n - m * m), 0.3, 5 * 0.3 / std::sqrt(2.0 * n));
}

TEST(Radii, SphereBodyKeepsTheEqualRadiusCentres) {
  SphereParams p;
  p.asperities = 1000;
  const RoughSphere s = make_rough_sphere(p, 11, 3);
  const RoughBody b = make_rough_sphere_body(p, RadiusDistribution::lognormal(6.5e-7, 0.5), 11, 3);
  for (std::size_t i = 0; i < s.centres.size(); ++i) ASSERT_EQ(b.centres[i], p.radius * s.centres[i]);
  EXPECT_NEAR(b.inertia(0, 0), 0.4 * b.mass * p.radius * p.radius, 1e-20);
  // Radii larger than R are refused, naming the value.
  EXPECT_THROW(make_rough_sphere_body(p, RadiusDistribution::fixed(4e-3), 1, 1), std::invalid_argument);
}

TEST(Support, TreeEqualsBruteOnRandomDirections) {
  for (std::uint64_t n : {1ull, 2ull, 9ull, 100ull, 20000ull}) {
    const RoughBody b = two_level_sphere(n, n);
    const auto q = make_support_tree(b.centres, b.radii);
    for (int k = 0; k < 3000; ++k) {
      Stream s(5, Purpose::test, k);
      expect_same(*q, b, random_direction(s));
    }
  }
}

TEST(Support, TreeEqualsBruteOnNearTies) {
  // Directions pointing exactly at an asperity centre, and half-way between two neighbours:
  // the top two are then separated by rounding-level differences only.
  const RoughBody b = two_level_sphere(5000, 1);
  const auto q = make_support_tree(b.centres, b.radii);
  for (std::uint32_t i = 0; i < 2000; ++i) {
    expect_same(*q, b, b.centres[i].normalized());
    const Vec3 mid = (b.centres[i] + b.centres[(i * 7919u) % 5000u]).normalized();
    expect_same(*q, b, mid);
  }
}

TEST(Support, ExactTiesGoToTheLowestIndex) {
  // A lattice on a flat face with equal radii: every direction along an axis ties many asperities;
  // duplicated balls tie in every direction.
  RoughBody b;
  // Indices scattered over the lattice, so that the lowest tied index is never simply the
  // first one the tree visits.
  for (int k = 0; k < 400; ++k) {
    const int m = (k * 151) % 400, i = m / 20, j = m % 20;
    b.centres.emplace_back(i * 1e-4, j * 1e-4, -1e-3);
    b.radii.push_back(1e-6);
  }
  b.centres.push_back(b.centres[57]);
  b.radii.push_back(1e-6);
  const auto q = make_support_tree(b.centres, b.radii);
  for (const Vec3& d : {Vec3(0, 0, -1), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0)})
    expect_same(*q, b, d);
  EXPECT_EQ(q->support(Vec3(0, 0, -1)).index, 0u);
  EXPECT_EQ(q->support(Vec3(0, 0, -1)).runner_up, 1u);
  const Vec3 d = (b.centres[57] - Vec3(1e-3, 1e-3, 0)).normalized();
  for (int k = 0; k < 200; ++k) {
    Stream s(9, Purpose::test, k);
    expect_same(*q, b, random_direction(s));
  }
  expect_same(*q, b, d);
}

TEST(Support, EqualRadiiAgreeWithTheNearestCentreQuery) {
  // With equal radii the support winner is the nearest centre (contact.hpp) whenever the two are
  // not separated only by rounding (different expressions round differently).
  SphereParams p;
  p.asperities = 20000;
  const RoughSphere s = make_rough_sphere(p, 2, 2);
  const RoughBody b = make_rough_sphere_body(p, RadiusDistribution::fixed(p.asperity_radius), 2, 2);
  const auto q = make_support_tree(b.centres, b.radii);
  int compared = 0;
  for (int k = 0; k < 2000; ++k) {
    Stream st(6, Purpose::test, k);
    const Vec3 d = random_direction(st);
    const Support sp = q->support(d);
    const Nearest nn = brute_lowest(s.centres, d);
    if (sp.h - sp.runner_up_h < 1e-15) continue;
    ++compared;
    ASSERT_EQ(sp.index, nn.index);
  }
  EXPECT_GT(compared, 1990);
}

TEST(Support, WithinIsTheBruteForceBall) {
  const RoughBody b = two_level_sphere(3000, 4);
  const auto q = make_support_tree(b.centres, b.radii);
  for (std::uint32_t i = 0; i < 100; ++i) {
    const double r = 1e-4 * (1 + i % 5);
    std::vector<std::uint32_t> want;
    for (std::uint32_t j = 0; j < b.size(); ++j)
      if ((b.centres[j] - b.centres[i]).squaredNorm() <= r * r) want.push_back(j);
    ASSERT_EQ(q->within(b.centres[i], r), want);
  }
}

TEST(Support, ContactPointIsTheLowestPointInTheWorld) {
  const RoughBody b = two_level_sphere(2000, 5);
  const auto q = make_support_tree(b.centres, b.radii);
  for (int k = 0; k < 200; ++k) {
    Stream s(8, Purpose::test, k);
    const Rotation rot = random_rotation(s);
    const BodyContact c = make_body_contact(q->support(body_down(rot)), b, rot);
    // No asperity ball reaches below the contact point (world z).
    for (std::size_t i = 0; i < b.size(); ++i) ASSERT_GE((rot * b.centres[i]).z() - b.radii[i], c.r.z() - 1e-15);
    EXPECT_GE(c.gap, 0.0);
  }
}
