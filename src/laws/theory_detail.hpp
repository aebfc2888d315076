// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Internal pieces shared by the laws of theory.cpp (equal radii) and theory_radii.cpp (level
// radii). Include after <cmath> with `using std::isnan;` visible (Boost 1.74's pchip calls isnan
// unqualified from a template).
#include <boost/math/interpolators/pchip.hpp>
#include <boost/math/special_functions/erf.hpp>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "asperity/laws/theory.hpp"

namespace asperity::detail {

using TailTable = boost::math::interpolators::pchip<std::vector<double>>;

/// tail(t) at `nodes` equally spaced t on [0, t_max], interpolated by pchip: monotone data give
/// a monotone interpolant, so a cdf built on the table stays a cdf.
template <class Tail>
std::shared_ptr<TailTable> tabulate_tail(double t_max, int nodes, Tail tail) {
  std::vector<double> ts(nodes), tails(nodes);
  for (int i = 0; i < nodes; ++i) {
    ts[i] = t_max * i / (nodes - 1);
    tails[i] = tail(ts[i]);
  }
  return std::make_shared<TailTable>(std::move(ts), std::move(tails));
}

/// The centred Gaussian of standard deviation sigma [m] (cdf and pdf); the caller names it.
inline Law centred_gaussian(double sigma) {
  Law law;
  law.cdf = [sigma](double t) { return 0.5 * boost::math::erfc(-t / (sigma * std::numbers::sqrt2)); };
  law.pdf = [sigma](double t) {
    const double z = t / sigma;
    return std::exp(-0.5 * z * z) / (sigma * std::sqrt(2.0 * std::numbers::pi));
  };
  return law;
}

}  // namespace asperity::detail
