// SPDX-License-Identifier: GPL-3.0-or-later
// The finite-N correction of Eq. 14 seen from explicit geometry (issue 14, item 2): at N = 10^3,
// explicit drops (spheres x 400 rotations, grid queries, streaming statistics; 20 seeds of
// 5 x 10^5 drops since issue 39) must reject Eq. 14 and keep the exact finite-N law, by the likelihood ratio of the two laws with its
// error from the spread between blocks of spheres (laws/binned.hpp). Theory: an iid sample needs
// n* = 7.3 x 10^5 drops for power 0.9 at alpha = 0.01 (lr_sample_size); the quenched disorder of
// 400 rotations per sphere inflates the variance by ~1.5 (measured: 1.9 at 1600 rotations), so
// 2 x 10^6 drops give z ~ 5. A KS test would need ~(2/D)^2 = 6 x 10^6 drops (D = 8.1 x 10^-4).
// At the paper's premise: the asperity radius a = 6e-5 m makes core contacts (the bare central
// sphere touching first) rare, P = (1 - a/2R)^N = 4.3e-5 per drop, so the contact vector is the
// lowest asperity's in all but ~1e-4 of the drops (with a = 0.65 um, 90 % would be core contacts).
// The asperity centres, hence r_xy, r_x, r_y, do not depend on a: the statistics are the same bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "asperity/experiments/streaming.hpp"
#include "asperity/laws/binned.hpp"
#include "asperity/laws/statistics.hpp"
#include "asperity/laws/theory.hpp"
#include "sanitized.hpp"

using namespace asperity;

// The acceptance is a statement about 20 fixed seeds (issue 39), not one: a single seed's exact-law
// p-value is below 0.01 one time in a hundred by construction, and seed 1 of the one-block stream
// was such a seed (p = 0.0027). Each seed is a quarter of the old design (1250 spheres x 400
// rotations = 5 x 10^5 drops; z ~ 2.5 against Eq. 14 each). Accepted when (a) the 20 exact-law
// p-values are uniform (KS against U(0, 1), p > 0.001: a calibrated law fails this once in 1000
// suites), (b) the pooled L, mean of the seeds with se = sqrt(sum se^2) / 20, rejects Eq. 14
// (z > 4.75, one-sided p < 10^-6; expected z ~ 11) and (c) keeps the exact law (|z| < 3.29,
// two-sided p > 0.001), every seed at the paper's premise with every cross-checked query agreeing.
TEST(FiniteN, ExplicitGeometryRejectsEq14AndKeepsTheExactLawAtN1000OverTwentySeeds) {
  // Under the sanitizers two seeds walk the same code (the statistics are the Release pass's: 10^7
  // drops cost minutes there).
  constexpr int kSeeds = asperity::testing::kSanitized ? 2 : 20;
  const Law eq14 = eq14_rxy(1000, 3e-3), exact = exact_sphere_rxy(1000, 3e-3);
  std::vector<double> p_exact;
  double L = 0, var = 0, kl10 = 0, kl01 = 0;
  std::uint64_t drops = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 1; k <= kSeeds; ++k) {
    EnsembleConfig c;
    c.sphere = {1000, 3e-3, 6e-5};
    c.mode = Mode::explicit_spheres;
    c.spheres = 1250;
    c.drops = 500000;
    c.seed = static_cast<std::uint64_t>(k);
    c.statistics = Statistics::streaming;
    const ContactStream s = run_contact_stream(c);
    const LrTest t = binned_lr(s.state.stats[0], eq14.cdf, exact.cdf);
    std::printf("seed %2d: L = %.3g +- %.2g per drop; Eq. 14 z = %.2f; exact z = %.2f, p = %.3g\n", k, t.L, t.se,
                t.law0.value, t.law1.value, t.law1.p);
    ASSERT_EQ(s.state.stats[0].n(), c.drops);
    EXPECT_LE(double(s.state.core_contacts), 1e-3 * double(c.drops)) << "seed " << k << ": the paper's premise";
    ASSERT_EQ(s.cross_check.queries, s.cross_check.agreed) << "seed " << k;
    p_exact.push_back(t.law1.p);
    L += t.L / kSeeds, var += t.se * t.se / (double(kSeeds) * kSeeds);
    kl10 += t.kl10 / kSeeds, kl01 += t.kl01 / kSeeds;
    drops += c.drops;
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::sort(p_exact.begin(), p_exact.end());
  const KsResult u = ks_one_sample(p_exact, [](double x) { return std::clamp(x, 0.0, 1.0); });
  const double se = std::sqrt(var), z_eq14 = (L + kl01) / se, z_exact = (L - kl10) / se;
  std::printf("%d seeds, %llu drops in %.1f s: pooled L = %.3g +- %.2g (exact expects %.3g, Eq. 14 %.3g): z vs Eq. 14 "
              "%.2f, vs exact %.2f; exact-law p-values uniform: KS D = %.3f, p = %.3g\n",
              kSeeds, (unsigned long long)drops, secs, L, se, kl10, -kl01, z_eq14, z_exact, u.D, u.p);
  if (asperity::testing::kSanitized) return;
  EXPECT_GT(u.p, 1e-3) << "the exact law's p-values over the seeds must be uniform";
  EXPECT_GT(z_eq14, 4.75) << "Eq. 14 must be rejected at N = 10^3 by the pooled seeds";
  EXPECT_LT(std::abs(z_exact), 3.29) << "the pooled seeds must keep the exact finite-N law";
}

TEST(FiniteN, SampledControlFromTheExactLaw) {
  // Control without geometry: iid drops from the exact law (sampled mode), the same size: the
  // exact law is kept and Eq. 14 rejected; the se is the iid one (no quenched disorder).
  EnsembleConfig c;
  c.sphere = {1000, 3e-3, 6e-5};
  c.mode = Mode::sampled;
  c.drops = 2000000;
  c.seed = 2;
  c.statistics = Statistics::streaming;
  const ContactStream s = run_contact_stream(c);
  const LrTest t = binned_lr(s.state.stats[0], eq14_rxy(1000, 3e-3).cdf, exact_sphere_rxy(1000, 3e-3).cdf);
  std::printf("sampled control: L = %.3g +- %.2g; Eq. 14 p = %.2g, exact p = %.2g\n", t.L, t.se, t.law0.p, t.law1.p);
  EXPECT_LT(t.law0.p, 0.01);
  EXPECT_GT(t.law1.p, 0.01);
}
