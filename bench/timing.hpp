// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What every benchmark driver times with: wall seconds of one call, and the median of repeats
// (bench/RESULTS.md reports medians and their ratios from one run).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace asperity::bench {

/// The median of `v` (the mean of the middle two for an even count; NaN for none).
inline double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Wall seconds of f().
template <class F>
double timed(F f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace asperity::bench
