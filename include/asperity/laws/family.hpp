// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The run-level decision: the decisive tests of one run are a family, and the run rejects (exit
// status 1) only when Holm's step-down procedure rejects at least one of them at the run's alpha.
// Each test alone is calibrated at alpha, so a run of ~6 of them rejecting whenever any one does
// is a false alarm far more often than alpha (issue 25: 15 of 300 seeds); Holm bounds the
// probability of any false rejection in the family by alpha.
//
// Holm (1979) rests on Bonferroni's inequality only: it is valid under ANY dependence between the
// tests (r_x and r_y of the same drops, Eq. 14 and the exact law on the same sample), needs only
// that each p-value be super-uniform under its own law (P(p <= t) <= t: exact KS, the bootstrap's
// (1 + c)/(B + 1), the doubled binomial tail), and is uniformly more powerful than Bonferroni.
#include <cstddef>
#include <span>
#include <vector>

#include "asperity/laws/verdict.hpp"

namespace asperity {

/// Holm-adjusted p-values, in the order given: with p sorted ascending, p~_(k) = max over j <= k of
/// min(1, (m - j + 1) p_(j)), m = p.size(). A test is rejected by the family at alpha iff
/// p~ <= alpha. Monotone in p; equal to p for m = 1. Throws std::invalid_argument for a NaN or
/// a value outside [0, 1].
std::vector<double> holm_adjusted(std::span<const double> p);

/// Which tests of a run form its family: the decisive ones that were decided (verdict accept or
/// reject). Excluded: not decisive (printed laws, explicit runs of too few spheres: information
/// only), skipped (no p-value) and undecided (the bootstrap's smallest attainable p is not below
/// alpha: it could never be rejected, and counting it would only make the others harder to reject).
inline bool in_family(const LawTest& t) {
  return t.decisive && (t.verdict == Verdict::accept || t.verdict == Verdict::reject);
}

/// The family-wise decision of a run at level alpha (report.json "family").
struct FamilyDecision {
  double alpha = 0;                     ///< the family's level (the run's --alpha)
  std::size_t tests = 0;                ///< m: the members of the family
  std::vector<double> adjusted_p;       ///< per test given; NaN for a test outside the family
  std::vector<bool> reject;             ///< per test given: rejected by the family
  bool rejected = false;                ///< any member rejected: the run exits 1
  double min_adjusted_p = 1;            ///< smallest adjusted p of the members (NaN without members)
};

/// Holm's step-down over the members (member[i]) of p at level alpha; the others get NaN and are
/// never rejected. Throws std::invalid_argument if sizes differ or alpha is not in (0, 1).
FamilyDecision holm_decision(std::span<const double> p, const std::vector<bool>& member, double alpha);

/// The same over tests with their p-values: `p_of(test)` reads a test's p (rows of different
/// kinds keep it in different places).
template <class Test, class P>
FamilyDecision family_decision(const std::vector<Test>& tests, P p_of, double alpha) {
  std::vector<double> p;
  std::vector<bool> member;
  for (const auto& t : tests) {
    p.push_back(p_of(t));
    member.push_back(in_family(t));
  }
  return holm_decision(std::span<const double>(p), member, alpha);
}

}  // namespace asperity
