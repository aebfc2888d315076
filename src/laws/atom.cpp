// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/laws/atom.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace asperity {
namespace {

double below(double v) { return std::nextafter(v, -std::numeric_limits<double>::infinity()); }

std::string num(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

// Fraction of the sample at or below t.
double ecdf(std::span<const double> x, double t) {
  return double(std::count_if(x.begin(), x.end(), [t](double v) { return v <= t; })) / double(x.size());
}

// The sample has no spread: every value is v.
AtomTest no_spread(double v, const Cdf& cdf, std::size_t units) {
  const double lo = std::clamp(cdf(below(v)), 0.0, 1.0), hi = std::clamp(cdf(v), 0.0, 1.0);
  const double m = std::max(0.0, hi - lo);
  AtomTest t;
  t.D = std::max(lo, 1.0 - hi);
  // m^units underflows to 0 for a law without mass at v: the reject the exact test asks for.
  t.p = std::min(1.0, 2.0 * std::pow(m, double(units)));
  t.note = "sample without spread (every value " + num(v) + "): exact test, the law's mass there m = " + num(m) +
           ", p = min(1, 2 m^" + std::to_string(units) + ")";
  return t;
}

}  // namespace

std::optional<AtomTest> exact_atom_test(std::span<const double> x, const Cdf& cdf, std::size_t units,
                                        std::optional<double> atom) {
  if (x.empty()) throw std::invalid_argument("exact_atom_test: empty sample");
  if (units == 0) throw std::invalid_argument("exact_atom_test: units must be >= 1");
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  if (*lo == *hi) return no_spread(*lo, cdf, units);
  // A law that is the atom at v: F jumps from 0 to 1 there.
  if (!atom || !(cdf(below(*atom)) <= 0.0 && cdf(*atom) >= 1.0)) return std::nullopt;
  AtomTest t;
  t.D = std::max(ecdf(x, below(*atom)), 1.0 - ecdf(x, *atom));
  t.p = 0;
  t.note = "the law is the atom at " + num(*atom) + " and the sample has other values (impossible under the law): exact test, p = 0";
  return t;
}

}  // namespace asperity
