// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Query-direction streams shared by the benchmarks: uniformly random directions, and the path of a
// slowly turning body. Both are pure functions of (count, seed, step), so every benchmark times the
// same queries.
#include <cmath>
#include <cstdint>
#include <vector>

#include "asperity/core/geometry.hpp"
#include "asperity/core/random.hpp"

namespace asperity::bench {

inline std::vector<Vec3> random_directions(std::size_t q, std::uint64_t seed) {
  std::vector<Vec3> d(q);
  const auto n = static_cast<std::int64_t>(q);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    Stream s(seed, Purpose::test, static_cast<std::uint64_t>(i), 1);
    const double u = s.uniform0(), v = s.uniform0();
    d[static_cast<std::size_t>(i)] = uniform_on_sphere(u, v);
  }
  return d;
}

// A body turning slowly: the body-frame down direction moves `step` radians per query along a
// great circle whose heading turns by a small random angle each step (so the path never closes
// on itself and the stream does not revisit the same cells periodically).
inline std::vector<Vec3> rotating_directions(std::size_t q, std::uint64_t seed, double step) {
  std::vector<Vec3> d(q);
  Stream s(seed, Purpose::test, 0, 2);
  Vec3 p = uniform_on_sphere(s.uniform0(), s.uniform0());
  Vec3 t = p.unitOrthogonal();
  const double cs = std::cos(step), sn = std::sin(step);
  for (std::size_t i = 0; i < q; ++i) {
    d[i] = p;
    const Vec3 p2 = (cs * p + sn * t).normalized();
    Vec3 t2 = -sn * p + cs * t;
    const double turn = 0.05 * (2.0 * s.uniform0() - 1.0);  // heading change, radians
    t2 = std::cos(turn) * t2 + std::sin(turn) * p2.cross(t2);
    t = (t2 - t2.dot(p2) * p2).normalized();
    p = p2;
  }
  return d;
}

}  // namespace asperity::bench
