// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/core/body.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "core/format.hpp"

#include "asperity/core/random.hpp"

namespace asperity {

using detail::num;

RadiusDistribution RadiusDistribution::fixed(double rho) {
  RadiusDistribution d;
  d.kind = Kind::fixed;
  d.radius = rho;
  return d;
}

RadiusDistribution RadiusDistribution::lognormal(double median, double sigma) {
  RadiusDistribution d;
  d.kind = Kind::lognormal;
  d.median = median;
  d.sigma = sigma;
  return d;
}

RadiusDistribution RadiusDistribution::discrete(std::vector<double> levels, std::vector<double> fractions) {
  RadiusDistribution d;
  d.kind = Kind::levels;
  d.levels = std::move(levels);
  d.fractions = std::move(fractions);
  return d;
}

std::string RadiusDistribution::describe() const {
  std::ostringstream os;
  switch (kind) {
    case Kind::fixed: os << "fixed(" << radius << ")"; break;
    case Kind::lognormal: os << "lognormal(" << median << "," << sigma << ")"; break;
    case Kind::levels:
      os << "levels(";
      for (std::size_t i = 0; i < levels.size(); ++i)
        os << (i ? "," : "") << levels[i] << ":" << (i < fractions.size() ? fractions[i] : 0.0);
      os << ")";
      break;
  }
  return os.str();
}

void validate(const RadiusDistribution& d) {
  // The same supported range as the paper's one radius (geometry.hpp), for every radius.
  auto positive = [](double v, const std::string& what) {
    if (!std::isfinite(v) || v <= 0) throw std::invalid_argument(what + " must be a finite number > 0 m, got " + num(v));
    if (v < kMinLength || v > kMaxLength)
      throw std::invalid_argument(what + " must be in [" + num(kMinLength) + ", " + num(kMaxLength) +
                                  "] m (supported range), got " + num(v));
  };
  switch (d.kind) {
    case RadiusDistribution::Kind::fixed: positive(d.radius, "asperity radius"); break;
    case RadiusDistribution::Kind::lognormal:
      positive(d.median, "lognormal median radius");
      if (!std::isfinite(d.sigma) || d.sigma < 0)
        throw std::invalid_argument("lognormal sigma must be finite and >= 0, got " + num(d.sigma));
      break;
    case RadiusDistribution::Kind::levels: {
      if (d.levels.empty()) throw std::invalid_argument("radius levels: at least one level needed, got none");
      if (d.levels.size() > kMaxRadiusLevels)
        throw std::invalid_argument("radius levels: at most " + std::to_string(kMaxRadiusLevels) + " levels, got " +
                                    std::to_string(d.levels.size()) + " (the exact level law costs ~levels^3 per point)");
      if (d.levels.size() != d.fractions.size())
        throw std::invalid_argument("radius levels: " + std::to_string(d.levels.size()) + " radii but " +
                                    std::to_string(d.fractions.size()) + " fractions");
      double sum = 0;
      for (std::size_t i = 0; i < d.levels.size(); ++i) {
        positive(d.levels[i], "radius level " + std::to_string(i));
        if (!std::isfinite(d.fractions[i]) || d.fractions[i] < 0 || d.fractions[i] > 1)
          throw std::invalid_argument("radius fraction " + std::to_string(i) + " must be in [0,1], got " +
                                      num(d.fractions[i]));
        sum += d.fractions[i];
      }
      if (std::abs(sum - 1.0) > 1e-9) throw std::invalid_argument("radius fractions must sum to 1, got " + num(sum));
      break;
    }
  }
}

double sample_radius(const RadiusDistribution& d, Stream& s) {
  switch (d.kind) {
    case RadiusDistribution::Kind::fixed: return d.radius;
    case RadiusDistribution::Kind::lognormal: {
      // Box-Muller: u1 in (0,1] keeps log finite.
      const double u1 = s.uniform(), u2 = s.uniform0();
      const double z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
      return d.median * std::exp(d.sigma * z);
    }
    case RadiusDistribution::Kind::levels: {
      const double u = s.uniform0();
      double acc = 0;
      for (std::size_t k = 0; k + 1 < d.levels.size(); ++k) {
        acc += d.fractions[k];
        if (u < acc) return d.levels[k];
      }
      return d.levels.back();
    }
  }
  return d.radius;
}

double RoughBody::max_radius() const { return radii.empty() ? 0.0 : *std::max_element(radii.begin(), radii.end()); }

RoughBody make_rough_sphere_body(const SphereParams& p_in, const RadiusDistribution& dist, std::uint64_t seed,
                                 std::uint64_t sphere_id, double density) {
  SphereParams p = p_in;
  p.asperity_radius = 0.5 * p.radius;  // not used here; keeps validate() about N and R
  validate(p);
  validate(dist);
  if (!std::isfinite(density) || density <= 0)
    throw std::invalid_argument("density must be a finite number > 0 kg/m^3, got " + num(density));
  const double R = p.radius;
  RoughBody b;
  b.name = "sphere";
  b.base_radius = R;
  b.area = 4.0 * std::numbers::pi * R * R;
  b.mass = 4.0 / 3.0 * std::numbers::pi * R * R * R * density;
  b.inertia = Eigen::Matrix3d::Identity() * (0.4 * b.mass * R * R);
  b.centres.resize(p.asperities);
  b.radii.resize(p.asperities);
  const auto n = static_cast<std::int64_t>(p.asperities);
#pragma omp parallel for schedule(static) if (n > 16384)  // small bodies: thread start-up dominates
  for (std::int64_t i = 0; i < n; ++i) {
    Stream s(seed, Purpose::sphere, sphere_id, static_cast<std::uint64_t>(i));
    const double u = s.uniform0(), v = s.uniform0();
    b.centres[static_cast<std::size_t>(i)] = R * uniform_on_sphere(u, v);
    b.radii[static_cast<std::size_t>(i)] = sample_radius(dist, s);
  }
  const double rmax = b.max_radius();
  if (!(rmax < R))
    throw std::invalid_argument("drawn asperity radius " + num(rmax) + " m is not smaller than radius " + num(R) +
                                " m (distribution " + dist.describe() + ")");
  return b;
}

}  // namespace asperity
