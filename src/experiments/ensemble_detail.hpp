#pragma once
// Shared by the two explicit drivers (ensemble.cpp: raw samples; streaming.cpp: streaming
// statistics): which queries are answered again by other backends, and the re-answering.
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

/// Rotations [b, e) of sphere k (m rotations per sphere): drop k m + j, one Haar rotation from
/// its own stream, the lowest asperity by one batched query. The one definition of an explicit
/// drop, so that both drivers see the same drops. `each(j, contact, down, nearest)` per rotation.
template <class Each>
void query_rotations(const EnsembleConfig& c, std::uint64_t m, std::span<const Vec3> centres, const ContactQuery& index,
                     std::uint64_t k, std::uint64_t b, std::uint64_t e, Each&& each) {
  std::vector<Rotation> q(e - b);
  std::vector<Vec3> d(e - b);
  std::vector<Nearest> nn(e - b);
  for (std::uint64_t j = b; j < e; ++j) {
    Stream st(c.seed, Purpose::orientation, k * m + j);
    q[j - b] = random_rotation(st);
    d[j - b] = body_down(q[j - b]);
  }
  index.lowest(d, nn);
  for (std::uint64_t j = b; j < e; ++j) {
    const Nearest& r = nn[j - b];
    each(j, make_contact(r, centres[r.index], q[j - b], c.sphere.radius, c.sphere.asperity_radius), d[j - b], r);
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
