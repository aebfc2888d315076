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
#include "asperity/core/drop_kernel.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/random.hpp"
#include "asperity/experiments/ensemble.hpp"

namespace asperity::detail {

/// The body-frame down direction of explicit drop `drop` (index k m + j): the drop kernel's
/// stream (core/drop_kernel.hpp). Shared by the drop loop and the streaming run's cross-check.
inline Vec3 drop_direction(const EnsembleConfig& c, std::uint64_t drop) { return draw_drop(c.seed, drop).d; }

/// Drops [b, e) of sphere k (m drops per sphere): drop k m + j, a down direction and a world
/// azimuth from its own stream, the lowest asperity by one batched query, the contact by the drop
/// kernel (c.kernel: scalar or simd, the same bits). The one definition of an explicit drop, so
/// that both drivers see the same drops. `each(j, contact, down, nearest)` per drop, in order of j.
/// Batches of kQueryBatch drops: their buffers (~40 KiB) stay in L1/L2 next to the index and the
/// histograms (answers do not depend on the batching). Answers::winners: the lowest asperity only
/// (ContactQuery::lowest_winners; the contacts' gap is then +inf), for statistics that need no
/// runner-up; Answers::full: the runner-up too (raw samples report the gap).
enum class Answers { full, winners };
inline constexpr std::uint64_t kQueryBatch = 256;
template <class Each>
void query_drops(const EnsembleConfig& c, std::uint64_t m, std::span<const Vec3> centres, const ContactQuery& index,
                 std::uint64_t k, std::uint64_t b, std::uint64_t e, Answers answers, Each&& each) {
  std::array<Vec3, kQueryBatch> d;
  std::array<double, kQueryBatch> cs, sn;
  std::array<Nearest, kQueryBatch> nn;
  std::array<Contact, kQueryBatch> ct;
  for (std::uint64_t lo = b; lo < e; lo += kQueryBatch) {
    const std::size_t n = static_cast<std::size_t>(std::min(kQueryBatch, e - lo));
    const std::span<Vec3> dn(d.data(), n);
    draw_drops(c.kernel, c.seed, k * m + lo, dn, std::span<double>(cs.data(), n), std::span<double>(sn.data(), n));
    if (answers == Answers::winners) index.lowest_winners(dn, std::span<Nearest>(nn.data(), n));
    else index.lowest(dn, std::span<Nearest>(nn.data(), n));
    drop_contacts(c.kernel, dn, std::span<const double>(cs.data(), n), std::span<const double>(sn.data(), n),
                  std::span<const Nearest>(nn.data(), n), centres, c.sphere.radius, c.sphere.asperity_radius,
                  std::span<Contact>(ct.data(), n));
    for (std::size_t i = 0; i < n; ++i) each(lo + i, ct[i], d[i], nn[i]);
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
