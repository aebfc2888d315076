// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/laws/family.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace asperity {

std::vector<double> holm_adjusted(std::span<const double> p) {
  for (double v : p)
    if (!(v >= 0 && v <= 1)) throw std::invalid_argument("holm_adjusted: p-value " + std::to_string(v) + " not in [0, 1]");
  const std::size_t m = p.size();
  std::vector<std::size_t> order(m);
  std::iota(order.begin(), order.end(), std::size_t{0});
  // Ties keep their input order; they get the same adjusted p either way (the running max).
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p[a] < p[b]; });
  std::vector<double> adj(m);
  double running = 0;  // step-down: a test is rejected only if every smaller p was
  for (std::size_t k = 0; k < m; ++k) {
    running = std::max(running, std::min(1.0, double(m - k) * p[order[k]]));
    adj[order[k]] = running;
  }
  return adj;
}

FamilyDecision holm_decision(std::span<const double> p, const std::vector<bool>& member, double alpha) {
  if (p.size() != member.size()) throw std::invalid_argument("holm_decision: p and member differ in size");
  if (!(alpha > 0 && alpha < 1)) throw std::invalid_argument("holm_decision: alpha must be in (0, 1)");
  FamilyDecision d;
  d.alpha = alpha;
  std::vector<double> members;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (member[i]) members.push_back(p[i]);
  const std::vector<double> adj = holm_adjusted(members);
  d.tests = members.size();
  d.adjusted_p.assign(p.size(), std::numeric_limits<double>::quiet_NaN());
  d.reject.assign(p.size(), false);
  d.min_adjusted_p = members.empty() ? std::numeric_limits<double>::quiet_NaN() : 1.0;
  for (std::size_t i = 0, k = 0; i < p.size(); ++i) {
    if (!member[i]) continue;
    d.adjusted_p[i] = adj[k++];
    d.reject[i] = d.adjusted_p[i] <= alpha;
    d.rejected = d.rejected || d.reject[i];
    d.min_adjusted_p = std::min(d.min_adjusted_p, d.adjusted_p[i]);
  }
  return d;
}

}  // namespace asperity
