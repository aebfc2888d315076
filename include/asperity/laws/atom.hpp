// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Exact comparison of a degenerate sample or law. When every drop has the same value (e.g. every
// drop a core contact: eps = eps_n and Omega'_x = Omega_x exactly), the KS statistic has no null
// distribution to speak of: every sphere-block bootstrap replicate D* is 0, so any D > 0 (the law's
// tiny mass off the atom) sits at the bootstrap's floor p = 1/(B + 1) and an exactly true law is
// rejected (issue 25). The degenerate case is decided exactly instead.
#include <cstddef>
#include <optional>
#include <span>
#include <string>

#include "asperity/laws/statistics.hpp"

namespace asperity {

/// The exact comparison of a degenerate sample or law (exact_atom_test): no bootstrap, which would
/// have nothing to resample and sit at its floor p = 1/(B + 1).
struct AtomTest {
  double D = 0;     ///< sup |F_n - F|, exact
  double p = 1;     ///< exact p-value: 1 (the sample is the law's atom), 0 (impossible under the law), or 2 m^units
  std::string note; ///< what was compared, for the report
};

/// The sample `x` (any order, non-empty) against the law `cdf`, whose atom (if it has one) is at `atom`:
///  - the sample has no spread (every value v): the count K of draws off v is Binomial(units, 1 - m)
///    with m = F(v) - F(v-) the law's mass at v, observed K = 0, two-sided p = min(1, 2 m^units).
///    A law that is the atom at v (m = 1) gives p = 1 (accept); a law without mass at v (continuous,
///    or its atom elsewhere) gives p = 0 (reject).
///  - the law is an atom (all its mass at `atom`) and the sample has spread: the values off the
///    atom are impossible under the law, p = 0.
///  - otherwise std::nullopt: the ordinary tests apply.
/// `units`: the independent units of the sample (drops when iid; spheres in the explicit design,
/// where one sphere's drops share its own core probability q: P(all K spheres at v) = prod E[q^M]
/// <= m^K, so p with units = K is conservative). O(n) with three evaluations of cdf: no sort.
std::optional<AtomTest> exact_atom_test(std::span<const double> x, const Cdf& cdf, std::size_t units,
                                        std::optional<double> atom = std::nullopt);

}  // namespace asperity
