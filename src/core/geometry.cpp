// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/core/geometry.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "core/format.hpp"

#include "asperity/core/random.hpp"

namespace asperity {

using detail::num;

void check_asperity_count(std::uint64_t n, std::string_view what) {
  if (n < 1 || n > kMaxAsperities)
    throw std::invalid_argument(std::string(what) + " must be in [1, 2^32-1], got " + std::to_string(n));
}

void validate(const SphereParams& p) {
  check_asperity_count(p.asperities);
  if (!std::isfinite(p.radius) || p.radius <= 0)
    throw std::invalid_argument("radius must be a finite number > 0 m, got " + num(p.radius));
  if (!std::isfinite(p.asperity_radius) || p.asperity_radius <= 0)
    throw std::invalid_argument("asperity-radius must be a finite number > 0 m, got " + num(p.asperity_radius));
  if (p.radius > kMaxLength)
    throw std::invalid_argument("radius must be <= " + num(kMaxLength) + " m (supported range), got " + num(p.radius));
  if (p.asperity_radius < kMinLength)
    throw std::invalid_argument("asperity-radius must be >= " + num(kMinLength) + " m (supported range), got " +
                                num(p.asperity_radius));
  if (p.asperity_radius >= p.radius)
    throw std::invalid_argument("asperity-radius (" + num(p.asperity_radius) +
                                " m) must be smaller than radius (" + num(p.radius) + " m)");
}

Vec3 uniform_on_sphere(double u, double v) {
  // Archimedes: z uniform in [-1,1] gives uniform area. For points near the poles, compute
  // sin(theta) from (1-z)(1+z) rather than 1 - z^2 to avoid cancellation.
  const double z = 1.0 - 2.0 * u;
  const double s = 2.0 * std::sqrt(u * (1.0 - u));
  const double phi = 2.0 * std::numbers::pi * v;
  return {s * std::cos(phi), s * std::sin(phi), z};
}

RoughSphere make_rough_sphere(const SphereParams& p, std::uint64_t seed, std::uint64_t sphere_id) {
  validate(p);
  RoughSphere body{p, std::vector<Vec3>(p.asperities)};
  const std::int64_t n = static_cast<std::int64_t>(p.asperities);
  // Centre i depends on (seed, sphere_id, i) only: Philox block i of the sphere's key.
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    Stream s(seed, Purpose::sphere, sphere_id, static_cast<std::uint64_t>(i));
    const double u = s.uniform0(), v = s.uniform0();
    body.centres[static_cast<std::size_t>(i)] = uniform_on_sphere(u, v);
  }
  return body;
}

}  // namespace asperity
