// SPDX-License-Identifier: GPL-3.0-or-later
// The asymmetric Laplace law (paper Eq. 2) and its maximum-likelihood fit.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <stdexcept>
#include <limits>
#include <vector>

#include "asperity/laws/laplace.hpp"
#include "asperity/laws/statistics.hpp"
#include "asperity/laws/verdict.hpp"
#include "asperity/core/random.hpp"
#include "sanitized.hpp"

using namespace asperity;

namespace {
std::vector<double> draw(const AsymmetricLaplace& law, std::size_t n, std::uint64_t index) {
  Stream s(7, Purpose::test, index);
  std::vector<double> x(n);
  for (auto& v : x) v = law.sample(s);
  return x;
}
AsymmetricLaplace truth() { return {0.9, std::log(3e5), std::log(1e6)}; }  // the scale of eps here
}  // namespace

TEST(Laplace, NormalisedContinuousAndNoUnderflow) {
  // Rates of 1e7 at m = 0.9: the paper's amplitude b = h e^{-a m} would be e^{-9e6} = 0.
  const AsymmetricLaplace law{0.9, std::log(1e7), std::log(2e7)};
  const double h = 1e7 * 2e7 / 3e7;
  EXPECT_NEAR(law.pdf(0.9) / h, 1.0, 1e-12);
  EXPECT_NEAR(law.pdf(0.9 - 1e-9) / h, 1.0, 1e-1);  // continuous at the mode
  EXPECT_TRUE(std::isfinite(law.log_pdf(0.8)));
  EXPECT_NEAR(law.cdf(0.9), 2e7 / 3e7 * 1.0 - 0.0 + 0.0, 1e-12);  // mass left of m = c/(a+c)
  // Quantile inverts cdf, and a trapezoid integral of the pdf is 1.
  for (double p : {1e-6, 0.1, 0.5, 0.66, 0.9, 1 - 1e-9}) EXPECT_NEAR(law.cdf(law.quantile(p)), p, 1e-9);
  double sum = 0;
  const double lo = law.quantile(1e-12), hi = law.quantile(1 - 1e-12);
  const int K = 200000;
  for (int i = 0; i < K; ++i) {
    const double t0 = lo + (hi - lo) * i / K, t1 = lo + (hi - lo) * (i + 1) / K;
    sum += 0.5 * (law.pdf(t0) + law.pdf(t1)) * (t1 - t0);
  }
  EXPECT_NEAR(sum, 1.0, 1e-4);
}

TEST(Laplace, FitRecoversParametersWithinStatedErrors) {
  // n = 2e4 draws of the law at the scale of eps (rates 3e5 and 1e6 around 0.9): each estimate
  // within 4 of its Fisher standard errors, and the se close to the asymptotic formula.
  const auto law = truth();
  const auto x = draw(law, 20000, 1);
  const auto f = fit_asymmetric_laplace(x);
  EXPECT_LT(std::abs(f.m.value - law.m), 4 * f.m.se);
  EXPECT_LT(std::abs(f.log_a.value - law.log_a), 4 * f.log_a.se);
  EXPECT_LT(std::abs(f.log_c.value - law.log_c), 4 * f.log_c.se);
  // A rate 10 % off is outside the same 4 se (se(log a) ~ 0.013 here).
  EXPECT_GT(std::abs(f.log_a.value - (law.log_a + std::log(1.1))), 4 * f.log_a.se);
  EXPECT_GT(f.log_a.se, 0.005);
  EXPECT_LT(f.log_a.se, 0.05);
  EXPECT_NEAR(f.a.se / f.a.value, f.log_a.se, 1e-15);
}

TEST(Laplace, ConfidenceIntervalsCover) {
  // 400 fits of n = 1000: the fraction of +-1.96 se intervals containing the truth must be
  // 0.95 +- 3 binomial sd (sd = 0.011). A wrong se (e.g. half) would give ~0.68 and fail.
  const auto law = truth();
  const int reps = 400;
  int cov_m = 0, cov_a = 0, cov_c = 0, wrong_a = 0;
  for (int r = 0; r < reps; ++r) {
    const auto f = fit_asymmetric_laplace(draw(law, 1000, 100 + r));
    cov_m += std::abs(f.m.value - law.m) < 1.96 * f.m.se;
    cov_a += std::abs(f.log_a.value - law.log_a) < 1.96 * f.log_a.se;
    cov_c += std::abs(f.log_c.value - law.log_c) < 1.96 * f.log_c.se;
    // A se 25 % too small (the size that matters: e.g. a missing factor in the Fisher information).
    wrong_a += std::abs(f.log_a.value - law.log_a) < 1.96 * 0.75 * f.log_a.se;
  }
  for (int c : {cov_m, cov_a, cov_c}) {
    EXPECT_GT(c / double(reps), 0.95 - 0.033) << c;
    EXPECT_LT(c / double(reps), 0.95 + 0.033) << c;
  }
  EXPECT_LT(wrong_a / double(reps), 0.95 - 0.033) << wrong_a;  // ~0.86 expected
}

TEST(Laplace, ProfileLikelihoodIsTheMaximum) {
  // The closed-form profile beats nearby parameter values and every other data point as mode.
  const auto x = draw(truth(), 500, 3);
  const auto f = fit_asymmetric_laplace(x);
  auto ll = [&](const AsymmetricLaplace& l) {
    double s = 0;
    for (double v : x) s += l.log_pdf(v);
    return s;
  };
  EXPECT_NEAR(ll(f.law), f.log_likelihood, 1e-6 * std::abs(f.log_likelihood));
  for (double d : {-0.01, 0.01}) {
    auto l = f.law;
    l.log_a += d;
    EXPECT_LT(ll(l), f.log_likelihood);
    l = f.law;
    l.log_c += d;
    EXPECT_LT(ll(l), f.log_likelihood);
  }
  std::vector<double> s = x;
  std::sort(s.begin(), s.end());
  for (std::size_t j = 1; j + 1 < s.size(); j += 7) {
    std::vector<double> one(1, s[j]);
    // Best rates for mode s[j] (closed form) never beat the fit.
    double L = 0, R = 0;
    for (double v : s) (v < s[j] ? L : R) += std::abs(v - s[j]);
    const double n = double(s.size()), q = std::sqrt(L * R);
    const AsymmetricLaplace l{s[j], std::log(n / (L + q)), std::log(n / (R + q))};
    EXPECT_LE(ll(l), f.log_likelihood + 1e-9 * std::abs(f.log_likelihood));
  }
}

TEST(Laplace, GoodnessOfFitAcceptsLaplaceAndRejectsOthers) {
  // Parametric bootstrap, B = 99, n = 2000. The ALD sample is accepted; a Gaussian and a
  // uniform sample of the same scale are rejected at the smallest attainable p (1/(B+1)).
  const auto law = truth();
  auto x = draw(law, 2000, 4);
  std::sort(x.begin(), x.end());
  const auto g = laplace_gof(x, fit_asymmetric_laplace_sorted(x), 99, 1, 0);
  EXPECT_GT(g.p, 0.05);
  Stream s(8, Purpose::test, 0);
  std::vector<double> gauss(2000), unif(2000);
  for (std::size_t i = 0; i < gauss.size(); ++i) {
    const double u = s.uniform(), v = s.uniform0();
    gauss[i] = 0.9 + 3e-6 * std::sqrt(-2 * std::log(u)) * std::cos(2 * M_PI * v);
    unif[i] = 0.9 + 1e-5 * s.uniform0();
  }
  for (auto* y : {&gauss, &unif}) {
    std::sort(y->begin(), y->end());
    const auto gy = laplace_gof(*y, fit_asymmetric_laplace_sorted(*y), 99, 1, 1);
    EXPECT_LE(gy.p, 0.02) << gy.D;
  }
}

TEST(Laplace, SortedSampleIsTheLaw) {
  // The bootstrap's replicate sampler against the law it claims, at the largest n the bounce
  // groups reach (~1e6): one-sample KS, n = 1e6, accepted at p > 1e-3 (fixed seed). The wrong
  // input of the size that matters: the same sampler with the left rate 2 % off (its cdf is off by
  // 3.5e-3 at the mode alone; D = 8e-3 measured; the KS distances the bootstrap compares are ~1e-3
  // at this n, so a sampler error of that size would move every p): rejected at p < 1e-6.
  // Under the sanitizers (tests/sanitized.hpp) the same code paths at 1/10 of the sizes, the
  // statistics asserted in the Release pass only.
  constexpr bool full = !asperity::testing::kSanitized;
  const auto law = truth();
  std::vector<double> y(full ? 1000000 : 100000);
  Stream s(11, Purpose::test, 0);
  sorted_sample(law, s, y);
  EXPECT_TRUE(std::is_sorted(y.begin(), y.end()));
  const auto ks = ks_one_sample(y, [&](double t) { return law.cdf(t); });
  if (full) {
    EXPECT_GT(ks.p, 1e-3) << "D = " << ks.D;
  }
  auto wrong = law;
  wrong.log_a += std::log(1.02);
  Stream s2(11, Purpose::test, 1);
  sorted_sample(wrong, s2, y);
  const auto kw = ks_one_sample(y, [&](double t) { return law.cdf(t); });
  if (full) {
    EXPECT_LT(kw.p, 1e-6) << "D = " << kw.D;
  }
  // Calibration: 300 samples of n = 2000 tested against the true law; P(p <= 0.05) = 0.05 within 4
  // sd (binomial sd 3.8): each sample's ECDF must fluctuate as an iid sample's does (a split K not
  // binomial or spacings not exponential would move the fraction).
  int low = 0;
  std::vector<double> z(2000);
  for (int r = 0; r < (full ? 300 : 30); ++r) {
    Stream sr(12, Purpose::test, static_cast<std::uint64_t>(r));
    sorted_sample(law, sr, z);
    low += ks_one_sample(z, [&](double t) { return law.cdf(t); }).p <= 0.05 ? 1 : 0;
  }
  if (full) {
    EXPECT_LT(std::abs(low - 15), 4 * std::sqrt(300 * 0.05 * 0.95)) << low;
  }
  // The same draws on every machine with the packaged Boost (1.74): a few values pinned.
  std::vector<double> w(1000);
  Stream sp(13, Purpose::test, 0);
  sorted_sample(law, sp, w);
  EXPECT_EQ(w[0], 0x1.ccc9f6b1fecbcp-1);
  EXPECT_EQ(w[247], 0x1.cccc487f9d8b8p-1);
  EXPECT_EQ(w[500], 0x1.cccc9e353de5cp-1);
  EXPECT_EQ(w[999], 0x1.cccd9bb0b50fap-1);
  std::cout << "n = 1e6: D = " << ks.D << ", p = " << ks.p << "; left rate 2 % off: D = " << kw.D << ", p = " << kw.p
            << "; calibration: " << low << " of 300 at p <= 0.05 (15 expected)\n";
}

TEST(Laplace, BootstrapIsCalibratedUnderTheNull) {
  // The replicates are drawn already sorted (sorted_sample: binomial split, Renyi sums). Under H0
  // the bootstrap p is uniform on {1/20, ..., 1} at B = 19: over 300 ALD samples of n = 400,
  // P(p <= 0.1) = 0.1 within 4 sd (a sorted sampler with the wrong law or a broken tail would shift
  // D_b against D and this fraction with it). The power side is the test above (Gaussian, uniform).
  const auto law = truth();
  int low = 0;
  for (int r = 0; r < 300; ++r) {
    auto x = draw(law, 400, 1000 + r);
    std::sort(x.begin(), x.end());
    low += laplace_gof(x, fit_asymmetric_laplace_sorted(x), 19, 7, r).p <= 0.1 + 1e-12 ? 1 : 0;
  }
  const double sd = std::sqrt(300 * 0.1 * 0.9);
  EXPECT_LT(std::abs(low - 30), 4 * sd) << low;
}

TEST(Laplace, BootstrapIndependentOfThreads) {
  auto x = draw(truth(), 3000, 5);
  std::sort(x.begin(), x.end());
  const auto f = fit_asymmetric_laplace_sorted(x);
  omp_set_num_threads(1);
  const auto g1 = laplace_gof(x, f, 40, 3, 9);
  omp_set_num_threads(2);
  const auto g2 = laplace_gof(x, f, 40, 3, 9);
  EXPECT_EQ(g1.D, g2.D);
  EXPECT_EQ(g1.p, g2.p);
}

TEST(Laplace, SequentialStopKeepsTheVerdict) {
  // The stop may only cut an accepting bootstrap short: over ALD samples (accepted) and Gaussian and
  // uniform ones (the deliberately wrong laws, rejected), at three alphas, the verdict with the stop is
  // the verdict of all B; a stopped run drew fewer replicates, saw >= K_stop exceedances and reports
  // K / L; a run that did not stop reports the exact (1 + K)/(1 + B). The rejected samples never stop.
  const auto law = truth();
  Stream s(21, Purpose::test, 0);
  std::vector<std::vector<double>> samples;
  for (int r = 0; r < 6; ++r) samples.push_back(draw(law, 1500, 300 + r));
  std::vector<double> gauss(1500), unif(1500);
  for (std::size_t i = 0; i < gauss.size(); ++i) {
    gauss[i] = 0.9 + 3e-6 * std::sqrt(-2 * std::log(s.uniform())) * std::cos(2 * M_PI * s.uniform0());
    unif[i] = 0.9 + 1e-5 * s.uniform0();
  }
  samples.push_back(gauss), samples.push_back(unif);
  int stopped = 0;
  for (std::size_t j = 0; j < samples.size(); ++j) {
    auto& x = samples[j];
    std::sort(x.begin(), x.end());
    const auto f = fit_asymmetric_laplace_sorted(x);
    const auto full = laplace_gof(x, f, 99, 4, j);
    EXPECT_EQ(full.replicates, 99u);
    for (double alpha : {0.01, 0.05, 0.2}) {
      const auto seq = laplace_gof(x, f, 99, 4, j, SequentialStop{5, alpha});
      EXPECT_EQ(verdict_at(seq.p, alpha), verdict_at(full.p, alpha)) << j << " alpha " << alpha;
      EXPECT_EQ(seq.D, full.D);
      if (seq.stopped_early) {
        ++stopped;
        EXPECT_LT(seq.replicates, 99u);
        EXPECT_GE(seq.exceedances, 5u);
        EXPECT_EQ(seq.p, double(seq.exceedances) / double(seq.replicates));
        EXPECT_GE(full.p, alpha);
      } else {
        EXPECT_EQ(seq.p, full.p);
      }
      if (j >= 6) {
        EXPECT_FALSE(seq.stopped_early) << "a rejected sample stopped early, alpha " << alpha;
      }
    }
  }
  EXPECT_GE(stopped, 6);  // the stop does happen on accepted samples
  // Where the stop happens is decided in replicate order: the same for any thread count.
  omp_set_num_threads(1);
  const auto f0 = fit_asymmetric_laplace_sorted(samples[0]);
  const auto g1 = laplace_gof(samples[0], f0, 99, 4, 0, SequentialStop{5, 0.01});
  omp_set_num_threads(2);
  const auto g2 = laplace_gof(samples[0], f0, 99, 4, 0, SequentialStop{5, 0.01});
  EXPECT_EQ(g1.p, g2.p);
  EXPECT_EQ(g1.replicates, g2.replicates);
}

TEST(Laplace, BatchEqualsOneTestAtATime) {
  // laplace_gof_batch runs the replicates of several tests in one loop (shared scratch across tests
  // of different n, a test's stop decided while other tests' replicates are in flight): every
  // result must equal that test alone on one thread, bit for bit, at 1 and 2 threads. Mix: an
  // accepted sample that stops early, a Gaussian (rejected, draws all B), one without a stop, a
  // tiny B and B = 0.
  const auto law = truth();
  std::vector<std::vector<double>> x = {draw(law, 1500, 40), {}, draw(law, 300, 41), draw(law, 4000, 42), draw(law, 50, 43)};
  Stream s(23, Purpose::test, 0);
  for (int i = 0; i < 1500; ++i) x[1].push_back(0.9 + 3e-6 * std::sqrt(-2 * std::log(s.uniform())) * std::cos(2 * M_PI * s.uniform0()));
  std::vector<LaplaceFit> fits;
  for (auto& v : x) std::sort(v.begin(), v.end()), fits.push_back(fit_asymmetric_laplace_sorted(v));
  const std::vector<GofJob> jobs = {{x[0], &fits[0], 99, 1, SequentialStop{5, 0.01}},
                                    {x[1], &fits[1], 99, 2, SequentialStop{5, 0.01}},
                                    {x[2], &fits[2], 40, 3, {}},
                                    {x[3], &fits[3], 3, 4, SequentialStop{1, 0.2}},
                                    {x[4], &fits[4], 0, 5, {}}};
  omp_set_num_threads(1);
  std::vector<LaplaceGof> alone;
  for (const auto& j : jobs) alone.push_back(laplace_gof(j.sorted, *j.fit, j.bootstrap, 9, j.stream_index, j.stop));
  EXPECT_TRUE(alone[0].stopped_early);
  EXPECT_EQ(alone[1].replicates, 99u);
  EXPECT_EQ(alone[1].exceedances, 0u);  // p = 1/(1 + B) = 0.01
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    // Tasks beside the replicates run once each and leave the results alone; a throwing task's
    // exception comes out after the loop.
    std::vector<int> ran(5, 0);
    std::vector<std::function<void()>> beside;
    for (std::size_t t = 0; t < ran.size(); ++t) beside.emplace_back([&ran, t] { ++ran[t]; });
    const auto batch = laplace_gof_batch(jobs, 9, beside);
    EXPECT_EQ(ran, std::vector<int>(5, 1));
    beside.emplace_back([] { throw std::runtime_error("task"); });
    EXPECT_THROW(laplace_gof_batch(jobs, 9, beside), std::runtime_error);
    ASSERT_EQ(batch.size(), jobs.size());
    for (std::size_t j = 0; j < jobs.size(); ++j) {
      EXPECT_EQ(batch[j].D, alone[j].D) << j;
      EXPECT_EQ(batch[j].p, alone[j].p) << j;
      EXPECT_EQ(batch[j].replicates, alone[j].replicates) << j;
      EXPECT_EQ(batch[j].exceedances, alone[j].exceedances) << j;
      EXPECT_EQ(batch[j].stopped_early, alone[j].stopped_early) << j;
      EXPECT_EQ(batch[j].bootstrap, jobs[j].bootstrap) << j;
    }
  }
}

TEST(Laplace, SequentialBootstrapIsCalibratedUnderTheNull) {
  // The same null as BootstrapIsCalibratedUnderTheNull with the stop (K = 5, B = 99): over 300 ALD
  // samples of n = 400, P(p <= 0.1) = 0.1 within 4 sd (binomial sd 5.2); a p that the stop biased
  // (e.g. K / L with L counted from 0, or the stop taken at the first exceedance) would move it.
  const auto law = truth();
  int low = 0;
  std::size_t drawn = 0;
  for (int r = 0; r < 300; ++r) {
    auto x = draw(law, 400, 1000 + r);
    std::sort(x.begin(), x.end());
    const auto g = laplace_gof(x, fit_asymmetric_laplace_sorted(x), 99, 7, r, SequentialStop{5, 0.01});
    low += g.p <= 0.1 + 1e-12 ? 1 : 0;
    drawn += g.replicates;
  }
  const double sd = std::sqrt(300 * 0.1 * 0.9);
  EXPECT_LT(std::abs(low - 30), 4 * sd) << low;
  EXPECT_LT(drawn, 300u * 99u / 2) << "the stop saved less than half the replicates under the null";
  // The deliberately wrong input: 40 Gaussian samples of the same n must leave the band (P(p <= 0.1)
  // far above 0.1 + 4 sd; 99 of 100 had p <= 0.1), so the band notices a p that is not calibrated.
  Stream g(22, Purpose::test, 0);
  int low_gauss = 0;
  for (int r = 0; r < 40; ++r) {
    std::vector<double> x(400);
    for (auto& v : x) v = 0.9 + 3e-6 * std::sqrt(-2 * std::log(g.uniform())) * std::cos(2 * M_PI * g.uniform0());
    std::sort(x.begin(), x.end());
    low_gauss += laplace_gof(x, fit_asymmetric_laplace_sorted(x), 99, 7, 500 + r, SequentialStop{5, 0.01}).p <= 0.1 ? 1 : 0;
  }
  EXPECT_GT(low_gauss, 4 + 4 * std::sqrt(40 * 0.1 * 0.9)) << low_gauss;
}

TEST(Laplace, BadInputNamesTheProblem) {
  EXPECT_THROW(fit_asymmetric_laplace(std::vector<double>{1, 2}), std::invalid_argument);
  EXPECT_THROW(fit_asymmetric_laplace(std::vector<double>{1, 1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(fit_asymmetric_laplace(std::vector<double>{1, NAN, 2, 3}), std::invalid_argument);
  EXPECT_THROW(fit_asymmetric_laplace_sorted(std::vector<double>{3, 2, 1}), std::invalid_argument);
  EXPECT_THROW(truth().quantile(1.0), std::invalid_argument);
}
