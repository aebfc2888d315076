// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The asymmetric Laplace law of the paper's Eq. 2 and its maximum-likelihood fit.
//
// Eq. 2 as printed, p = b e^{a eps} (eps < m), b e^{(a+c) m} e^{-c eps} (eps >= m), lists more
// constants than a normalised density continuous at its mode has. Normalised and continuous it is
//   p(t) = h e^{ a (t - m)}  (t <  m),
//   p(t) = h e^{-c (t - m)}  (t >= m),   h = a c / (a + c),
// three free parameters: the mode m and the rates a, c > 0 [1/unit of t]. The paper's amplitude
// b = h e^{-a m} is never formed: with rates a ~ 1e5..1e7 and m ~ 0.9 it underflows (e^{-1e6}).
// Everything here works with (m, log a, log c) and with differences t - m.
//
// Fit: for fixed m the likelihood has closed-form maxima
//   a = n / (L + sqrt(L R)),  c = n / (R + sqrt(L R)),  L = sum_{t<m} (m - t),  R = sum_{t>=m} (t - m),
// and the profile log-likelihood is n log n - n - 2 n log(sqrt(L) + sqrt(R)). sqrt(L) + sqrt(R) is
// concave between data points, so the maximum lies at a data point: all n are scanned in O(n) after
// sorting. m is restricted to points with data on both sides (L, R > 0): at the sample's edge the
// law degenerates to a one-sided exponential (c or a infinite).
// Standard errors from the expected Fisher information per observation in (m, log a, log c):
//   I_mm = a c, I_m,la = -a c/(a+c), I_m,lc = a c/(a+c),
//   I_la,la = c (2a + c)/(a+c)^2, I_lc,lc = a (2c + a)/(a+c)^2, I_la,lc = -a c/(a+c)^2
// (the ALD is differentiable in quadratic mean, so the MLE is asymptotically normal with
// covariance (n I)^-1 despite the kink; tests/test_laplace.cpp checks the coverage).
// Goodness of fit: KS with estimated parameters is not distribution-free, so its p-value comes
// from a parametric bootstrap (refit on samples drawn from the fitted law; Lilliefors-type).
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "asperity/laws/statistics.hpp"

namespace asperity {

class Stream;

/// Asymmetric Laplace law, normalised and continuous at the mode.
struct AsymmetricLaplace {
  double m = 0;      ///< mode
  double log_a = 0;  ///< log of the rate left of the mode
  double log_c = 0;  ///< log of the rate right of the mode

  double a() const;               ///< rate left of the mode, exp(log_a) [1/unit of t]
  double c() const;               ///< rate right of the mode, exp(log_c) [1/unit of t]
  double pdf(double t) const;     ///< density at t, exp(log_pdf(t))
  /// log density at t, computed from (m, log a, log c) without forming h when one rate dominates.
  double log_pdf(double t) const;
  /// P(T <= t): c/(a+c) e^{a (t-m)} below the mode, 1 - a/(a+c) e^{-c (t-m)} from it on.
  double cdf(double t) const;
  /// Inverse cdf, p in (0, 1).
  double quantile(double p) const;
  double mean() const;  ///< m + 1/c - 1/a
  /// One draw: m + E1/c - E2/a with E1, E2 standard exponentials (consumes two uniforms).
  double sample(Stream& s) const;
};

/// y.size() iid draws of `law`, sorted ascending, in O(n) without a logarithm per value: the
/// bootstrap's replicate sample (the count left of the mode from a binomial, each side's
/// exponential order statistics as Renyi sums of ziggurat exponentials; laplace.cpp says more).
void sorted_sample(const AsymmetricLaplace& law, Stream& s, std::span<double> y);

/// A maximum-likelihood fit of the asymmetric Laplace law to a sample.
struct LaplaceFit {
  AsymmetricLaplace law;       ///< the fitted law
  std::size_t n = 0;           ///< sample size
  std::size_t mode_rank = 0;   ///< index of m in the sorted sample
  double log_likelihood = 0;   ///< maximised log-likelihood of the whole sample, n log n - n - 2 n log(sqrt L + sqrt R)
  ///@{
  /// m, log a and log c with Fisher standard errors (expected information, see the file's comment).
  Estimate m, log_a, log_c;
  ///@}
  ///@{
  /// The rates a and c with delta-method se (se = rate x se(log rate)).
  Estimate a, c;
  ///@}
};

/// Maximum-likelihood fit. Needs n >= 3 finite values with at least one value strictly below and
/// one strictly above some sample point (otherwise std::invalid_argument naming the problem).
LaplaceFit fit_asymmetric_laplace(std::span<const double> x);
/// Same, for data already sorted ascending (checked).
LaplaceFit fit_asymmetric_laplace_sorted(std::span<const double> sorted);

/// The goodness of fit of a sample to its own fitted asymmetric Laplace law (laplace_gof).
struct LaplaceGof {
  double D = 0;               ///< KS distance of the sample to its fitted law
  /// parametric-bootstrap p-value: (1 + #{D_b >= D}) / (1 + B); after a sequential stop
  /// (stopped_early) the estimate K / L from the L replicates drawn, K of them >= D.
  double p = 1;
  std::size_t bootstrap = 0;  ///< B (the budget)
  std::size_t replicates = 0;   ///< L: replicates drawn (B unless stopped_early)
  std::size_t exceedances = 0;  ///< K: replicates with D_b >= D among them
  bool stopped_early = false;   ///< the sequential stop ended the bootstrap before B replicates
};

/// When the bootstrap may stop before B replicates: once K >= `exceedances` replicates reached D
/// and both K / L and (K + 1)/(B + 1) are >= alpha. The p of all B replicates could then only be
/// (K_B + 1)/(B + 1) >= (K + 1)/(B + 1) >= alpha: the verdict at alpha (accept) is the one all B
/// would give, and K / L estimates p (relative se ~ 1/sqrt(K), Besag & Clifford 1991). A test
/// heading for rejection never stops early. exceedances = 0: always all B.
struct SequentialStop {
  std::size_t exceedances = 0;  ///< K needed before stopping; 0: never stop early
  double alpha = 0;             ///< the level of the verdict the stop must not change
};

/// KS of the sample against its own fit with a parametric-bootstrap p-value. Replicate b draws n
/// values from Stream(seed, Purpose::analysis, stream_index, b + 1), refits and computes D_b;
/// replicates run in parallel (on one thread when called inside a parallel region) and the result,
/// including where a sequential stop happens (decided in replicate order), is the same for any
/// thread count.
LaplaceGof laplace_gof(std::span<const double> sorted, const LaplaceFit& fit, std::size_t bootstrap,
                       std::uint64_t seed, std::uint64_t stream_index, SequentialStop stop = {});

/// One test of laplace_gof_batch: laplace_gof's arguments but the seed (`sorted` and `fit` must
/// outlive the call).
struct GofJob {
  std::span<const double> sorted;    ///< the sample, sorted ascending
  const LaplaceFit* fit = nullptr;   ///< its fit (fit_asymmetric_laplace_sorted of `sorted`)
  std::size_t bootstrap = 0;         ///< B, the replicate budget
  std::uint64_t stream_index = 0;    ///< keeps the replicates of different tests apart
  SequentialStop stop;               ///< when the bootstrap may stop early
};

/// Several laplace_gof at once: the replicates of all jobs in one parallel loop (largest n B
/// first), so a large test's replicates are spread over the threads instead of one test per
/// thread with the largest left running alone. result[j] equals laplace_gof(jobs[j] ..., seed)
/// bit for bit, for any thread count: a job's stop is decided in its replicate order, and the
/// replicates computed past it (at most one per thread) are discarded. `beside`: other work of the
/// caller that shares the threads (each task run once, started before any replicate, in the given
/// order; the first exception is rethrown after the loop), so that a long task does not run alone.
std::vector<LaplaceGof> laplace_gof_batch(std::span<const GofJob> jobs, std::uint64_t seed,
                                          std::span<const std::function<void()>> beside = {});

}  // namespace asperity
