// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Shared by the two explicit drivers (ensemble.cpp: raw samples; streaming.cpp: streaming
// statistics): which queries are answered again by other backends, and the re-answering.
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "asperity/core/contact.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/random.hpp"
#include "asperity/experiments/ensemble.hpp"

namespace asperity::detail {

/// The rotation of explicit drop `drop` (index k m + j): Marsaglia's trig-free Haar draw from the
/// drop's own stream. Shared by the drop loop and the streaming run's cross-check.
inline Rotation drop_rotation(const EnsembleConfig& c, std::uint64_t drop) {
  Stream st(c.seed, Purpose::orientation, drop);
  return random_rotation_marsaglia(st);
}

/// Rotations [b, e) of sphere k (m rotations per sphere): drop k m + j, one Haar rotation from
/// its own stream, the lowest asperity by one batched query. The one definition of an explicit
/// drop, so that both drivers see the same drops. `each(j, contact, down, nearest)` per rotation,
/// in order of j. Batches of kQueryBatch rotations: their buffers (~20 KiB) stay in L1/L2 next to
/// the index and the histograms (answers do not depend on the batching).
inline constexpr std::uint64_t kQueryBatch = 256;
template <class Each>
void query_rotations(const EnsembleConfig& c, std::uint64_t m, std::span<const Vec3> centres, const ContactQuery& index,
                     std::uint64_t k, std::uint64_t b, std::uint64_t e, Each&& each) {
  std::array<Rotation, kQueryBatch> q;
  std::array<Vec3, kQueryBatch> d;
  std::array<Nearest, kQueryBatch> nn;
  for (std::uint64_t lo = b; lo < e; lo += kQueryBatch) {
    const std::size_t n = static_cast<std::size_t>(std::min(kQueryBatch, e - lo));
    for (std::size_t i = 0; i < n; ++i) {
      q[i] = drop_rotation(c, k * m + lo + i);
      d[i] = body_down(q[i]);
    }
    index.lowest(std::span<const Vec3>(d.data(), n), std::span<Nearest>(nn.data(), n));
    // The touching asperity's centre is a random read of the centres (N = 10^5: 2.4 MB, a cache
    // miss per drop, ~17% of the run): prefetched kCentreLag drops ahead.
    constexpr std::size_t kCentreLag = 16;
    for (std::size_t i = 0; i < std::min(n, kCentreLag); ++i) __builtin_prefetch(centres.data() + nn[i].index);
    for (std::size_t i = 0; i < n; ++i) {
      if (i + kCentreLag < n) __builtin_prefetch(centres.data() + nn[i + kCentreLag].index);
      const Nearest& r = nn[i];
      each(lo + i, make_contact(r, centres[r.index], q[i], c.sphere.radius, c.sphere.asperity_radius), d[i], r);
    }
  }
}

/// The cross-check of an explicit run (CrossCheck, ensemble.hpp): rotations j % stride == 0 (the
/// first per_sphere of them) of spheres 0, sphere_stride, 2 sphere_stride, ... (`spheres` of them).
struct CheckPlan {
  std::vector<Backend> others;
  std::uint64_t spheres = 0, sphere_stride = 1, per_sphere = 0, stride = 1;
  bool checked(std::uint64_t k) const { return k % sphere_stride == 0 && k / sphere_stride < spheres; }
};
CheckPlan check_plan(const EnsembleConfig& c);

struct SphereCheck {
  std::uint64_t queries = 0, agreed = 0;
  std::string first_disagreement;
};
/// Re-answers one sphere's sampled queries (direction, the run's answer) by the other backends.
SphereCheck cross_check_sphere(const EnsembleConfig& c, std::span<const Vec3> centres,
                               const std::vector<std::pair<Vec3, Nearest>>& answers, const std::vector<Backend>& others,
                               std::uint64_t sphere);

}  // namespace asperity::detail
