// SPDX-License-Identifier: GPL-3.0-or-later
// Screening of unequal asperities: every asperity that can touch is kept, the screened ones
// never touch (checked by dense direction sampling), equal radii screen nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "asperity/core/body.hpp"
#include "asperity/core/random.hpp"
#include "asperity/core/screening.hpp"
#include "asperity/core/support.hpp"

using namespace asperity;

namespace {
RoughBody sphere(std::uint64_t n, const RadiusDistribution& d, std::uint64_t id = 1) {
  SphereParams p;
  p.asperities = n;
  p.radius = 3e-3;
  return make_rough_sphere_body(p, d, 21, id);
}
}  // namespace

TEST(Screening, EqualRadiiScreenNothing) {
  const RoughBody b = sphere(3000, RadiusDistribution::fixed(6.5e-7));
  const auto q = make_support_tree(b.centres, b.radii);
  const ScreeningResult r = screen_sphere(b, *q);
  EXPECT_EQ(r.screened, 0u);
  EXPECT_EQ(r.kept, 3000u);
  EXPECT_DOUBLE_EQ(r.lambda_eff, r.lambda);
  EXPECT_GT(r.theta_cover, 0.0);
  EXPECT_LT(r.theta_cover, 0.2);
}

TEST(Screening, ABallInsideTheHullOfLargerOnesIsScreened) {
  // Three big balls around a small one sitting lower than their common tangent plane.
  RoughBody b;
  b.name = "sphere";
  b.base_radius = 1.0;
  auto on_sphere = [](double th, double ph) {
    return Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
  };
  for (int k = 0; k < 3; ++k) {
    b.centres.push_back(on_sphere(0.01, 2 * std::numbers::pi * k / 3));
    b.radii.push_back(1e-3);
  }
  b.centres.push_back(on_sphere(0, 0));  // the small one, at the pole
  b.radii.push_back(1e-5);
  // A far-away small ball on the other side: nothing screens it.
  b.centres.push_back(on_sphere(2.0, 1.0));
  b.radii.push_back(1e-5);
  // Filler so that every direction has a nearby centre.
  for (int i = 0; i < 2000; ++i) {
    Stream s(1, Purpose::test, i);
    const Vec3 u = uniform_on_sphere(s.uniform0(), s.uniform0());
    if (u.z() > 0.99) continue;
    b.centres.push_back(u);
    b.radii.push_back(1e-5);
  }
  const auto q = make_support_tree(b.centres, b.radii);
  const ScreeningResult r = screen_sphere(b, *q);
  // Small ball at the pole: the big ones (angular distance 0.01) have h = cos(0.01) + 1e-3 > 1 + 1e-5
  // at d = pole, and all around it.
  EXPECT_EQ(r.status[3], Screen::screened);
  EXPECT_NE(r.status[4], Screen::screened);
  for (int k = 0; k < 3; ++k) EXPECT_NE(r.status[static_cast<std::size_t>(k)], Screen::screened);
}

TEST(Screening, ScreenedAsperitiesNeverTouchAndKeptOnesDo) {
  // Two levels: 20% of radius 2 um, 80% of 0.5 um on R = 3 mm, N = 4000.
  const RoughBody b = sphere(4000, RadiusDistribution::discrete({2e-6, 5e-7}, {0.2, 0.8}));
  const auto q = make_support_tree(b.centres, b.radii);
  const ScreeningResult r = screen_sphere(b, *q);
  ASSERT_EQ(r.kept + r.screened, 4000u);
  EXPECT_GT(r.screened, 100u);  // the hierarchy does screen
  EXPECT_GT(r.kept, 800u);      // at least all big ones
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.radii[i] == 2e-6) {
      ASSERT_NE(r.status[i], Screen::screened) << i;
    }
  }

  // Global sampling: 2e5 uniform directions; no winner may be screened.
  const ScreeningCheck c = check_screening(b, *q, r, 200000, 3);
  EXPECT_EQ(c.winners_screened, 0u);
  // Local sampling around every screened asperity: 300 directions within the region where it
  // could possibly win (angle <= 2 theta_cover); it must never be the lowest.
  std::uint64_t probes = 0;
  for (std::uint32_t j = 0; j < b.size(); ++j) {
    if (r.status[j] != Screen::screened) continue;
    const Vec3 u = b.centres[j].normalized();
    const Vec3 e1 = u.unitOrthogonal(), e2 = u.cross(e1);
    for (int k = 0; k < 300; ++k) {
      Stream s(4, Purpose::test, j, static_cast<std::uint64_t>(k));
      const double rad = 2 * r.theta_cover * std::sqrt(s.uniform0()), ph = 2 * std::numbers::pi * s.uniform0();
      const Vec3 d = (u + std::tan(rad) * (std::cos(ph) * e1 + std::sin(ph) * e2)).normalized();
      ASSERT_NE(q->support(d).index, j) << "screened asperity " << j << " touches";
      ++probes;
    }
  }
  EXPECT_GT(probes, 30000u);
}

TEST(Screening, TheCrossCheckCanFail) {
  // Power of check_screening: mark the winner of some direction as screened; the check sees it.
  const RoughBody b = sphere(2000, RadiusDistribution::discrete({2e-6, 5e-7}, {0.2, 0.8}), 2);
  const auto q = make_support_tree(b.centres, b.radii);
  ScreeningResult r = screen_sphere(b, *q);
  Stream s(3, Purpose::analysis, 0);
  const double u = s.uniform0(), v = s.uniform0();
  r.status[q->support(uniform_on_sphere(u, v)).index] = Screen::screened;
  EXPECT_GT(check_screening(b, *q, r, 1000, 3).winners_screened, 0u);
}

TEST(Screening, RejectsNonSpheres) {
  RoughBody b;
  b.centres = {Vec3(0, 0, 1)};
  b.radii = {1e-3};
  const auto q = make_support_tree(b.centres, b.radii);
  EXPECT_THROW(screen_sphere(b, *q), std::invalid_argument);
}

// theta_cover (report field screening.theta_cover) is a function of the centres alone: CGAL's hull
// may start a facet at any of its vertices, and the circumcap's rounding depended on which (before
// the fix, 4 of 80 such bodies gave other bits on a second call, bodies 1 of seeds 15 and 16 among them).
TEST(Screening, ThetaCoverIsTheSameBitsOnEveryCall) {
  int differ = 0;
  for (std::uint64_t seed : {14, 15, 16})
    for (std::uint64_t k : {1}) {
      SphereParams p;
      p.asperities = 2000, p.radius = 3e-3;
      const RoughBody b = make_rough_sphere_body(p, RadiusDistribution::lognormal(6.5e-7, 0.5), seed, k);
      const auto q = make_support_tree(b.centres, b.radii);
      const double t1 = screen_sphere(b, *q).theta_cover, t2 = screen_sphere(b, *q).theta_cover;
      differ += t1 != t2;
      EXPECT_TRUE(std::isfinite(t1) && t1 > 0) << seed << " " << k;
    }
  EXPECT_EQ(differ, 0);
}
