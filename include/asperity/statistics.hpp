#pragma once
// Sample statistics with honest uncertainties: histograms with Poisson error bars, one- and
// two-sample Kolmogorov-Smirnov tests with p-values, binned chi-square, and means, standard
// deviations and quantiles with standard errors (iid, or from batch means when samples are
// correlated within batches, e.g. many rotations of one sphere).
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

namespace asperity {

using Cdf = std::function<double(double)>;

/// A value with its standard error (se is NaN when it cannot be estimated, e.g. one batch).
struct Estimate {
  double value = 0;
  double se = 0;
};

struct KsResult {
  double D = 0;        ///< sup |F_n - F|
  double p = 1;        ///< p-value under H0 (iid samples from F; F continuous)
  std::size_t n = 0;   ///< sample size (effective n*m/(n+m) for two samples)
};

/// Survival function of the Kolmogorov statistic: P(D_n >= d) for a sample of size n.
/// Exact (Marsaglia, Tsang & Wang 2003) for n*d^2 small enough and n <= 10^5; otherwise the
/// asymptotic Kolmogorov series with Stephens' finite-n correction.
double kolmogorov_pvalue(double d, std::size_t n);

/// One-sample KS test. `sorted` must be sorted ascending; cdf must be continuous.
KsResult ks_one_sample(std::span<const double> sorted, const Cdf& cdf);
/// Two-sample KS test; both inputs sorted ascending. Asymptotic p-value with n_eff = nm/(n+m).
KsResult ks_two_sample(std::span<const double> a_sorted, std::span<const double> b_sorted);

/// Fixed-width histogram on [lo, hi). Samples outside are counted in `under`/`over`.
struct Histogram {
  double lo = 0, hi = 1;
  std::vector<double> counts;
  std::size_t total = 0;  ///< all samples, including under/over
  std::size_t under = 0, over = 0;

  std::size_t bins() const { return counts.size(); }
  double width() const { return (hi - lo) / static_cast<double>(counts.size()); }
  double centre(std::size_t i) const { return lo + (static_cast<double>(i) + 0.5) * width(); }
  double left(std::size_t i) const { return lo + static_cast<double>(i) * width(); }
  /// Density estimate count/(total*width), normalised over ALL samples so that it compares
  /// directly with a pdf.
  double density(std::size_t i) const;
  /// Poisson standard error of density(i): sqrt(count)/(total*width).
  double density_se(std::size_t i) const;
};
Histogram make_histogram(std::span<const double> x, double lo, double hi, std::size_t bins);

struct Chi2Result {
  double chi2 = 0;
  int dof = 0;
  double p = 1;
};
/// Pearson chi-square of a histogram against a cdf; adjacent bins are merged until each
/// expected count is >= min_expected (5 by the usual rule), and under/over flow bins are
/// included as two more cells. dof = cells - 1 (no fitted parameters).
Chi2Result chi2_test(const Histogram& h, const Cdf& cdf, double min_expected = 5.0);

/// Sample quantile (linear interpolation, Hyndman-Fan type 7) of sorted data.
double quantile_sorted(std::span<const double> sorted, double prob);

struct Summary {
  std::size_t n = 0;
  Estimate mean, std;
  std::vector<double> probs;          ///< quantile levels
  std::vector<Estimate> quantiles;    ///< same length as probs
  std::size_t batches = 0;            ///< number of batches used for the se (n for iid)
};

/// iid samples: se(mean) = s/sqrt(n); se(std) = s*sqrt((kurtosis-1)/(4n)) (delta method with the
/// sample excess kurtosis, valid for non-normal data); quantile se from the distribution-free
/// order-statistic interval: half the distance between ranks n*p -/+ sqrt(n p (1-p)).
Summary summarize_iid(std::span<const double> x, std::span<const double> probs);

/// Correlated samples in `batches` equal consecutive batches (e.g. K spheres x M rotations):
/// the value of each statistic is computed on the pooled data; its se is the standard deviation
/// of the per-batch statistic divided by sqrt(batches). se = NaN when batches < 2.
Summary summarize_batches(std::span<const double> x, std::size_t batches, std::span<const double> probs);

}  // namespace asperity
