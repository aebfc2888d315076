// SPDX-License-Identifier: GPL-3.0-or-later
// The cube-map grid backend must agree bit-for-bit with brute_lowest on every query.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <ostream>
#include <span>
#include <stdexcept>
#include <vector>

#include "asperity/core/contact.hpp"
#include "print_nearest.hpp"
#include "asperity/core/geometry.hpp"
#include "asperity/core/random.hpp"
#include "core/contact/detail.hpp"


namespace {

using asperity::brute_lowest;
using asperity::Nearest;
using asperity::Vec3;

std::vector<Vec3> sphere(std::uint64_t n, std::uint64_t seed) {
  return asperity::make_rough_sphere(asperity::SphereParams{n, 3e-3, 6.5e-7}, seed, 0).centres;
}

std::vector<Vec3> directions(std::size_t n, std::uint64_t seed) {
  std::vector<Vec3> d(n);
  for (std::size_t i = 0; i < n; ++i) {
    asperity::Stream s(seed, asperity::Purpose::test, i);
    const double u = s.uniform0(), v = s.uniform0();
    d[i] = asperity::uniform_on_sphere(u, v);
  }
  return d;
}

/// Special directions: axes, cube edges and corners (and points just off them).
std::vector<Vec3> special_directions() {
  std::vector<Vec3> d;
  for (int a = 0; a < 3; ++a)
    for (double sg : {1.0, -1.0}) {
      Vec3 v = Vec3::Zero();
      v[a] = sg;
      d.push_back(v);
    }
  for (double x : {1.0, -1.0})
    for (double y : {1.0, -1.0})
      for (double z : {1.0, -1.0}) d.push_back(Vec3(x, y, z).normalized());
  for (double tiny : {1e-17, -1e-17, 1e-300, 1e-9, 0.0}) {
    d.push_back(Vec3(1, tiny, 0).normalized());
    d.push_back(Vec3(tiny, 1, 0).normalized());
    d.push_back(Vec3(0, -1, tiny).normalized());
    d.push_back(Vec3(1, 1 + tiny, 0).normalized());
    d.push_back(Vec3(-1, 0, 1 - tiny).normalized());
    d.push_back(Vec3(1, 1, 1 + tiny).normalized());
    d.push_back(Vec3(-1 - tiny, 1, -1).normalized());
  }
  for (double a : {1.0, -1.0})
    for (double b : {1.0, -1.0}) {
      d.push_back(Vec3(a, b, 0).normalized());
      d.push_back(Vec3(0, a, b).normalized());
      d.push_back(Vec3(a, 0, b).normalized());
    }
  return d;
}

/// Checks every query of the single and the batch API, and the winners-only batch (float kernel,
/// guard, fallbacks), against the reference; returns mismatches.
int check(const asperity::ContactQuery& q, std::span<const Vec3> c, std::span<const Vec3> d) {
  std::vector<Nearest> batch(d.size()), ref(d.size()), win(d.size());
  q.lowest(d, batch);
  q.lowest_winners(d, win);
  // The reference scans dominate the test time: spread them over the cores.
  const auto nq = static_cast<std::int64_t>(d.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (std::int64_t k = 0; k < nq; ++k) {
    const auto i = static_cast<std::size_t>(k);
    ref[i] = brute_lowest(c, d[i]);
  }
  int bad = 0;
  for (std::size_t k = 0; k < d.size(); ++k) {
    const Nearest one = q.lowest(d[k]);
    EXPECT_EQ(one, ref[k]) << "query " << k << " d = (" << d[k].transpose() << ")";
    EXPECT_EQ(batch[k], one) << "batch query " << k;
    EXPECT_EQ(win[k], asperity::winner_only(ref[k])) << "winners query " << k << " d = (" << d[k].transpose() << ")";
    if (!(one == ref[k]) || !(batch[k] == one) || !(win[k] == asperity::winner_only(ref[k]))) ++bad;
    if (bad > 10) {
      ADD_FAILURE() << "too many mismatches, stopping";
      break;
    }
  }
  return bad;
}

auto grid(std::span<const Vec3> c) { return asperity::make_contact_query(asperity::Backend::grid, c); }

// ---- (a) random centres, random queries --------------------------------------------------------

class GridRandom : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(GridRandom, MatchesBruteOnRandomQueries) {
  const std::uint64_t n = GetParam();
  const auto c = sphere(n, 1234 + n);
  const auto q = grid(c);
  EXPECT_EQ(q->backend(), asperity::Backend::grid);
  EXPECT_GT(q->memory_bytes(), 0u);
  const auto d = directions(10000, 77 + n);
  EXPECT_EQ(check(*q, c, d), 0);
}

INSTANTIATE_TEST_SUITE_P(Sizes, GridRandom, ::testing::Values(1, 2, 3, 10, 1000, 100000));

TEST(Grid, SingleCentreHasInfiniteRunnerUp) {
  const std::vector<Vec3> c{Vec3(0, 0, 1)};
  const auto q = grid(c);
  const Nearest r = q->lowest(Vec3(0, 0, -1));
  EXPECT_EQ(r.index, 0u);
  EXPECT_EQ(r.runner_up, 0u);
  EXPECT_EQ(r.runner_up_key, std::numeric_limits<double>::infinity());
  EXPECT_EQ(r, brute_lowest(c, Vec3(0, 0, -1)));
}

// ---- (b) special query directions --------------------------------------------------------------

TEST(Grid, QueriesAtCentresEdgesCornersAndAxes) {
  for (std::uint64_t n : {1000u, 50000u}) {
    auto c = sphere(n, 99);
    // Some centres exactly at the special directions too (stored in two or three faces).
    const auto sp = special_directions();
    for (std::size_t k = 0; k < sp.size(); ++k) c[(k * 37) % n] = sp[k];
    const auto q = grid(c);
    std::vector<Vec3> d = sp;
    for (std::size_t k = 0; k < n; k += n / 500) d.push_back(c[k]);  // exactly at centres
    EXPECT_EQ(check(*q, c, d), 0) << "n = " << n;
  }
}

// ---- (c) adversarial point sets -----------------------------------------------------------------

TEST(Grid, DuplicatedCentres) {
  auto c = sphere(3000, 5);
  for (std::size_t k : {100u, 700u, 2999u, 1500u}) c[k] = c[5];  // same vector at five indices
  c[6] = c[2000];                                                // a duplicated pair
  const auto q = grid(c);
  std::vector<Vec3> d{c[5], c[6], c[2000], c[0]};
  const auto r = directions(2000, 6);
  d.insert(d.end(), r.begin(), r.end());
  // directions just next to the duplicated centre
  for (int k = 0; k < 50; ++k) d.push_back((c[5] + 1e-4 * r[static_cast<std::size_t>(k)]).normalized());
  EXPECT_EQ(check(*q, c, d), 0);
  EXPECT_EQ(q->lowest(c[5]).index, 5u);
  EXPECT_EQ(q->lowest(c[5]).runner_up, 100u);
  EXPECT_EQ(q->lowest(c[5]).runner_up_key, 0.0);
}

TEST(Grid, SymmetricTies) {
  // Points whose keys tie exactly: reflections about d = +-z ((x,y) -> (+-x,+-y), and x <-> y),
  // and x <-> y swaps for d = (1,1,0)/sqrt2 (d_x == d_y, so the sum x^2 + y^2 just commutes).
  std::vector<Vec3> c = sphere(4000, 11);
  const auto r = directions(60, 12);
  std::size_t slot = 3;
  for (std::size_t k = 0; k < r.size(); ++k) {
    const double th = 1e-3 * static_cast<double>(k + 1) * (k % 3 == 0 ? 30.0 : 1.0);
    const double phi = 6.283185307179586 * r[k].x();
    const double a = std::sin(th) * std::cos(phi), b = std::sin(th) * std::sin(phi), z = std::cos(th);
    for (double sz : {1.0, -1.0})
      for (const Vec3& v : {Vec3(a, b, z), Vec3(-a, b, z), Vec3(a, -b, z), Vec3(-a, -b, z), Vec3(b, a, z),
                            Vec3(-b, -a, z)}) {
        c[slot] = Vec3(v.x(), v.y(), sz * v.z());
        slot = (slot + 41) % c.size();
      }
  }
  const double h = std::sqrt(0.5);
  const Vec3 dxy(h, h, 0);
  for (std::size_t k = 0; k < 40; ++k) {
    const Vec3 u = (dxy + 1e-3 * static_cast<double>(k % 7 + 1) * r[k]).normalized();
    c[(slot + 13) % c.size()] = u;
    c[(slot + 29) % c.size()] = Vec3(u.y(), u.x(), u.z());
    slot = (slot + 97) % c.size();
  }
  const auto q = grid(c);
  const std::vector<Vec3> d{Vec3(0, 0, 1), Vec3(0, 0, -1), dxy, Vec3(-h, -h, 0), Vec3(h, h, 0)};
  EXPECT_EQ(check(*q, c, d), 0);
  // the tie really is there and is broken by index
  const Nearest up = brute_lowest(c, Vec3(0, 0, 1));
  EXPECT_EQ(up.key, up.runner_up_key);
  EXPECT_LT(up.index, up.runner_up);

  // A unique lowest centre and a tie for the runner-up (several indices at the same key).
  auto c2 = sphere(20000, 13);
  const double th = 1e-4, s = std::sin(th), z = std::cos(th);
  c2[9000] = Vec3(0, 0, 1);
  c2[7000] = Vec3(s, 0, z);
  c2[3000] = Vec3(-s, 0, z);
  c2[5000] = Vec3(0, s, z);
  c2[100] = Vec3(0, 0, -1);
  c2[17000] = Vec3(0, s, -z);
  c2[200] = Vec3(-s, 0, -z);
  const auto q2 = grid(c2);
  const std::vector<Vec3> d2{Vec3(0, 0, 1), Vec3(0, 0, -1)};
  EXPECT_EQ(check(*q2, c2, d2), 0);
  EXPECT_EQ(q2->lowest(Vec3(0, 0, 1)), (Nearest{9000, 0.0, 3000, brute_lowest(c2, Vec3(0, 0, 1)).runner_up_key}));
  EXPECT_EQ(q2->lowest(Vec3(0, 0, -1)).runner_up, 200u);
}

std::vector<Vec3> cluster(std::size_t n, const Vec3& w, double radius, std::uint64_t seed) {
  const auto r = directions(n, seed);
  std::vector<Vec3> c(n);
  for (std::size_t k = 0; k < n; ++k) c[k] = (w + radius * r[k]).normalized();
  return c;
}

TEST(Grid, ClusteredPoints) {
  const auto r = directions(4, 21);
  for (const Vec3& w : {r[0], Vec3(1, 1, 1).normalized(), Vec3(0, 0, -1), Vec3(1, 1e-7, 0).normalized()}) {
    for (double radius : {1e-6, 1e-3}) {
      const auto c = cluster(2000, w, radius, 22);
      const auto q = grid(c);
      std::vector<Vec3> d = directions(300, 23);
      for (std::size_t k = 0; k < 100; ++k) d.push_back((w + 0.7 * radius * d[k]).normalized());
      for (std::size_t k = 0; k < 100; k += 7) d.push_back(c[k]);
      d.push_back(w);
      d.push_back(-w);
      EXPECT_EQ(check(*q, c, d), 0) << "radius " << radius << " w = " << w.transpose();
    }
  }
}

TEST(Grid, OneHemisphereQueriedFromTheOtherSide) {
  auto c = sphere(20000, 31);
  for (auto& u : c) u.z() = std::abs(u.z());
  const auto q = grid(c);
  std::vector<Vec3> d = directions(500, 32);
  for (auto& v : d) v.z() = -std::abs(v.z());
  d.push_back(Vec3(0, 0, -1));
  d.push_back(Vec3(0, 0, 1));
  EXPECT_EQ(check(*q, c, d), 0);
}

TEST(Grid, ZeroCoordinatesOnCellEdges) {
  // Points with exact zero coordinates lie on the s = 0 / t = 0 cell edges of an even grid and on
  // face borders; sweep grid sides and margins, including a single cell per face.
  std::vector<Vec3> c = sphere(5000, 41);
  for (std::size_t k = 0; k < c.size(); k += 3) c[k][static_cast<Eigen::Index>(k % 3)] = 0.0;
  for (std::size_t k = 0; k < c.size(); k += 3) c[k].normalize();
  for (std::size_t k = 1; k < c.size(); k += 50) c[k] = Vec3(0, 0, 1);
  std::vector<Vec3> d = directions(1000, 42);
  for (std::size_t k = 0; k < 300; k += 3) d.push_back(c[k]);
  const auto sp = special_directions();
  d.insert(d.end(), sp.begin(), sp.end());
  for (int side : {1, 2, 3, 8, 64})
    for (double margin : {0.001, 0.2, 1.0}) {
      const auto q = asperity::detail::make_grid_with(c, side, margin);
      EXPECT_EQ(check(*q, c, d), 0) << "side " << side << " margin " << margin;
    }
}

TEST(Grid, StructuredPointSets) {
  // A lattice on the cube, projected: exact duplicates at cube edges, exact key ties, points on
  // cell edges and face borders. And the equator z = 0: every point on a face border.
  std::vector<Vec3> lattice;
  constexpr int m = 40;
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i <= m; ++i)
      for (int j = 0; j <= m; ++j) {
        Vec3 v;
        const int a = f / 2;
        v[a] = f % 2 ? -1.0 : 1.0;
        v[(a + 1) % 3] = -1.0 + 2.0 * i / m;
        v[(a + 2) % 3] = -1.0 + 2.0 * j / m;
        lattice.push_back(v.normalized());
      }
  std::vector<Vec3> d = directions(1500, 71);
  for (std::size_t k = 0; k < lattice.size(); k += 37) d.push_back(lattice[k]);
  const auto sp = special_directions();
  d.insert(d.end(), sp.begin(), sp.end());
  EXPECT_EQ(check(*grid(lattice), lattice, d), 0);

  std::vector<Vec3> equator;
  for (int k = 0; k < 20000; ++k) {
    const double phi = 6.283185307179586 * k / 20000.0;
    equator.emplace_back(std::cos(phi), std::sin(phi), 0.0);
  }
  auto near = directions(300, 72);
  for (auto& v : near) v = Vec3(v.x(), v.y(), 1e-3 * v.z()).normalized();
  near.insert(near.end(), sp.begin(), sp.end());
  EXPECT_EQ(check(*grid(equator), equator, near), 0);
}

TEST(Grid, NonUnitInputsFallBackToTheReference) {
  auto c = sphere(1000, 51);
  const auto d = directions(200, 52);
  {
    auto scaled = c;
    scaled[17] *= 2.0;  // one centre off the unit sphere
    const auto q = grid(scaled);
    EXPECT_EQ(check(*q, scaled, d), 0);
  }
  const auto q = grid(c);
  std::vector<Vec3> odd;
  for (const auto& v : d) odd.push_back(1.5 * v);
  odd.push_back(Vec3(0, 0, 0));
  EXPECT_EQ(check(*q, c, odd), 0);
}

// ---- winners only: near-ties below float resolution ---------------------------------------------

// Clusters of 2-7 centres around random directions, spread by 1e-9 .. 1e-6 rad (far below what a
// float key resolves at N = 10^4), some of them exact copies (key ties: the lowest index wins), on a
// random background sphere; queried at the cluster's direction and just beside it. Every answer
// of the winners path (float keys, FP64 recheck, guard, plane bound, fallback) equals brute force.
TEST(GridWinners, NearTiesBelowFloatResolution) {
  auto c = sphere(10000, 91);
  const auto centre = directions(300, 92);
  std::vector<Vec3> q;
  for (std::size_t k = 0; k < centre.size(); ++k) {
    asperity::Stream s(93, asperity::Purpose::test, k);
    const Vec3 a = centre[k];
    const Vec3 t1 = a.unitOrthogonal(), t2 = a.cross(t1);
    const double spread = std::pow(10.0, -9.0 + 3.0 * s.uniform0());
    const auto members = 2 + static_cast<std::size_t>(6.0 * s.uniform0());
    for (std::size_t i = 0; i < members; ++i) {
      const double e1 = spread * (2.0 * s.uniform0() - 1.0), e2 = spread * (2.0 * s.uniform0() - 1.0);
      const Vec3 p = (a + e1 * t1 + e2 * t2).normalized();
      const std::size_t at = static_cast<std::size_t>(s.uniform0() * double(c.size()));
      c[at] = p;
      if (i == 0 && k % 3 == 0) c[(at + 4999) % c.size()] = p;  // an exact copy: a key tie
    }
    q.push_back(a);
    q.push_back((a + 0.5 * spread * t1).normalized());
  }
  const auto g = grid(c);
  EXPECT_EQ(check(*g, c, q), 0);
  // The batch tail: sizes that are not multiples of anything.
  for (std::size_t n : {1u, 7u, 255u}) EXPECT_EQ(check(*g, c, std::span<const Vec3>(q).first(n)), 0);
}

// Stress grids: 0.1-0.5 centres per cell, so the 3x3 window often holds a point while the nearest
// centre lies outside it: the winners path must then refuse the guard's certificate and widen
// (plane bound, full search, brute force). A guard 100x too large fails here (checked by hand).
TEST(GridWinners, SparseCellsForceTheFallbacks) {
  const auto c = sphere(2000, 95);
  const auto d = directions(5000, 96);
  for (int side : {30, 40, 60}) {
    const auto q = asperity::detail::make_grid_with(c, side, 0.2);
    EXPECT_EQ(check(*q, c, d), 0) << "side " << side;
  }
}

// The winner pipeline of an index above L2 (batch_winners: a three-stage prefetch pipeline, the
// window's winner from the FP64 records, certified by the guard or the plane bound): every batch
// size -- tails shorter than the pipeline, the drop loop's 256, a whole batch -- answers as brute force, on a stress grid (0.3 centres per cell: guards and plane bounds
// fail often, the full search and brute force answer) and on the default grid, with face edges,
// corners and a non-unit query inside the batches.
TEST(GridWinners, PipelineAboveL2AnswersAsBruteAtEveryBatchSize) {
  const auto c = sphere(60000, 71);
  auto d = directions(3000, 72);
  const auto sp = special_directions();
  d.insert(d.begin() + 40, sp.begin(), sp.end());
  d[70] = 1.5 * d[70];
  std::vector<Nearest> ref(d.size());
  const auto nq = static_cast<std::int64_t>(d.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (std::int64_t k = 0; k < nq; ++k) ref[static_cast<std::size_t>(k)] = brute_lowest(c, d[static_cast<std::size_t>(k)]);
  for (int side : {0, 180}) {
    const auto q = asperity::detail::make_grid_with(c, side, 0);
    ASSERT_GT(q->memory_bytes(), std::size_t{1} << 20) << "the index must be above the resident size";
    for (std::size_t chunk : {std::size_t{1}, std::size_t{7}, std::size_t{25}, std::size_t{63}, std::size_t{64},
                              std::size_t{256}, d.size()}) {
      std::vector<Nearest> win(d.size());
      for (std::size_t b = 0; b < d.size(); b += chunk) {
        const std::size_t n = std::min(chunk, d.size() - b);
        q->lowest_winners(std::span<const Vec3>(d.data() + b, n), std::span<Nearest>(win.data() + b, n));
      }
      int bad = 0;
      for (std::size_t k = 0; k < d.size() && bad < 10; ++k) {
        EXPECT_EQ(win[k], asperity::winner_only(ref[k])) << "side " << side << " chunk " << chunk << " query " << k;
        bad += !(win[k] == asperity::winner_only(ref[k]));
      }
    }
  }
}

// ---- (d) single vs batch ------------------------------------------------------------------------

TEST(Grid, BatchEqualsSingle) {
  const auto c = sphere(100000, 61);
  const auto q = grid(c);
  auto d = directions(10007, 62);  // not a multiple of the batch chunk
  const auto sp = special_directions();
  d.insert(d.begin() + 500, sp.begin(), sp.end());
  d[3] = 2.0 * d[3];  // a non-unit one in the middle of a chunk
  std::vector<Nearest> out(d.size());
  q->lowest(d, out);
  int bad = 0;
  for (std::size_t k = 0; k < d.size() && bad < 10; ++k) {
    EXPECT_EQ(out[k], q->lowest(d[k])) << "query " << k;
    bad += !(out[k] == q->lowest(d[k]));
  }
  std::vector<Nearest> wrong(d.size() + 1);
  EXPECT_THROW(q->lowest(d, wrong), std::invalid_argument);
}

}  // namespace
