#pragma once
// Shared by the two explicit drivers (ensemble.cpp: raw samples; streaming.cpp: streaming
// statistics): which queries are answered again by other backends, and the re-answering.
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "asperity/experiments/ensemble.hpp"

namespace asperity::detail {

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
