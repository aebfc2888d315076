// SPDX-License-Identifier: GPL-3.0-or-later
// The contract of every contact backend: the same answer as the brute-force reference, bit for
// bit (index, key, runner-up, runner-up key), on random and adversarial queries.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "asperity/core/contact.hpp"
#include "asperity/core/random.hpp"

using namespace asperity;

namespace {

std::vector<Vec3> random_dirs(std::size_t n, std::uint64_t seed) {
  std::vector<Vec3> d(n);
  for (std::size_t i = 0; i < n; ++i) {
    Stream s(seed, Purpose::test, i);
    d[i] = uniform_on_sphere(s.uniform0(), s.uniform0());
  }
  return d;
}

void expect_all_agree(Backend b, const std::vector<Vec3>& centres, const std::vector<Vec3>& queries) {
  const auto q = make_contact_query(b, centres);
  std::vector<Nearest> batch(queries.size());
  q->lowest(queries, batch);
  std::size_t bad = 0;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const Nearest ref = brute_lowest(centres, queries[i]);
    const Nearest got = q->lowest(queries[i]);
    if (!(got == ref) || !(batch[i] == ref)) {
      if (++bad <= 3)
        ADD_FAILURE() << to_string(b) << ": query " << i << " ref (" << ref.index << ", " << ref.runner_up << ") got ("
                      << got.index << ", " << got.runner_up << ") batch (" << batch[i].index << ", "
                      << batch[i].runner_up << ")";
    }
  }
  EXPECT_EQ(bad, 0u) << to_string(b) << " disagreed with brute force on " << bad << " of " << queries.size();
}

class Backends : public ::testing::TestWithParam<Backend> {};

TEST_P(Backends, RandomSpheresAndRandomQueries) {
  for (std::uint64_t n : {1u, 2u, 3u, 7u, 1000u, 30000u}) {
    const auto body = make_rough_sphere(SphereParams{n, 3e-3, 6.5e-7}, 42, n);
    expect_all_agree(GetParam(), body.centres, random_dirs(3000, n));
  }
}

TEST_P(Backends, QueriesAtCentresAxesAndCubeCorners) {
  const auto body = make_rough_sphere(SphereParams{5000, 3e-3, 6.5e-7}, 7, 0);
  std::vector<Vec3> q(body.centres.begin(), body.centres.begin() + 500);
  for (int s : {-1, 1}) {
    q.emplace_back(s, 0, 0), q.emplace_back(0, s, 0), q.emplace_back(0, 0, s);
    q.push_back(Vec3(s, 1, 1).normalized()), q.push_back(Vec3(1, s, -1).normalized());
    q.push_back(Vec3(1, s * 1e-17, 0).normalized()), q.push_back(Vec3(s * 1e-9, 1, 1).normalized());
  }
  expect_all_agree(GetParam(), body.centres, q);
}

TEST_P(Backends, ExactTiesGoToTheLowestIndex) {
  // Duplicated centres at several indices, and pairs mirrored about the query (identical keys).
  auto body = make_rough_sphere(SphereParams{2000, 3e-3, 6.5e-7}, 11, 0);
  auto& c = body.centres;
  for (std::size_t i = 0; i < 200; ++i) c[1000 + i] = c[i];  // duplicates, higher index
  for (std::size_t i = 0; i < 100; ++i) c[1500 + i] = c[1700 + i];  // duplicates, lower index first
  std::vector<Vec3> q(c.begin(), c.begin() + 200);
  // Mirror pairs about the x axis direction: u = (cos t, sin t, 0) and (cos t, -sin t, 0).
  for (int k = 0; k < 50; ++k) {
    const double t = 1e-4 * (k + 1);
    c[1800 + 2 * k] = Vec3(std::cos(t), std::sin(t), 0);
    c[1801 + 2 * k] = Vec3(std::cos(t), -std::sin(t), 0);
    q.emplace_back(1, 0, 0);
  }
  const Nearest n = brute_lowest(c, Vec3(1, 0, 0));
  EXPECT_EQ(n.key, n.runner_up_key);  // the construction really is a tie
  EXPECT_LT(n.index, n.runner_up);
  expect_all_agree(GetParam(), c, q);
}

TEST_P(Backends, NearTiesOneUlpApart) {
  // Two centres whose keys differ by a few ulps around a random query; plus a third far one.
  std::vector<Vec3> q;
  std::vector<Vec3> c = make_rough_sphere(SphereParams{3000, 3e-3, 6.5e-7}, 5, 0).centres;
  for (int k = 0; k < 40; ++k) {
    const Vec3 d = c[static_cast<std::size_t>(k)];
    const Vec3 e1 = d.unitOrthogonal(), e2 = d.cross(e1);
    const double t = 1e-3;
    c.push_back((d * std::cos(t) + e1 * std::sin(t)).normalized());
    c.push_back((d * std::cos(t) + e2 * std::sin(std::nextafter(t, 1.0))).normalized());
    q.push_back(d);
  }
  expect_all_agree(GetParam(), c, q);
}

TEST_P(Backends, ClustersAndHemispheres) {
  // All points in a cluster 1e-6 rad wide; then all on one hemisphere queried from the other.
  std::vector<Vec3> cluster;
  for (std::size_t i = 0; i < 2000; ++i) {
    Stream s(3, Purpose::test, i);
    cluster.push_back(Vec3(1, 1e-6 * (s.uniform0() - 0.5), 1e-6 * (s.uniform0() - 0.5)).normalized());
  }
  expect_all_agree(GetParam(), cluster, random_dirs(500, 9));
  auto hemi = make_rough_sphere(SphereParams{3000, 3e-3, 6.5e-7}, 4, 0).centres;
  for (auto& u : hemi) u.z() = std::abs(u.z());
  auto q = random_dirs(500, 10);
  for (auto& d : q) d.z() = -std::abs(d.z());
  expect_all_agree(GetParam(), hemi, q);
}

INSTANTIATE_TEST_SUITE_P(AllBackends, Backends, ::testing::ValuesIn(all_backends().begin(), all_backends().end()),
                         [](const auto& info) { return std::string(to_string(info.param)); });

TEST(Contact, ParseBackendNamesTheBadValue) {
  EXPECT_EQ(parse_backend("grid"), Backend::grid);
  try {
    parse_backend("octree");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("octree"), std::string::npos);
  }
}

TEST(Contact, MakeContactGeometry) {
  // A body rotated by q: the contact point is a straight below the lowest centre, in the world frame.
  const double R = 3e-3, a = 6.5e-7;
  Stream s(1, Purpose::test, 0);
  const Rotation q = random_rotation(s);
  const Vec3 d = body_down(q);
  const Vec3 e1 = d.unitOrthogonal();
  const double theta = 2e-3;
  const Vec3 u = (d * std::cos(theta) + e1 * std::sin(theta)).normalized();
  const std::vector<Vec3> c{u};
  const Nearest n = brute_lowest(c, d);
  const Contact k = make_contact(n, u, q, R, a);
  const Vec3 world = q * (R * u);
  EXPECT_NEAR(k.r.x(), world.x(), 1e-18);
  EXPECT_NEAR(k.r.y(), world.y(), 1e-18);
  EXPECT_NEAR(k.r.z(), -(R * std::cos(theta) + a), 1e-17);
  EXPECT_NEAR(k.r_xy, R * std::sin(theta), 1e-17);
  EXPECT_NEAR(std::hypot(k.r.x(), k.r.y()), k.r_xy, 1e-15);
  // theta = 2e-3: R (1 - cos) = 6e-9 m < a, so an asperity touches.
  EXPECT_FALSE(k.core);
  // Far from the pole the central sphere touches first.
  const Vec3 far = (d * std::cos(0.1) + e1 * std::sin(0.1)).normalized();
  const std::vector<Vec3> c2{far};
  EXPECT_TRUE(make_contact(brute_lowest(c2, d), far, q, R, a).core);
}

}  // namespace
