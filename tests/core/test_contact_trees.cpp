// SPDX-License-Identifier: GPL-3.0-or-later
// The CGAL kd-tree and FCL AABB-tree backends agree bit-for-bit with the reference scan,
// including on adversarial ties, and answer concurrent queries exactly as serial ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <ostream>
#include <vector>

#include "asperity/core/contact.hpp"
#include "print_nearest.hpp"
#include "asperity/core/geometry.hpp"
#include "asperity/core/random.hpp"


namespace {

using asperity::Backend;
using asperity::Nearest;
using asperity::Vec3;

constexpr std::uint64_t kSeed = 20240611;

std::vector<Vec3> random_centres(std::uint64_t n, std::uint64_t sphere_id = 0) {
  return asperity::make_rough_sphere(asperity::SphereParams{n, 3e-3, 6.5e-7}, kSeed, sphere_id).centres;
}

std::vector<Vec3> random_directions(std::size_t n, std::uint64_t stream) {
  std::vector<Vec3> d(n);
  for (std::size_t i = 0; i < n; ++i) {
    asperity::Stream s(kSeed, asperity::Purpose::test, stream, i);
    const double u = s.uniform0(), v = s.uniform0();
    d[i] = asperity::uniform_on_sphere(u, v);
  }
  return d;
}

std::vector<Vec3> axes() {
  return {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0), Vec3(0, 0, 1), Vec3(0, 0, -1)};
}

Vec3 unit(double x, double y, double z) { return Vec3(x, y, z).normalized(); }

// Reference answers, computed once per (centres, queries) and shared by both backends.
std::vector<Nearest> reference(const std::vector<Vec3>& c, const std::vector<Vec3>& q) {
  std::vector<Nearest> r(q.size());
  const auto n = static_cast<std::int64_t>(q.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) r[static_cast<std::size_t>(i)] = asperity::brute_lowest(c, q[static_cast<std::size_t>(i)]);
  return r;
}

constexpr Backend kBackends[] = {Backend::cgal, Backend::fcl};

// Every query of every backend equals the reference; reports the first few mismatches.
void expect_exact(const std::vector<Vec3>& c, const std::vector<Vec3>& q, const char* what) {
  const auto ref = reference(c, q);
  for (Backend b : kBackends) {
    SCOPED_TRACE(::testing::Message() << what << ", backend " << asperity::to_string(b) << ", N = " << c.size());
    const auto idx = asperity::make_contact_query(b, c);
    ASSERT_EQ(idx->backend(), b);
    int wrong = 0;
    for (std::size_t i = 0; i < q.size(); ++i) {
      const Nearest got = idx->lowest(q[i]);
      if (got != ref[i] && ++wrong <= 5) {
        EXPECT_EQ(got, ref[i]) << "query " << i << " d = (" << q[i].transpose() << ")";
      }
    }
    EXPECT_EQ(wrong, 0);
  }
}

// (a) random centres, random directions.
TEST(ContactTrees, RandomSmallN) {
  const auto q = random_directions(10000, 1);
  for (std::uint64_t n : {1, 2, 3, 10, 1000}) expect_exact(random_centres(n), q, "random");
}

// N = 50000: 10^4 queries in two halves (the reference scan dominates; keeps each test short
// under ASan).
TEST(ContactTrees, RandomN50000FirstHalf) {
  expect_exact(random_centres(50000), random_directions(5000, 2), "random");
}
TEST(ContactTrees, RandomN50000SecondHalf) {
  expect_exact(random_centres(50000), random_directions(5000, 3), "random");
}

// (b) queries exactly at centres (key 0) and along the axes.
TEST(ContactTrees, QueriesAtCentresAndAxes) {
  for (std::uint64_t n : {1, 2, 3, 10, 1000, 50000}) {
    const auto c = random_centres(n, 7);
    std::vector<Vec3> q = axes();
    for (std::size_t i = 0; i < c.size(); i += std::max<std::size_t>(1, c.size() / 2000)) {
      q.push_back(c[i]);
      q.push_back(-c[i]);
    }
    expect_exact(c, q, "at centres / axes");
  }
}

// (c) exact duplicates at several indices: identical keys, ties broken by index.
TEST(ContactTrees, DuplicatedCentres) {
  auto c = random_centres(1000, 11);
  // Pairs, a triple and a quintuple of identical centres, at scattered indices (low index last
  // as well as first, so that insertion order cannot stand in for index order).
  const std::vector<std::vector<std::size_t>> groups = {
      {3, 900}, {500, 17}, {42, 43, 999}, {600, 100, 7, 800, 250}, {0, 1}};
  for (const auto& g : groups)
    for (std::size_t j = 1; j < g.size(); ++j) c[g[j]] = c[g[0]];
  std::vector<Vec3> q = random_directions(5000, 12);
  for (const auto& g : groups) {
    q.push_back(c[g[0]]);                            // on the duplicates: key 0 ties
    q.push_back(unit(c[g[0]].x() + 1e-3, c[g[0]].y(), c[g[0]].z()));  // near them
    q.push_back(-c[g[0]]);
  }
  for (const Vec3& a : axes()) q.push_back(a);
  expect_exact(c, q, "duplicates");

  // All centres identical: every query is a full tie.
  for (std::uint64_t n : {2, 3, 4, 50}) {
    const std::vector<Vec3> same(n, unit(0.3, -0.2, 0.9));
    std::vector<Vec3> qs = random_directions(500, 13);
    qs.push_back(same[0]);
    expect_exact(same, qs, "all identical");
  }
}

// (c) large groups of identical centres (value-based kd splitters chain them: must not recurse
// ~N deep), alone and mixed with random centres; every query here is a many-way tie or near one.
TEST(ContactTrees, LargeDuplicateGroups) {
  const Vec3 p = unit(0.6, 0.0, 0.8);
  std::vector<Vec3> q = random_directions(20, 16);
  q.push_back(p);
  q.push_back(-p);
  q.push_back(unit(0.6, 1e-9, 0.8));
  expect_exact(std::vector<Vec3>(100000, p), q, "100000 identical");

  auto c = random_centres(100000, 17);
  for (std::size_t i = 0; i < c.size(); i += 2) c[i] = p;  // every even index
  c[1] = -p;
  for (std::size_t i = 3; i < c.size(); i += 1000) c[i] = -p;
  q.push_back(c[5]);
  expect_exact(c, q, "half identical");
}

// (c) near-ties: copies of a centre nudged by 1..2^20 ulps in one coordinate, so that keys differ
// in the last few bits up to ~1e-10 relative, straddling the backends' tie tolerance (1e-12).
TEST(ContactTrees, NearTies) {
  auto c = random_centres(3000, 15);
  std::vector<Vec3> q;
  for (std::size_t g = 0; g < 60; ++g) {
    const std::size_t base = 100 + 40 * g;
    const int ulps = 1 << (g % 21);
    for (std::size_t j = 1; j <= 3; ++j) {
      Vec3 u = c[base];
      const int axis = static_cast<int>((g + j) % 3);
      for (int k = 0; k < ulps * static_cast<int>(j); ++k) u[axis] = std::nextafter(u[axis], 2.0);
      c[j == 2 ? base - 1 : base + j] = u;  // a lower index as well as higher ones
    }
    q.push_back(c[base]);
    q.push_back(unit(c[base].x() + 3e-4, c[base].y() - 2e-4, c[base].z()));
    q.push_back(unit(c[base].x(), c[base].y(), c[base].z() + 1e-7));
  }
  expect_exact(c, q, "near ties");
}

// (c) two (and up to eight) centres mirrored about the query: bit-identical keys by symmetry.
// For d = (a, a, b), u = (p, q, r) and (q, p, r) have the same key (x^2+y^2 == y^2+x^2 exactly);
// for d = +z, (+-x, +-y, z) and (+-y, +-x, z) all share one key.
TEST(ContactTrees, SymmetricTies) {
  const auto background = random_centres(2000, 21);
  std::vector<Vec3> q;
  std::vector<Vec3> c = background;
  // Around +z: eight symmetric centres at angle 1e-3 (much closer than the background spacing),
  // and around -z a symmetric pair BEHIND a single closer centre (tie at the runner-up only),
  // and around x a symmetric pair that ties for the lowest.
  {
    const double x = 6e-4, y = 8e-4 * 0.5, z = std::sqrt(1 - x * x - y * y);
    for (double sx : {1.0, -1.0})
      for (double sy : {1.0, -1.0}) {
        c.push_back(Vec3(sx * x, sy * y, z));
        c.push_back(Vec3(sy * y, sx * x, z));
      }
    q.push_back(Vec3(0, 0, 1));
  }
  {
    const double x = 6e-4, y = 3e-4, z = -std::sqrt(1 - x * x - y * y);
    c.push_back(Vec3(x, y, z));
    c.push_back(Vec3(y, x, z));
    c.push_back(unit(1e-4, 0, -1));  // strictly lower than the pair
    q.push_back(Vec3(0, 0, -1));
  }
  {
    const Vec3 d = unit(1, 1, 0.5);
    const Vec3 u = unit(1 + 1e-3, 1 - 2e-3, 0.5 + 1e-3);
    c.push_back(u);
    c.push_back(Vec3(u.y(), u.x(), u.z()));
    q.push_back(d);
  }
  // Many generic symmetric pairs on the diagonal plane x = y, each the query's own tie.
  const auto dirs = random_directions(300, 22);
  for (const Vec3& r : dirs) {
    const Vec3 d = unit(r.x(), r.x(), r.z());  // x == y exactly
    const Vec3 u = unit(d.x() + 2e-4, d.y() - 1e-4, d.z() + 5e-5);
    c.push_back(u);
    c.push_back(Vec3(u.y(), u.x(), u.z()));
    q.push_back(d);
  }
  for (const Vec3& a : axes()) q.push_back(a);
  const auto more = random_directions(2000, 23);
  q.insert(q.end(), more.begin(), more.end());
  expect_exact(c, q, "symmetric ties");
}

// (c) many-way exact ties at random indices: for d = +z the 8 centres (+-x, +-y, z), (+-y, +-x, z)
// share one key; for d = (1,1,1)/sqrt(3) (equal components) the 6 permutations of (p, q, r) do.
// Placed at random slots of a random background, as the lowest or (behind one strictly lower
// centre) as the runner-up, in many independent trials.
TEST(ContactTrees, ManyWayTiesAtRandomIndices) {
  for (std::uint64_t trial = 0; trial < 120; ++trial) {
    auto c = random_centres(400, 100 + trial);
    asperity::Stream s(kSeed, asperity::Purpose::test, 61, trial);
    std::vector<Vec3> tied;
    Vec3 d;
    const double t = 1e-3 * (0.5 + s.uniform0()), phi = 1.5 * s.uniform0();
    if (trial % 2 == 0) {
      d = Vec3(0, 0, 1);
      const double x = t * std::cos(phi), y = t * std::sin(phi), z = std::sqrt(1 - x * x - y * y);
      for (double sx : {1.0, -1.0})
        for (double sy : {1.0, -1.0}) {
          tied.push_back(Vec3(sx * x, sy * y, z));
          tied.push_back(Vec3(sy * y, sx * x, z));
        }
    } else {
      const double a = 1 / std::sqrt(3.0);
      d = Vec3(a, a, a);
      const Vec3 u = unit(a + t * std::cos(phi), a + t * std::sin(phi), a - t);
      const double p = u.x(), q = u.y(), r = u.z();
      tied = {Vec3(p, q, r), Vec3(p, r, q), Vec3(q, p, r), Vec3(q, r, p), Vec3(r, p, q), Vec3(r, q, p)};
    }
    if (trial % 4 >= 2) tied.push_back((d + Vec3(1e-5, -1e-5, 0)).normalized());  // strictly lowest
    for (const Vec3& u : tied) c[static_cast<std::size_t>(s.bits() % c.size())] = u;
    std::vector<Vec3> q{d, -d};
    for (int k = 0; k < 8; ++k) q.push_back((d + Vec3(1e-12 * k, 0, 0)).normalized());
    expect_exact(c, q, "many-way ties");
  }
}

// (c) tight clusters: all points within ~1e-6 rad of each other (keys ~1e-12 and below, relative
// gaps far below any library's tie order), queried from inside, near and far.
TEST(ContactTrees, TightClusters) {
  for (std::uint64_t n : {3, 10, 1000, 20000}) {
    const Vec3 c0 = unit(0.2, -0.7, 0.4);
    const Vec3 e1 = c0.unitOrthogonal(), e2 = c0.cross(e1);
    std::vector<Vec3> c(n);
    for (std::uint64_t i = 0; i < n; ++i) {
      asperity::Stream s(kSeed, asperity::Purpose::test, 31, i);
      const double a = 5e-7 * (2 * s.uniform0() - 1), b = 5e-7 * (2 * s.uniform0() - 1);
      c[i] = (c0 + a * e1 + b * e2).normalized();
    }
    // A few exact duplicates inside the cluster too.
    if (n >= 10) c[n - 1] = c[1], c[n / 2] = c[3];
    std::vector<Vec3> q{c0, -c0};
    for (std::uint64_t i = 0; i < n; i += std::max<std::uint64_t>(1, n / 300)) q.push_back(c[i]);
    for (std::uint64_t i = 0; i < 500; ++i) {
      asperity::Stream s(kSeed, asperity::Purpose::test, 32, i);
      const double scale = std::pow(10.0, -3 - 5 * s.uniform0());  // 1e-3 .. 1e-8 rad from c0
      const double a = scale * (2 * s.uniform0() - 1), b = scale * (2 * s.uniform0() - 1);
      q.push_back((c0 + a * e1 + b * e2).normalized());
    }
    const auto far = random_directions(500, 33);
    q.insert(q.end(), far.begin(), far.end());
    for (const Vec3& a : axes()) q.push_back(a);
    expect_exact(c, q, "tight cluster");
  }
}

// (c) all centres on the upper hemisphere, queries from the lower one (the nearest centres are
// far, keys near 2..4, and many are nearly equidistant for queries near the south pole).
TEST(ContactTrees, OppositeHemisphere) {
  for (std::uint64_t n : {3, 10, 1000, 50000}) {
    auto c = random_centres(n, 41);
    for (Vec3& u : c) u.z() = std::abs(u.z());
    auto q = random_directions(3000, 42);
    for (Vec3& d : q) d.z() = -std::abs(d.z());
    q.push_back(Vec3(0, 0, -1));
    for (int i = 0; i < 200; ++i) q.push_back(unit(1e-6 * std::cos(i), 1e-6 * std::sin(i), -1));
    // Equator: the query lies in the plane of the hemisphere's rim.
    for (int i = 0; i < 100; ++i) q.push_back(Vec3(std::cos(0.1 * i), std::sin(0.1 * i), 0));
    expect_exact(c, q, "opposite hemisphere");
  }
}

// (d) concurrent queries from two OpenMP threads equal the serial ones.
TEST(ContactTrees, ConcurrentEqualsSerial) {
  const auto c = random_centres(50000, 51);
  auto q = random_directions(20000, 52);
  for (std::size_t i = 0; i < 2000; ++i) q.push_back(c[i * 7]);  // key-0 queries as well
  for (Backend b : kBackends) {
    SCOPED_TRACE(asperity::to_string(b));
    const auto idx = asperity::make_contact_query(b, c);
    std::vector<Nearest> serial(q.size()), parallel(q.size());
    for (std::size_t i = 0; i < q.size(); ++i) serial[i] = idx->lowest(q[i]);
    const auto n = static_cast<std::int64_t>(q.size());
#pragma omp parallel for num_threads(2) schedule(dynamic, 64)
    for (std::int64_t i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      parallel[k] = idx->lowest(q[k]);
    }
    int wrong = 0;
    for (std::size_t i = 0; i < q.size(); ++i) wrong += parallel[i] != serial[i];
    EXPECT_EQ(wrong, 0);
    EXPECT_EQ(serial[0], asperity::brute_lowest(c, q[0]));
  }
}

TEST(ContactTrees, MemoryIsReported) {
  const auto c = random_centres(1000);
  for (Backend b : kBackends) EXPECT_GT(asperity::make_contact_query(b, c)->memory_bytes(), 1000u * 8u);
}

}  // namespace
