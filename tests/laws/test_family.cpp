// SPDX-License-Identifier: GPL-3.0-or-later
// The run-level decision (laws/family.hpp: Holm's step-down) and the exact comparison of
// degenerate samples and atom laws (laws/atom.hpp). Each test names the input a wrong
// implementation would get wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include <boost/math/distributions/binomial.hpp>

#include "asperity/laws/atom.hpp"
#include "asperity/laws/family.hpp"

namespace {

using namespace asperity;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

FamilyDecision holm_all(const std::vector<double>& p, double alpha) {
  return holm_decision(p, std::vector<bool>(p.size(), true), alpha);
}

TEST(Holm, TextbookExample) {
  // Holm (1979) as Wikipedia's "Holm-Bonferroni method" works it: p = (0.01, 0.04, 0.03, 0.005),
  // alpha = 0.05. Sorted: 0.005 < 0.05/4, 0.01 < 0.05/3, 0.03 > 0.05/2: stop. H4 and H1 are
  // rejected; adjusted p = (0.03, 0.06, 0.06, 0.02).
  const auto d = holm_all({0.01, 0.04, 0.03, 0.005}, 0.05);
  EXPECT_EQ(d.tests, 4u);
  EXPECT_EQ(d.reject, (std::vector<bool>{true, false, false, true}));
  const std::vector<double> want{0.03, 0.06, 0.06, 0.02};
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(d.adjusted_p[i], want[i], 1e-15) << i;
  EXPECT_TRUE(d.rejected);
  EXPECT_NEAR(d.min_adjusted_p, 0.02, 1e-15);
}

TEST(Holm, WrongProceduresFailTheseCases) {
  // Unadjusted "min p < alpha" (the old rule) rejects (0.03, 0.5) at 0.05; Holm does not (0.06).
  EXPECT_FALSE(holm_all({0.03, 0.5}, 0.05).rejected);
  // Hochberg's step-up rejects both of (0.04, 0.045) (the largest is <= alpha); Holm's step-down
  // stops at the first: 2 x 0.04 = 0.08 > 0.05.
  EXPECT_FALSE(holm_all({0.04, 0.045}, 0.05).rejected);
  // Bonferroni rejects only the first of (0.01, 0.02, 0.04) (0.03, 0.06, 0.12); Holm all three
  // (0.03, 0.04, 0.04).
  EXPECT_EQ(holm_all({0.01, 0.02, 0.04}, 0.05).reject, (std::vector<bool>{true, true, true}));
  // Adjusted p without the running max would give 0.04 < 0.045 to the larger p of (0.0225, 0.04):
  // 2 x 0.0225 = 0.045, then 1 x 0.04 = 0.04 -> must be 0.045 (monotone).
  const auto d = holm_all({0.0225, 0.04}, 0.05);
  EXPECT_NEAR(d.adjusted_p[1], 0.045, 1e-15);
}

TEST(Holm, OneTestIsThePlainTestAndAdjustedPIsMonotone) {
  for (double p : {0.0, 1e-9, 0.0099, 0.0101, 0.5, 1.0}) {
    const auto d = holm_all({p}, 0.01);
    EXPECT_EQ(d.adjusted_p[0], p);
    EXPECT_EQ(d.rejected, verdict_at(p, 0.01) == Verdict::reject) << p;
  }
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int rep = 0; rep < 200; ++rep) {
    std::vector<double> p(1 + rep % 9);
    for (auto& v : p) v = std::pow(u(g), 3);
    const auto adj = holm_adjusted(p);
    for (std::size_t i = 0; i < p.size(); ++i) {
      EXPECT_GE(adj[i], p[i]);
      EXPECT_LE(adj[i], std::min(1.0, double(p.size()) * p[i]) + 1e-15);
      for (std::size_t j = 0; j < p.size(); ++j)
        if (p[i] <= p[j]) {
          EXPECT_LE(adj[i], adj[j]) << "not monotone";
        }
    }
  }
  EXPECT_THROW(holm_adjusted(std::vector<double>{0.5, kNaN}), std::invalid_argument);
  EXPECT_THROW(holm_adjusted(std::vector<double>{1.5}), std::invalid_argument);
}

TEST(Holm, OnlyDecidedDecisiveTestsAreMembers) {
  // A not-decisive row with p = 1e-9 (a printed law) must neither reject the run nor count in m.
  std::vector<LawTest> rows(4);
  const std::vector<double> p{1e-9, 0.004, 0.5, kNaN};
  rows[0].decisive = false, rows[0].verdict = Verdict::reject;
  rows[1].decisive = true, rows[1].verdict = Verdict::reject;
  rows[2].decisive = true, rows[2].verdict = Verdict::accept;
  rows[3].decisive = true, rows[3].verdict = Verdict::skipped;
  std::size_t i = 0;
  const auto d = family_decision(rows, [&](const LawTest&) { return p[i++]; }, 0.01);
  EXPECT_EQ(d.tests, 2u);
  EXPECT_TRUE(std::isnan(d.adjusted_p[0]) && std::isnan(d.adjusted_p[3]));
  EXPECT_NEAR(d.adjusted_p[1], 0.008, 1e-15);
  EXPECT_TRUE(d.rejected);
  rows[1].verdict = Verdict::undecided;  // undecided: out of the family, nothing left to reject
  i = 0;
  EXPECT_FALSE(family_decision(rows, [&](const LawTest&) { return p[i++]; }, 0.01).rejected);
}

// Family-wise error rate by simulation: m = 6 true nulls with uniform p, independent and fully
// dependent (one p for all: the worst case for the old rule is independence, for Bonferroni-type
// bounds neither is a problem). n families, statistic: the count of families with any rejection,
// one-sided binomial p against rate alpha, threshold 1e-3. The old rule (any p <= alpha) fails
// the independent case: 1 - 0.99^6 = 5.9 % >> 1 %.
TEST(Holm, FamilyWiseErrorAtMostAlphaByMonteCarlo) {
  const int n = 20000, m = 6;
  const double alpha = 0.01;
  std::mt19937_64 g(11);
  std::uniform_real_distribution<double> u(0, 1);
  boost::math::binomial_distribution<double> bin(n, alpha);
  for (bool dependent : {false, true}) {
    int holm = 0, old = 0;
    for (int f = 0; f < n; ++f) {
      std::vector<double> p(m);
      const double common = u(g);
      for (auto& v : p) v = dependent ? common : u(g);
      holm += holm_all(p, alpha).rejected;
      old += *std::min_element(p.begin(), p.end()) <= alpha;
    }
    const double tail = holm > 0 ? boost::math::cdf(boost::math::complement(bin, holm - 1)) : 1.0;
    const double tail_old = old > 0 ? boost::math::cdf(boost::math::complement(bin, old - 1)) : 1.0;
    std::printf("FWER (%s, m = %d, n = %d, alpha = %g): Holm %d (binomial P(X >= k) = %.3g), old rule %d (%.3g); "
                "threshold 1e-3\n", dependent ? "dependent" : "independent", m, n, alpha, holm, tail, old, tail_old);
    EXPECT_GT(tail, 1e-3) << "Holm's family-wise error exceeds alpha";
    if (!dependent) {
      EXPECT_LT(tail_old, 1e-3) << "the old rule must fail this check";
    }
  }
}

// A law that is the atom at v (F = 0 below v, 1 from v on).
Cdf atom_at(double v) {
  return [v](double t) { return t >= v ? 1.0 : 0.0; };
}
// Mass m at v, the rest N(v - 1, 0.1) (below v, like the asperity contacts' eps < eps_n).
Cdf mixed(double v, double m) {
  return [v, m](double t) { return (1 - m) * 0.5 * std::erfc(-(t - (v - 1)) / (0.1 * std::sqrt(2.0))) + (t >= v ? m : 0.0); };
}

TEST(ExactAtom, SampleAtTheAtomIsAcceptedAShiftedAtomRejected) {
  const double v = 0.94524376;
  const std::vector<double> at(2000, v), shifted(2000, std::nextafter(v, 1.0));
  const auto a = exact_atom_test(at, atom_at(v), 50, v);
  ASSERT_TRUE(a.has_value());
  EXPECT_EQ(a->p, 1.0);
  EXPECT_EQ(a->D, 0.0);
  // The law's atom one ulp away: no mass at the sample's value: p = 0 (the bootstrap gave 0.001 to both).
  const auto b = exact_atom_test(at, atom_at(std::nextafter(v, 1.0)), 50, std::nextafter(v, 1.0));
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->p, 0.0);
  EXPECT_EQ(exact_atom_test(shifted, atom_at(v), 50, v)->p, 0.0);
  // The law is the atom, the sample has one value off it: impossible under the law.
  std::vector<double> one_off = at;
  one_off[17] = v - 1e-3;
  const auto c = exact_atom_test(one_off, atom_at(v), 50, v);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->p, 0.0);
  EXPECT_NEAR(c->D, 1.0 / 2000, 1e-15);
}

TEST(ExactAtom, NoSpreadAgainstALawWithMostOfItsMassThere) {
  // m = 1 - 1e-4 (fig4 with N = 1: the bare sphere touches with probability ~1 - 1e-4): 2000
  // drops all at v have probability 0.82: p = min(1, 2 x 0.82) = 1. At 10^5 units the same sample
  // has probability e^-10: p = 9e-5, rejected. A law with half its mass there: p = 2^-1999 -> 0.
  const double v = 0.9;
  const std::vector<double> x(2000, v);
  EXPECT_EQ(exact_atom_test(x, mixed(v, 1 - 1e-4), 2000)->p, 1.0);
  const double p5 = exact_atom_test(x, mixed(v, 1 - 1e-4), 100000)->p;
  EXPECT_NEAR(p5, 2 * std::pow(1 - 1e-4, 1e5), 1e-9);
  EXPECT_LT(p5, 0.01);
  EXPECT_LT(exact_atom_test(x, mixed(v, 0.5), 2000)->p, 1e-300);
  // A continuous law has no mass at any value: a sample without spread is rejected.
  const Cdf normal = [](double t) { return 0.5 * std::erfc(-t / std::sqrt(2.0)); };
  EXPECT_EQ(exact_atom_test(x, normal, 2000)->p, 0.0);
}

TEST(ExactAtom, OrdinarySamplesAreLeftToTheOrdinaryTests) {
  const Cdf normal = [](double t) { return 0.5 * std::erfc(-t / std::sqrt(2.0)); };
  std::vector<double> x{-0.3, 0.1, 0.7, 1.2};
  EXPECT_FALSE(exact_atom_test(x, normal, 4).has_value());
  // A law with an atom that is not all of its mass: the randomised-PIT KS / bootstrap decide.
  EXPECT_FALSE(exact_atom_test(x, mixed(0.7, 0.5), 4, 0.7).has_value());
  EXPECT_THROW(exact_atom_test(std::vector<double>{}, normal, 1), std::invalid_argument);
}

}  // namespace
