// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Sample statistics with honest uncertainties: histograms with Poisson error bars, one- and
// two-sample Kolmogorov-Smirnov tests with p-values, binned chi-square, and means, standard
// deviations and quantiles with standard errors (iid, or from batch means when samples are
// correlated within batches, e.g. many rotations of one sphere).
//
// Conventions: invalid input (NaN data or parameters, empty samples, unsorted "sorted" input,
// cdf values outside [0,1], ...) throws std::invalid_argument whose message names the offending
// value. NaN is returned only where documented (Estimate::se when it cannot be estimated,
// Chi2Result::p when fewer than 2 cells remain).
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

namespace asperity {

/// A cumulative distribution function F(x) = P(X <= x), values in [0, 1], non-decreasing.
using Cdf = std::function<double(double)>;

/// A value with its standard error (se is NaN when it cannot be estimated, e.g. one batch).
struct Estimate {
  double value = 0;  ///< the estimate
  double se = 0;     ///< its standard error, same unit (NaN: not estimable)
};

/// The outcome of a Kolmogorov-Smirnov test.
struct KsResult {
  double D = 0;        ///< sup |F_n - F|
  double p = 1;        ///< p-value under H0 (iid samples from F; F continuous)
  std::size_t n = 0;   ///< sample size (effective n*m/(n+m), rounded, for two samples)
};

/// Survival function of the Kolmogorov statistic: P(D_n >= d) for a sample of size n >= 1.
/// Always finite, in [0,1] and non-increasing in d: 1 for d <= 1/(2n) (D_n >= 1/(2n) always),
/// 0 for d >= 1. Otherwise, for n <= 10^5:
///  - exact (Marsaglia, Tsang & Wang 2003, see kolmogorov_cdf_mtw) as 1 - P(D_n < d) while
///    k = floor(n d) + 1 <= kolmogorov_exact_kmax(n) (cost O(k^3 log n), a few ms at most);
///  - in the upper tail n d^2 >= 4.2 (or d >= 1/2), when that is reachable within the cost
///    limit (all n < 829, some up to 1032), as 2 P(D_n^+ >= d) (exact Smirnov, smirnov_pvalue): exact for d >= 1/2;
///    for d < 1/2 the neglected P(D^+ >= d and D^- >= d) is ~exp(-6 n d^2) <~ 1e-11 relative,
///    whereas 1 - P(D_n < d) would lose ever more digits to cancellation. Small n are thus
///    exact for all d: relative error <~ 3e-11 for n <= 800 (<~ 1e-13 for n <= 20 and for
///    p > 0.01), checked against Steck's determinant formula in rational arithmetic;
///  - beyond the cost limit, kolmogorov_pvalue_asymptotic, blended linearly with the exact
///    value over the last 2% of d below the switch d_s = kmax/n so that p stays continuous and
///    monotone. This happens only for n >= 829, where d_s is at lambda = sqrt(n) d_s < 2.05
///    (lambda_s = 1.93 at n = 1000, 0.17 at n = 10^5).
/// For n > 10^5: kolmogorov_pvalue_asymptotic throughout.
/// Accuracy of the asymptotic branch (measured against the exact algorithm, n >= 900; also
/// the typical jump bridged by the blend):
/// relative error < 1% for p >= 5e-3, ~3% at p ~ 1e-5, ~5% at p ~ 1e-11, smaller as n grows.
/// Throws std::invalid_argument for NaN d or n = 0.
double kolmogorov_pvalue(double d, std::size_t n);

/// P(D_n < d) by the algorithm of Marsaglia, Tsang & Wang (2003), "Evaluating Kolmogorov's
/// distribution", J. Stat. Softw. 8(18): (H^n)_{kk} n!/n^n with k = floor(n d)+1, H of order
/// 2k-1, the decimal exponent carried separately (their 1e140 rescaling). No cost limit: it
/// takes O(k^3 log n) time and O(k^2) memory, so keep n d small. Absolute error of the cdf
/// ~1e-17 n (measured for n <= 800), so 1 - cdf loses relative accuracy in the far tail.
double kolmogorov_cdf_mtw(double d, std::size_t n);

/// One-sided Smirnov survival function P(D_n^+ >= d), D_n^+ = sup (F_n - F), exact
/// (Birnbaum & Tingey 1951 sum of positive terms), O(n). Also equals P(D_n^- >= d).
double smirnov_pvalue(double d, std::size_t n);

/// Asymptotic P(D_n >= d) = Q_KS(lambda), Q_KS(lambda) = 2 sum_{j>=1} (-1)^{j-1}
/// exp(-2 j^2 lambda^2), with Stephens' lambda = (sqrt(n) + 0.12 + 0.11/sqrt(n)) d. n is real
/// (> 0) so that the two-sample n_eff = nm/(n+m) can be used directly.
double kolmogorov_pvalue_asymptotic(double d, double n);

/// Largest k = floor(n d) + 1 for which kolmogorov_pvalue uses the exact algorithm at this n
/// (0 for n > 10^5). Exposed for tests and diagnostics.
std::size_t kolmogorov_exact_kmax(std::size_t n);

/// One-sample KS test: D = max_i max(i/n - F(x_i), F(x_i) - (i-1)/n), p = kolmogorov_pvalue.
/// `sorted` must be sorted ascending (checked) and non-empty; cdf must be continuous and
/// return values in [0,1] (checked: NaN or out-of-range values throw). +-inf samples are
/// allowed if cdf maps them to 0/1.
KsResult ks_one_sample(std::span<const double> sorted, const Cdf& cdf);
/// The same D and p as ks_one_sample, bit for bit, for a cdf that is expensive and
/// non-decreasing (a mixture of many laws): F is evaluated at every 32nd point first, and a run of
/// points between two evaluated ones only when the bounds F(lo) <= F <= F(hi) leave room for it to
/// reach the largest distance found (with a margin of 1e-12 for rounding in F). Measured under a
/// true law: n/23 evaluations at n = 1e5, n/31 at 1.9e6, but n/1.2 at 1e3 (the runs are too short
/// for their bounds to fall below D). Only evaluated values are checked to lie in [0, 1].
KsResult ks_one_sample_monotone(std::span<const double> sorted, const Cdf& cdf);
/// Two-sample KS test; both inputs sorted ascending (checked) and non-empty. D is exact
/// (ties within and between the samples are handled: both ECDFs step past a value before
/// they are compared, so identical samples give D = 0). p = kolmogorov_pvalue_asymptotic(D,
/// n_eff), n_eff = nm/(n+m); p = 1 when D = 0. This p is approximate: D is discrete (steps of
/// 1/lcm(n,m)) and Stephens' correction was derived for one sample. For n = m = 200 it is
/// ~9% (relative) below the exact Gnedenko-Korolyuk value near p = 0.05, so "p < 0.05" has a
/// true level of 0.052; the discrepancy shrinks as n_eff grows.
KsResult ks_two_sample(std::span<const double> a_sorted, std::span<const double> b_sorted);

/// Fixed-width histogram on [lo, hi). Samples outside are counted in `under`/`over`.
struct Histogram {
  ///@{
  /// The binned range [lo, hi), in the samples' unit.
  double lo = 0, hi = 1;
  ///@}
  std::vector<double> counts;  ///< samples per bin (whole numbers, stored as doubles)
  std::size_t total = 0;  ///< all samples, including under/over
  ///@{
  /// Samples below lo and at or above hi.
  std::size_t under = 0, over = 0;
  ///@}

  std::size_t bins() const { return counts.size(); }  ///< number of bins
  double width() const { return (hi - lo) / static_cast<double>(counts.size()); }  ///< bin width (hi - lo)/bins
  /// Centre of bin i (no range check).
  double centre(std::size_t i) const { return lo + (static_cast<double>(i) + 0.5) * width(); }
  /// Left edge of bin i (no range check).
  double left(std::size_t i) const { return lo + static_cast<double>(i) * width(); }
  /// Density estimate count/(total*width), normalised over ALL samples so that it compares
  /// directly with a pdf (sum_i density(i) * width() = 1 - (under + over)/total).
  /// Throws std::out_of_range for i >= bins(), std::invalid_argument if total == 0.
  double density(std::size_t i) const;
  /// Poisson standard error of density(i): sqrt(count)/(total*width) (same throws).
  double density_se(std::size_t i) const;
};
/// Bins [lo + i w, lo + (i+1) w), w = (hi-lo)/bins; x < lo -> under, x >= hi -> over (+-inf
/// allowed). Throws for NaN samples, bins == 0, or non-finite / empty [lo, hi). An empty x
/// gives a valid histogram with total = 0 (whose density() throws).
Histogram make_histogram(std::span<const double> x, double lo, double hi, std::size_t bins);

/// The outcome of chi2_test.
struct Chi2Result {
  double chi2 = 0;  ///< Pearson's statistic sum (O - E)^2 / E over the merged cells
  int dof = 0;      ///< degrees of freedom, cells - 1
  double p = 1;     ///< P(chi2_dof >= chi2); NaN when fewer than 2 cells remain
};
/// Pearson chi-square of a histogram against a cdf; adjacent bins are merged until each
/// expected count is >= min_expected (5 by the usual rule), and under/over flow bins are
/// included as two more cells. dof = cells - 1 (no fitted parameters).
/// Cells are, in order, [under, bin 0, ..., bin B-1, over] with expected counts
/// total * (F(edge_right) - F(edge_left)) (F(-inf) = 0, F(+inf) = 1). Merging is greedy from
/// the left: cells are accumulated until the accumulated expectation reaches min_expected;
/// a remainder at the right end that does not reach it is merged into the last cell. If fewer
/// than 2 cells remain (too few samples), no test is possible: chi2 = 0, dof = 0, p = NaN.
/// p = P(chi2_dof >= chi2) (boost::math::chi_squared_distribution).
/// Throws for min_expected <= 0, total == 0, counts inconsistent with total, or a cdf that
/// returns values outside [0,1] or decreases.
Chi2Result chi2_test(const Histogram& h, const Cdf& cdf, double min_expected = 5.0);

/// Sample quantile (linear interpolation, Hyndman-Fan type 7; R's default) of sorted data:
/// h = (n-1) prob, x[floor h] + (h - floor h)(x[floor h + 1] - x[floor h]) (0-based).
/// Throws for empty or unsorted data or prob outside [0,1].
double quantile_sorted(std::span<const double> sorted, double prob);
/// The same type-7 quantiles of unsorted data, by selection (nth_element) instead of a sort:
/// O(n) per distinct rank. Reorders `x`. Same throws as quantile_sorted (for empty x, NaN x, prob).
std::vector<double> quantiles_unsorted(std::vector<double>& x, std::span<const double> probs);

/// Mean, standard deviation and quantiles of a sample, each with its standard error.
struct Summary {
  std::size_t n = 0;                  ///< sample size
  ///@{
  /// Mean and standard deviation (n - 1 denominator), with standard errors.
  Estimate mean, std;
  ///@}
  std::vector<double> probs;          ///< quantile levels
  std::vector<Estimate> quantiles;    ///< same length as probs
  std::size_t batches = 0;            ///< number of batches used for the se (n for iid)
};

/// iid samples: se(mean) = s/sqrt(n); se(std) = s*sqrt((kurtosis-1)/(4n)) (delta method with the
/// sample kurtosis m4/m2^2 -- the plain kurtosis, 3 for a normal, i.e. excess kurtosis + 3 --
/// valid for non-normal data; for normal data it is s/sqrt(2n)); quantile se from the
/// distribution-free order-statistic interval: half the distance between ranks
/// n*p -/+ sqrt(n p (1-p)), evaluated as type-7 quantiles at p -/+ sqrt(p (1-p)/n) clamped to
/// [0,1]. s uses the n-1 denominator. Quantile values are type 7 (quantile_sorted).
/// For prob = 0 or 1 (sample min/max) that interval is degenerate: se = NaN (not estimable).
/// batches = n. Throws for n < 2, non-finite x, or prob outside [0,1]. All se are large-n
/// approximations (within a few % of the Monte Carlo truth at n = 400; e.g. for n = 2 the
/// sample kurtosis is always 1 and se(std) = 0).
Summary summarize_iid(std::span<const double> x, std::span<const double> probs);

/// Correlated samples in `batches` equal consecutive batches (e.g. K spheres x M rotations):
/// the value of each statistic is computed on the pooled data; its se is the standard deviation
/// of the per-batch statistic divided by sqrt(batches). se = NaN when batches < 2.
/// Batch b is x[b*m, (b+1)*m), m = n/batches. The se is that of the mean of the batch
/// statistics, which is the se of the pooled statistic for the mean, and approximately so for
/// the std and quantiles when batches are large (small batches bias per-batch quantiles/stds,
/// not their spread much). Throws std::invalid_argument (naming n and batches) when batches is
/// 0 or does not divide n, or when m < 2; also for non-finite x or prob outside [0,1].
Summary summarize_batches(std::span<const double> x, std::size_t batches, std::span<const double> probs);

}  // namespace asperity
