// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Streaming, mergeable statistics of one quantity (issue 14): memory independent of the number of
// samples, merged with the same bits for any thread count, rank count or schedule.
//
// A sample x is mapped to u = F_ref(x), equiprobable under a reference law with a closed-form
// cdf and quantile (Eq. 14's Rayleigh for r_xy, Eq. 18's normal for r_x), and counted in
//  - a fine histogram of 2^fine_log2 bins of u (exact integer counts: any merge order, same bits);
//  - coarse per-block histograms (blocks x 2^coarse_log2 bins of u): blocks are groups of whole
//    spheres, independent of each other, so the decisive tests take their error from the spread
//    between blocks (the quenched disorder of explicit spheres), never from an iid assumption;
//  - running moments per block (Welford within a unit of work, Chan's merge between units), merged
//    in block order: the caller merges units of fixed drop-index ranges in index order.
// Tests on the binned data, each stating its resolution (bin width in u):
//  - binned KS (iid drops only): D over the fine edges with exact bin probabilities of the law;
//  - Pearson chi^2 on equiprobable (reference) cells with exact expected counts (iid drops only);
//  - the likelihood ratio of two candidate laws on the coarse cells, its standard error from the
//    spread between blocks (valid for explicit spheres);
//  - a block-bootstrap KS: to_block_bins feeds laws/block_ks.hpp.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "asperity/laws/block_ks.hpp"
#include "asperity/laws/statistics.hpp"

namespace asperity {

/// Mean and second central moment of a stream (Welford); merge is Chan et al.'s formula.
/// Deterministic: the same sequence of add/merge calls gives the same bits.
struct Moments {
  std::uint64_t n = 0;  ///< samples counted
  ///@{
  /// Running mean and sum of squared deviations from it, sum (x - mean)^2 (not divided by n).
  double mean = 0, m2 = 0;
  ///@}
  /// Counts one sample (Welford's update; x must be finite, not checked).
  void add(double x) {
    ++n;
    const double d = x - mean;
    mean += d / double(n);
    m2 += d * (x - mean);
  }
  /// Adds o's samples as if they had been added after this one's (Chan et al.); the result depends
  /// on the order of merges, so callers merge in a fixed order.
  void merge(const Moments& o);
  /// Sample variance m2 / (n - 1); 0 for n < 2.
  double variance() const { return n > 1 ? m2 / double(n - 1) : 0.0; }
  /// Bit-for-bit equality (the determinism tests).
  friend bool operator==(const Moments&, const Moments&) = default;
};

/// Sums of d = x - c and d^2 about a fixed shift c: no division per sample (Welford's add has
/// one, in a dependency chain), for the per-drop loop. moments(c) turns them into a Moments
/// (mean c + S1/n, m2 = S2 - S1^2/n), merged with Chan's formula as before. Accurate when c is
/// within a few standard deviations of the mean: the cancellation in S2 - S1^2/n costs
/// log10(1 + (mean - c)^2 / var) digits (the streaming run uses the reference law's mean).
/// Deterministic like Moments.
struct ShiftedSums {
  std::uint64_t n = 0;  ///< samples counted
  ///@{
  /// S1 = sum (x - c) and S2 = sum (x - c)^2 about the shift c.
  double s1 = 0, s2 = 0;
  ///@}
  /// Counts x about the shift c (the same c for every sample of one ShiftedSums).
  void add(double x, double c) {
    const double d = x - c;
    ++n;
    s1 += d;
    s2 += d * d;
  }
  /// The Moments of the samples added (c: the shift they were added with).
  Moments moments(double c) const;
};

/// The reference law whose cdf makes the bins equiprobable: closed-form cdf and quantile.
struct Reference {
  ///@{
  /// The family: Rayleigh (r_xy, Eq. 14) or centred normal (r_x, Eq. 18).
  enum class Kind { rayleigh, normal } kind = Kind::rayleigh;
  ///@}
  double sigma = 1;  ///< Rayleigh scale (cdf 1 - exp(-x^2 / 2 sigma^2)) or normal standard deviation
  double cdf(double x) const;       ///< u = F_ref(x) in [0, 1] (0 below the Rayleigh's support)
  double quantile(double u) const;  ///< u in [0, 1]; quantile(0) and quantile(1) are the support's ends
  double mean() const;              ///< sigma sqrt(pi / 2) (Rayleigh) or 0 (normal)
  std::string name() const;         ///< e.g. "Rayleigh(sigma = 3.2e-06)"
  /// Field-by-field equality (BinnedStats::merge requires the same reference).
  friend bool operator==(const Reference&, const Reference&) = default;
};

/// The fine bin of a sample x, decided by the edges the binned tests use: bin j holds
/// x_j <= x < x_(j+1) with x_j = ref.quantile(j 2^-k) (x_0 = -inf, x_(2^k) = +inf), the same doubles
/// as binned_ks / binned_chi2 / to_block_bins evaluate their laws at. It agrees with
/// fine_bin(ref.cdf(x)) except for x within rounding of an edge (where the cdf's rounding decided,
/// the edge now does). Fast, and never dependent on an approximation being good: g(x), the
/// reference cdf (times 2^k) tabulated on a fine x grid and interpolated linearly, is a
/// non-decreasing function of x (up to one ulp at table nodes), and the construction measures
/// slack = max_j |g(x_j) - j| over all edges. If frac(g(x)) lies in (slack, 1 - slack), then
/// g(x_m) < g(x) < g(x_(m+1)) for m = floor(g(x)), hence x_m <= x < x_(m+1): the bin is m without
/// reading an edge. Otherwise (within slack of an edge: ~2 slack of the samples; slack ~ 1e-2 at
/// 2^16 bins) exact comparisons with the edges, walking from the guess, decide. Immutable: share it.
class FineBinner {
 public:
  /// Throws std::logic_error if the computed edges are not non-decreasing.
  FineBinner(const Reference& ref, unsigned fine_log2);
  /// The fine bin of x in [0, 2^fine_log2): the same as exact comparisons with the edges (NaN in
  /// bin 0). Thread-safe, no allocation.
  std::size_t operator()(double x) const noexcept {
    const double g = guess(x);
    std::size_t k = g > 0 ? (g < double(last_) ? static_cast<std::size_t>(g) : last_) : 0;
    const double f = g - double(k);
    if (f > slack_ && f < 1.0 - slack_) return k;  // g in (k, k + 1), clear of both edges' g
    const double* e = edge_.data();
    while (k < last_ && x >= e[k + 1]) ++k;
    while (k > 0 && x < e[k]) --k;
    return k;
  }
  /// The largest |g(x_j) - j| over the edges, plus a rounding allowance (tests, reports).
  double slack() const noexcept { return slack_; }
  /// Bytes of the edge and interpolation tables.
  std::size_t memory_bytes() const noexcept { return (edge_.capacity() + table_.capacity()) * sizeof(double); }

 private:
  double guess(double x) const noexcept {
    double t = (x - lo_) * inv_h_;
    t = t > 0 ? t : 0;  // NaN too
    t = t < tmax_ ? t : tmax_;
    const auto i = static_cast<std::size_t>(t);
    return table_[i] + (t - double(i)) * (table_[i + 1] - table_[i]);
  }
  std::vector<double> edge_;   // x_0 .. x_(2^k)
  std::vector<double> table_;  // 2^k ref.cdf at lo + i h, i = 0 .. kTable
  double lo_ = 0, inv_h_ = 1, tmax_ = 0;
  double slack_ = 1;           // >= 0.5: the shortcut never applies
  std::size_t last_ = 0;       // 2^k - 1
};

/// The streaming statistics of one quantity (see the file's comment): fine histogram, per-block
/// coarse histograms and per-block moments. Make one with make_binned; merge partial ones in
/// index order.
struct BinnedStats {
  Reference ref;                       ///< the law whose cdf maps samples to u
  ///@{
  /// log2 of the number of fine bins (<= 24) and of coarse bins per block (4 .. 16, <= fine_log2).
  unsigned fine_log2 = 16, coarse_log2 = 10;
  ///@}
  std::size_t blocks = 1;              ///< independent blocks (groups of whole spheres), >= 1
  std::vector<std::uint64_t> fine;     ///< 2^fine_log2 counts of u
  std::vector<std::uint64_t> coarse;   ///< blocks x 2^coarse_log2 counts of u
  std::vector<Moments> block_moments;  ///< per block

  std::size_t fine_bins() const { return std::size_t{1} << fine_log2; }      ///< 2^fine_log2
  std::size_t coarse_bins() const { return std::size_t{1} << coarse_log2; }  ///< 2^coarse_log2 per block
  std::uint64_t n() const;  ///< samples counted (the sum of the fine counts)
  /// Fine bin of u: floor(u 2^k), u = 1 in the last bin.
  std::size_t fine_bin(double u) const;
  /// All blocks merged in block order.
  Moments moments() const;
  /// Adds o's counts and merges o's block moments into this one's, block by block (the caller
  /// merges in index order). Throws std::invalid_argument if the layouts differ.
  void merge(const BinnedStats& o);
  /// Bit-for-bit equality (the thread- and rank-count independence tests).
  friend bool operator==(const BinnedStats&, const BinnedStats&) = default;
};

/// Empty statistics. Throws std::invalid_argument for fine_log2 outside [coarse_log2, 24],
/// coarse_log2 outside [4, 16], or blocks = 0.
BinnedStats make_binned(const Reference& ref, std::size_t blocks, unsigned fine_log2 = 16, unsigned coarse_log2 = 10);

/// Counts x (already mapped: u = ref.cdf(x)) in block `block`. Not thread-safe; the driver keeps
/// per-thread fine histograms or adds atomically (add_atomic).
void add_sample(BinnedStats& s, std::size_t block, double u);

/// u of x under the reference; throws std::invalid_argument for a non-finite x.
double reference_u(const Reference& ref, double x);

/// The outcome of one binned test.
struct BinnedTest {
  std::string statistic;     ///< "binned-KS", "chi2", "LR-block", "KS-block-bootstrap"
  double value = 0;          ///< D, chi^2 or the z of the LR
  double p = 1;              ///< p-value (NaN when the test could not be made; the note says why)
  std::uint64_t n = 0;       ///< samples the test used
  double resolution = 0;     ///< bin width in u of the cells the test used
  std::string note;          ///< how p was computed, in words
};

/// Binned KS against `cdf` (in x) over the 2^fine_log2 - 1 interior fine edges, x_j =
/// ref.quantile(j 2^-k), with the law's exact probabilities F(x_j). p = Kolmogorov's (D on a grid is
/// at most the continuous D; calibration measured 0.058 +- 0.006 at alpha 0.05, 2^12 bins, n = 2e4,
/// tests/laws/test_binned.cpp). iid samples only.
BinnedTest binned_ks(const BinnedStats& s, const Cdf& cdf);

/// Pearson chi^2 on `cells` cells of equal reference probability (fine bins merged), expected
/// counts n (F(x_hi) - F(x_lo)) from the law; cells with expected < 5 are merged into neighbours.
/// p from chi^2 with (cells - 1) dof. iid samples only.
BinnedTest binned_chi2(const BinnedStats& s, const Cdf& cdf, std::size_t cells = 1024);

/// Likelihood ratio of law 1 against law 0 on the coarse cells: L = sum_c n_c log(p1_c / p0_c) / n,
/// with se from the spread of the per-block L between blocks (ratio estimator, G/(G-1) corrected).
/// E[L] is -KL(p0 || p1) if law 0 is the law of the data and +KL(p1 || p0) if law 1 is, so
///   law 0 is rejected when z0 = (L + KL01) / se > z_(1-alpha) (one-sided: the data lean to law 1),
///   law 1 is rejected when z1 = (L - KL10) / se < -z_(1-alpha),
/// p from Student's t with G - 1 dof. Cells where either law has probability 0 are pooled with a
/// neighbour. Needs blocks >= 2.
struct LrTest {
  ///@{
  /// L, its standard error from the spread between blocks, and KL(p0 || p1), KL(p1 || p0) on the
  /// cells used (nats per sample).
  double L = 0, se = 0, kl01 = 0, kl10 = 0;
  ///@}
  ///@{
  /// The test of law 0 (z0) and of law 1 (z1): value = z, p one-sided.
  BinnedTest law0, law1;
  ///@}
  std::size_t blocks = 0;  ///< G: blocks with samples, the se's degrees of freedom + 1
};
/// The likelihood-ratio test above. Throws std::invalid_argument for fewer than 2 blocks.
LrTest binned_lr(const BinnedStats& s, const Cdf& law0, const Cdf& law1);

/// The coarse per-block counts as laws/block_ks.hpp bins: edges x_j = ref.quantile(j 2^-c),
/// j = 1 .. 2^c - 1, so block_ks_tests gives a sphere-block-bootstrap KS (resolution 2^-c in u).
/// Throws std::overflow_error if a count exceeds 2^32 - 1 (BlockBins holds 32-bit counts).
BlockBins to_block_bins(const BinnedStats& s);

/// Pooled cdf at the coarse edges x_j with its standard error from the spread between blocks.
struct CdfBand {
  ///@{
  /// The coarse edges x_j = ref.quantile(j 2^-c), j = 1 .. 2^c - 1; the pooled fraction of samples
  /// below each; its standard error from the spread between blocks (NaN with fewer than 2 blocks
  /// holding samples). Equal lengths.
  std::vector<double> x, cdf, se;
  ///@}
};
/// The pooled cdf of s at its coarse edges, with standard errors (for the cdf-difference figures).
CdfBand pooled_cdf(const BinnedStats& s);

/// Drops a likelihood-ratio test needs to reject law 0 at level alpha with power 1 - beta when the
/// data follow law 1 (iid, normal approximation): ((z_a + z_b) sd / (KL01 + KL10))^2 with the sd of
/// a log ratio under law 1, on cells of `cells_log2` equiprobable reference cells.
double lr_sample_size(const Reference& ref, const Cdf& law0, const Cdf& law1, double alpha, double beta,
                      unsigned cells_log2 = 10);

}  // namespace asperity
