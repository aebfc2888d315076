// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/laws/statistics.hpp"

#include <boost/math/distributions/chi_squared.hpp>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <string>
#include <vector>

namespace asperity {

namespace {

constexpr double nan_v = std::numeric_limits<double>::quiet_NaN();

// Shortest round-trip text of a number (so messages name the exact offending value).
template <class T>
std::string str(T v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

[[noreturn]] void fail(const std::string& msg) { throw std::invalid_argument(msg); }

// ---------------------------------------------------------------------------------------------
// Kolmogorov distribution
// ---------------------------------------------------------------------------------------------

// Tuning of kolmogorov_pvalue (see the header for the resulting regions).
constexpr std::size_t exact_n_max = 100000;  // above: asymptotic only
// Budget for the exact algorithm, in multiply-adds: m^3 per matrix product (m = 2k-1), one
// squaring per bit of n plus one product per set bit. 2.5e7 took 3-4 ms on one core of the
// development machine (x86-64, SSE2 only, no FMA), i.e. comfortably under 10 ms. This gives
// kmax = 92 at n = 10, 61 at n = 1000, 53 at n = 10^5.
constexpr double exact_budget = 2.5e7;
// n d^2 from which the upper tail uses 2 * P(D+ >= d) (exact one-sided Smirnov) instead of
// 1 - P(D < d): above it 1 - P(D < d) loses digits to cancellation (relative error ~ n eps / p)
// while the neglected P(D+ >= d and D- >= d) is ~exp(-6 n d^2) relative (exactly 0 for
// d >= 1/2). Against exact rational references (Steck's determinant) at n = 200..800 both
// errors are ~1e-11 relative at n d^2 = 4.2, where they cross.
constexpr double tail_nd2 = 4.2;
// Relative width of the band below the exact/asymptotic switch d_s = kmax/n in which the two
// are blended linearly, so p stays continuous and monotone across the switch. The blend is
// monotone while |p_asym - p_exact| < blend_width * d |dp/dd|; the mismatch (Stephens' error,
// <= 1.2e-2 relative at the switch for n >= 829) is several times below that bound for every
// n (checked by a fine scan through the band for ~100 n from 829 to 10^5).
constexpr double blend_width = 0.02;

double matrix_products(std::size_t n) {
  // Squarings: bit_width(n)-1; extra products: popcount(n)-1.
  const auto bits = static_cast<double>(std::bit_width(n));
  const auto ones = static_cast<double>(std::popcount(n));
  return std::max(1.0, bits - 1.0 + ones - 1.0);
}

// C = A * B for m x m row-major matrices (i-k-j order: the inner loop vectorises).
void mat_mul(const std::vector<double>& A, const std::vector<double>& B, std::vector<double>& C,
             std::size_t m) {
  std::fill(C.begin(), C.end(), 0.0);
  for (std::size_t i = 0; i < m; ++i) {
    double* c = &C[i * m];
    for (std::size_t l = 0; l < m; ++l) {
      const double a = A[i * m + l];
      if (a == 0.0) continue;
      const double* b = &B[l * m];
      for (std::size_t j = 0; j < m; ++j) c[j] += a * b[j];
    }
  }
}

// Marsaglia, Tsang & Wang (2003), "Evaluating Kolmogorov's distribution", J. Stat. Softw.
// 8(18): P(D_n < d) = n!/n^n * (H^n)_{kk}, with the decimal exponent carried separately
// (rescaling by 1e-140 whenever the centre element exceeds 1e140). The paper's quick right-tail
// shortcut is deliberately omitted (it is only 7-digit accurate).
double mtw_cdf(double d, std::size_t n) {
  const double nd = static_cast<double>(n) * d;
  const auto k = static_cast<std::size_t>(nd) + 1;
  const std::size_t m = 2 * k - 1;
  const double h = static_cast<double>(k) - nd;  // in (0, 1]

  std::vector<double> H(m * m);
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = 0; j < m; ++j) H[i * m + j] = (i + 1 >= j) ? 1.0 : 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    H[i * m] -= std::pow(h, static_cast<double>(i + 1));
    H[(m - 1) * m + i] -= std::pow(h, static_cast<double>(m - i));
  }
  H[(m - 1) * m] += (2 * h - 1 > 0 ? std::pow(2 * h - 1, static_cast<double>(m)) : 0.0);
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = 0; j < m && j <= i + 1; ++j) {
      // divide by (i-j+1)!
      double f = 1.0;
      for (std::size_t g = 2; g <= i + 1 - j; ++g) f *= static_cast<double>(g);
      H[i * m + j] /= f;
    }

  // V = H^n by binary powering from the most significant bit (equivalent to the paper's
  // recursive mPower, including its rescaling after every step).
  std::vector<double> V = H, T(m * m);
  long eV = 0;  // V_true = V * 10^eV
  const int top = std::bit_width(n) - 1;
  for (int bit = top - 1; bit >= 0; --bit) {
    mat_mul(V, V, T, m);
    V.swap(T);
    eV *= 2;
    if ((n >> bit) & 1u) {
      mat_mul(H, V, T, m);
      V.swap(T);
    }
    if (V[(m / 2) * m + m / 2] > 1e140) {
      for (double& v : V) v *= 1e-140;
      eV += 140;
    }
  }
  double s = V[(k - 1) * m + (k - 1)];
  const double dn = static_cast<double>(n);
  for (std::size_t i = 1; i <= n; ++i) {
    s = s * static_cast<double>(i) / dn;
    if (s < 1e-140) {
      s *= 1e140;
      eV -= 140;
    }
  }
  // s * 10^eV; eV may be far outside the double range only when the result is 0 or 1 anyway.
  if (eV < -400) return 0.0;
  if (eV > 400) return 1.0;
  return std::min(1.0, std::max(0.0, s * std::pow(10.0, static_cast<double>(eV))));
}

// Smallest k for which the exact algorithm exceeds the budget, minus one.
std::size_t kmax_for(std::size_t n) {
  if (n > exact_n_max) return 0;
  const double prods = matrix_products(n);
  const double m = std::cbrt(exact_budget / prods);  // m = 2k - 1
  return static_cast<std::size_t>((m + 1.0) / 2.0);
}

// Q_KS(lambda) = 2 sum_{j>=1} (-1)^{j-1} exp(-2 j^2 lambda^2); for lambda < 1 through the
// theta-function form 1 - sqrt(2 pi)/lambda sum_{j>=1} exp(-(2j-1)^2 pi^2 / (8 lambda^2)),
// which converges fast where the alternating series does not.
double kolmogorov_q(double lambda) {
  if (!(lambda > 0)) return 1.0;
  if (lambda < 1.0) {
    const double c = std::numbers::pi * std::numbers::pi / (8.0 * lambda * lambda);
    double s = 0;
    for (int j = 1; j < 100; ++j) {
      const double o = 2.0 * j - 1.0;
      const double t = std::exp(-o * o * c);
      s += t;
      if (t <= 1e-17 * s) break;
    }
    const double K = std::sqrt(2.0 * std::numbers::pi) / lambda * s;
    return std::clamp(1.0 - K, 0.0, 1.0);
  }
  double s = 0;
  for (int j = 1; j < 100; ++j) {
    const double t = std::exp(-2.0 * j * j * lambda * lambda);
    s += (j % 2 == 1) ? t : -t;
    if (t <= 1e-17 * s) break;
  }
  return std::clamp(2.0 * s, 0.0, 1.0);
}

void check_d_n(double d, double n, const char* who) {
  if (std::isnan(d)) fail(std::string(who) + ": d is NaN");
  if (!(n > 0) || !std::isfinite(n)) fail(std::string(who) + ": n must be > 0, got " + str(n));
}

}  // namespace

double kolmogorov_cdf_mtw(double d, std::size_t n) {
  check_d_n(d, static_cast<double>(n), "kolmogorov_cdf_mtw");
  const double dn = static_cast<double>(n);
  if (d <= 0.5 / dn) return 0.0;
  if (d >= 1.0) return 1.0;
  return mtw_cdf(d, n);
}

double smirnov_pvalue(double d, std::size_t n) {
  check_d_n(d, static_cast<double>(n), "smirnov_pvalue");
  if (d <= 0) return 1.0;
  if (d >= 1) return 0.0;
  // Birnbaum & Tingey (1951): P(D+_n >= d) = d sum_{j=0}^{floor(n(1-d))} C(n,j)
  //   (1 - d - j/n)^(n-j) (d + j/n)^(j-1); all terms positive, summed in log space.
  const double dn = static_cast<double>(n);
  const auto J = static_cast<std::size_t>(std::floor(dn * (1.0 - d)));
  double logc = 0;  // log C(n, j)
  double sum = 0;
  for (std::size_t j = 0; j <= J && j < n; ++j) {
    const double dj = static_cast<double>(j);
    if (j > 0) logc += std::log((dn - dj + 1.0) / dj);
    const double a = (dn - dj) / dn - d;
    if (!(a > 0)) break;
    const double b = d + dj / dn;
    const double lt = logc + (dn - dj) * std::log(a) + (dj - 1.0) * std::log(b);
    sum += std::exp(lt);
  }
  return std::clamp(d * sum, 0.0, 1.0);
}

double kolmogorov_pvalue_asymptotic(double d, double n) {
  check_d_n(d, n, "kolmogorov_pvalue_asymptotic");
  if (d <= 0) return 1.0;
  const double sn = std::sqrt(n);
  return kolmogorov_q((sn + 0.12 + 0.11 / sn) * d);
}

std::size_t kolmogorov_exact_kmax(std::size_t n) { return kmax_for(n); }

double kolmogorov_pvalue(double d, std::size_t n) {
  check_d_n(d, static_cast<double>(n), "kolmogorov_pvalue");
  const double dn = static_cast<double>(n);
  if (d <= 0.5 / dn) return 1.0;  // D_n >= 1/(2n) always
  if (d >= 1.0) return 0.0;       // D_n < 1 almost surely
  const std::size_t kmax = kmax_for(n);
  if (kmax == 0) return kolmogorov_pvalue_asymptotic(d, dn);
  const double d_tail = std::min(0.5, std::sqrt(tail_nd2 / dn));
  const double d_s = static_cast<double>(kmax) / dn;  // exact for d < d_s (k <= kmax)
  if (d_tail < d_s) {
    // The exact algorithm reaches the tail: exact everywhere.
    if (d >= d_tail) return std::min(1.0, 2.0 * smirnov_pvalue(d, n));
    return 1.0 - mtw_cdf(d, n);
  }
  if (d >= d_s) return kolmogorov_pvalue_asymptotic(d, dn);
  const double d_b = d_s * (1.0 - blend_width);
  const double pe = 1.0 - mtw_cdf(d, n);
  if (d < d_b) return pe;
  const double w = (d - d_b) / (d_s - d_b);
  const double pa = kolmogorov_pvalue_asymptotic(d, dn);
  return std::clamp((1.0 - w) * pe + w * pa, 0.0, 1.0);
}

// -------------------------------------------------------------------------------------------
// Kolmogorov-Smirnov tests
// -------------------------------------------------------------------------------------------

namespace {

void check_sorted(std::span<const double> x, const char* who, const char* name) {
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (std::isnan(x[i])) fail(std::string(who) + ": " + name + "[" + str(i) + "] is NaN");
    if (i > 0 && x[i] < x[i - 1])
      fail(std::string(who) + ": " + name + " is not sorted ascending: " + name + "[" + str(i - 1) +
           "] = " + str(x[i - 1]) + " > " + name + "[" + str(i) + "] = " + str(x[i]));
  }
}

double eval_cdf(const Cdf& cdf, double x, const char* who) {
  const double F = cdf(x);
  if (!(F >= 0.0 && F <= 1.0))
    fail(std::string(who) + ": cdf(" + str(x) + ") = " + str(F) + " is not in [0, 1]");
  return F;
}

}  // namespace

KsResult ks_one_sample(std::span<const double> sorted, const Cdf& cdf) {
  if (sorted.empty()) fail("ks_one_sample: empty sample (n = 0)");
  if (!cdf) fail("ks_one_sample: empty cdf");
  check_sorted(sorted, "ks_one_sample", "sorted");
  const std::size_t n = sorted.size();
  const double dn = static_cast<double>(n);
  double D = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double F = eval_cdf(cdf, sorted[i], "ks_one_sample");
    const double up = static_cast<double>(i + 1) / dn - F;  // i/n - F(x_i), 1-based i
    const double down = F - static_cast<double>(i) / dn;    // F(x_i) - (i-1)/n
    D = std::max(D, std::max(up, down));
  }
  return {D, kolmogorov_pvalue(D, n), n};
}

namespace {

// KS distance at the i-th smallest point (0-based) where the cdf is F.
double ks_distance_at(std::size_t i, double F, double dn) {
  return std::max(static_cast<double>(i + 1) / dn - F, F - static_cast<double>(i) / dn);
}

}  // namespace

KsResult ks_one_sample_monotone(std::span<const double> sorted, const Cdf& cdf) {
  if (sorted.empty()) fail("ks_one_sample_monotone: empty sample (n = 0)");
  if (!cdf) fail("ks_one_sample_monotone: empty cdf");
  check_sorted(sorted, "ks_one_sample_monotone", "sorted");
  constexpr std::size_t stride = 32;
  // Rounding may make a computed F decrease by a few ulp where the true one is flat; the margin
  // keeps every skipped point's distance below the maximum, so the maximum is the same number.
  constexpr double margin = 1e-12;
  const std::size_t n = sorted.size();
  const double dn = static_cast<double>(n);
  std::vector<std::size_t> at;
  for (std::size_t i = 0; i < n; i += stride) at.push_back(i);
  if (at.back() != n - 1) at.push_back(n - 1);
  std::vector<double> F(at.size());
  double D = 0;
  for (std::size_t k = 0; k < at.size(); ++k) {
    F[k] = eval_cdf(cdf, sorted[at[k]], "ks_one_sample_monotone");
    D = std::max(D, ks_distance_at(at[k], F[k], dn));
  }
  // Interior points of run k: up <= hi/n - F(lo), down <= F(hi) - (lo + 1)/n. Runs with the
  // largest bound first, so that the maximum grows early and prunes the rest.
  std::vector<std::pair<double, std::size_t>> runs;
  for (std::size_t k = 0; k + 1 < at.size(); ++k) {
    if (at[k + 1] - at[k] < 2) continue;
    const double bound = std::max(static_cast<double>(at[k + 1]) / dn - F[k], F[k + 1] - static_cast<double>(at[k] + 1) / dn);
    runs.push_back({bound, k});
  }
  std::sort(runs.begin(), runs.end(), [](const auto& x, const auto& y) { return x.first > y.first || (x.first == y.first && x.second < y.second); });
  for (const auto& [bound, k] : runs) {
    if (bound + margin < D) break;  // sorted: no later run can reach D either
    for (std::size_t i = at[k] + 1; i < at[k + 1]; ++i)
      D = std::max(D, ks_distance_at(i, eval_cdf(cdf, sorted[i], "ks_one_sample_monotone"), dn));
  }
  return {D, kolmogorov_pvalue(D, n), n};
}

KsResult ks_two_sample(std::span<const double> a, std::span<const double> b) {
  if (a.empty() || b.empty())
    fail("ks_two_sample: empty sample (n = " + str(a.size()) + ", m = " + str(b.size()) + ")");
  check_sorted(a, "ks_two_sample", "a_sorted");
  check_sorted(b, "ks_two_sample", "b_sorted");
  const std::size_t n = a.size(), m = b.size();
  const double dn = static_cast<double>(n), dm = static_cast<double>(m);
  std::size_t i = 0, j = 0;
  double D = 0;
  // Walk the distinct values of the union; at each, step BOTH ECDFs past every copy of it
  // before comparing (otherwise ties between the samples create spurious differences).
  while (i < n && j < m) {
    const double v = std::min(a[i], b[j]);
    while (i < n && a[i] == v) ++i;
    while (j < m && b[j] == v) ++j;
    D = std::max(D, std::fabs(static_cast<double>(i) / dn - static_cast<double>(j) / dm));
  }
  // Once one sample is exhausted its ECDF is 1 and the other's only increases to 1: the
  // difference can only shrink, so the maximum is already found.
  const double n_eff = dn * dm / (dn + dm);
  const double p = D > 0 ? kolmogorov_pvalue_asymptotic(D, n_eff) : 1.0;
  return {D, p, static_cast<std::size_t>(std::llround(n_eff))};
}

// -------------------------------------------------------------------------------------------
// Histogram and chi-square
// -------------------------------------------------------------------------------------------

double Histogram::density(std::size_t i) const {
  if (i >= counts.size())
    throw std::out_of_range("Histogram::density: bin " + str(i) + " >= bins " + str(counts.size()));
  if (total == 0) fail("Histogram::density: histogram has no samples (total = 0)");
  return counts[i] / (static_cast<double>(total) * width());
}

double Histogram::density_se(std::size_t i) const {
  if (i >= counts.size())
    throw std::out_of_range("Histogram::density_se: bin " + str(i) + " >= bins " +
                            str(counts.size()));
  if (total == 0) fail("Histogram::density_se: histogram has no samples (total = 0)");
  return std::sqrt(counts[i]) / (static_cast<double>(total) * width());
}

Histogram make_histogram(std::span<const double> x, double lo, double hi, std::size_t bins) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi))
    fail("make_histogram: need finite lo < hi, got lo = " + str(lo) + ", hi = " + str(hi));
  if (bins == 0) fail("make_histogram: bins must be >= 1, got 0");
  if (!std::isfinite((hi - lo) / static_cast<double>(bins)) || !((hi - lo) > 0))
    fail("make_histogram: range hi - lo overflows: lo = " + str(lo) + ", hi = " + str(hi));
  Histogram h;
  h.lo = lo;
  h.hi = hi;
  h.counts.assign(bins, 0.0);
  const double scale = static_cast<double>(bins) / (hi - lo);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double v = x[i];
    if (std::isnan(v)) fail("make_histogram: x[" + str(i) + "] is NaN");
    if (v < lo) {
      ++h.under;
    } else if (v >= hi) {
      ++h.over;
    } else {
      // Rounding can put v just below hi into index `bins`, or v just above a bin edge into
      // the bin below; clamp the former (the latter is an unavoidable 1-ulp ambiguity).
      auto k = static_cast<std::size_t>((v - lo) * scale);
      if (k >= bins) k = bins - 1;
      h.counts[k] += 1.0;
    }
  }
  h.total = x.size();
  return h;
}

namespace {

void check_chi2_input(const Histogram& h, const Cdf& cdf, double min_expected) {
  if (!cdf) fail("chi2_test: empty cdf");
  if (!(min_expected > 0) || !std::isfinite(min_expected))
    fail("chi2_test: min_expected must be finite and > 0, got " + str(min_expected));
  if (h.counts.empty()) fail("chi2_test: histogram has no bins");
  if (!std::isfinite(h.lo) || !std::isfinite(h.hi) || !(h.lo < h.hi))
    fail("chi2_test: histogram needs finite lo < hi, got lo = " + str(h.lo) + ", hi = " + str(h.hi));
  if (h.total == 0) fail("chi2_test: histogram has no samples (total = 0)");
  double sum = static_cast<double>(h.under) + static_cast<double>(h.over);
  for (std::size_t i = 0; i < h.counts.size(); ++i) {
    const double c = h.counts[i];
    if (!(c >= 0) || !std::isfinite(c))
      fail("chi2_test: counts[" + str(i) + "] = " + str(c) + " is not a finite count >= 0");
    sum += c;
  }
  const double N = static_cast<double>(h.total);
  if (std::fabs(sum - N) > 1e-9 * N + 0.5)
    fail("chi2_test: counts + under + over = " + str(sum) + " differs from total = " + str(N));
}

// Observed and expected counts per cell: under, bins..., over, expected from cdf differences.
std::pair<std::vector<double>, std::vector<double>> chi2_cells(const Histogram& h, const Cdf& cdf) {
  const char* who = "chi2_test";
  const double N = static_cast<double>(h.total);
  const std::size_t B = h.counts.size();
  std::vector<double> obs, expct;
  obs.reserve(B + 2);
  expct.reserve(B + 2);
  double Fprev = eval_cdf(cdf, h.lo, who);
  obs.push_back(static_cast<double>(h.under));
  expct.push_back(N * Fprev);
  for (std::size_t i = 0; i < B; ++i) {
    const double edge = (i + 1 == B) ? h.hi : h.left(i + 1);
    const double F = eval_cdf(cdf, edge, who);
    double dF = F - Fprev;
    if (dF < 0) {
      if (dF < -1e-12)
        fail("chi2_test: cdf decreases: cdf(" + str(h.left(i)) + ") = " + str(Fprev) + " > cdf(" +
             str(edge) + ") = " + str(F));
      dF = 0;  // rounding in a flat part of the cdf
    }
    obs.push_back(h.counts[i]);
    expct.push_back(N * dF);
    Fprev = std::max(F, Fprev);
  }
  obs.push_back(static_cast<double>(h.over));
  expct.push_back(N * (1.0 - Fprev));
  return {obs, expct};
}

// Merge left to right until each cell expects >= min_expected; a short remainder at the end joins
// the last complete cell.
std::pair<std::vector<double>, std::vector<double>> merge_cells(const std::vector<double>& obs, const std::vector<double>& expct,
                                                                double min_expected) {
  std::vector<double> mo, me;
  double co = 0, ce = 0;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    co += obs[i];
    ce += expct[i];
    if (ce >= min_expected) {
      mo.push_back(co);
      me.push_back(ce);
      co = ce = 0;
    }
  }
  if (co > 0 || ce > 0) {
    if (mo.empty()) {
      mo.push_back(co);
      me.push_back(ce);
    } else {
      mo.back() += co;
      me.back() += ce;
    }
  }
  return {mo, me};
}

}  // namespace

Chi2Result chi2_test(const Histogram& h, const Cdf& cdf, double min_expected) {
  check_chi2_input(h, cdf, min_expected);
  const auto [obs, expct] = chi2_cells(h, cdf);
  const auto [mo, me] = merge_cells(obs, expct, min_expected);
  Chi2Result r;
  r.dof = static_cast<int>(mo.size()) - 1;
  if (mo.size() < 2) {
    r.chi2 = 0;
    r.dof = 0;
    r.p = nan_v;
    return r;
  }
  double chi2 = 0;
  for (std::size_t c = 0; c < mo.size(); ++c) {
    const double diff = mo[c] - me[c];
    chi2 += diff * diff / me[c];  // me[c] >= min_expected > 0
  }
  r.chi2 = chi2;
  if (!std::isfinite(chi2)) {
    r.p = 0;
  } else {
    const boost::math::chi_squared_distribution<double> dist(static_cast<double>(r.dof));
    r.p = boost::math::cdf(boost::math::complement(dist, chi2));
  }
  return r;
}

// -------------------------------------------------------------------------------------------
// Quantiles and summaries
// -------------------------------------------------------------------------------------------

namespace {

void check_prob(double p, const char* who) {
  if (!(p >= 0.0 && p <= 1.0)) fail(std::string(who) + ": probability " + str(p) + " not in [0, 1]");
}

// Type 7 on data known to be sorted and non-empty.
double q7(std::span<const double> s, double p) {
  const std::size_t n = s.size();
  if (n == 1) return s[0];
  const double h = static_cast<double>(n - 1) * p;
  const auto j = static_cast<std::size_t>(std::floor(h));
  if (j >= n - 1) return s[n - 1];
  const double g = h - static_cast<double>(j);
  if (g == 0) return s[j];
  return s[j] + g * (s[j + 1] - s[j]);
}

// Type-7 quantiles of unsorted data without sorting it: the order statistics they need are found by
// successive nth_element on the shrinking right part (O(n) per distinct rank instead of O(n log n)).
// Equal to q7 on the sorted data, value for value.
std::vector<double> q7_select(std::vector<double>& v, std::span<const double> probs) {
  const std::size_t n = v.size();
  std::vector<std::size_t> ranks;
  for (double p : probs) {
    if (n == 1) break;
    const double h = static_cast<double>(n - 1) * p;
    const auto j = static_cast<std::size_t>(std::floor(h));
    ranks.push_back(std::min(j, n - 1));
    if (j + 1 < n) ranks.push_back(j + 1);
  }
  std::sort(ranks.begin(), ranks.end());
  ranks.erase(std::unique(ranks.begin(), ranks.end()), ranks.end());
  // Multi-select: place the middle rank, then recurse into each side with the ranks that lie there
  // (O(n log k) for k ranks, against O(n k) for one nth_element after another).
  auto select = [&](auto&& self, std::size_t lo, std::size_t hi, std::size_t r0, std::size_t r1) -> void {
    if (r0 >= r1 || lo >= hi) return;
    const std::size_t mid = (r0 + r1) / 2, r = ranks[mid];
    std::nth_element(v.begin() + static_cast<std::ptrdiff_t>(lo), v.begin() + static_cast<std::ptrdiff_t>(r),
                     v.begin() + static_cast<std::ptrdiff_t>(hi));
    self(self, lo, r, r0, mid);
    self(self, r + 1, hi, mid + 1, r1);
  };
  select(select, 0, n, 0, ranks.size());
  // v now holds every needed rank at its sorted position.
  std::vector<double> out;
  for (double p : probs) out.push_back(q7(v, p));
  return out;
}

void check_finite_data(std::span<const double> x, const char* who) {
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i])) fail(std::string(who) + ": x[" + str(i) + "] = " + str(x[i]) + " is not finite");
}

struct Moments {
  double mean, sd, kurt;  // sd with n-1; kurt = m4/m2^2 (plain kurtosis, 3 for a normal)
};

Moments moments(std::span<const double> x) {
  const double n = static_cast<double>(x.size());
  double mean = 0;
  for (double v : x) mean += v;
  mean /= n;
  double m2 = 0, m4 = 0, c = 0;
  for (double v : x) {
    const double d = v - mean;
    c += d;
    const double d2 = d * d;
    m2 += d2;
    m4 += d2 * d2;
  }
  mean += c / n;  // second-pass correction (Bjorck)
  m2 -= c * c / n;
  m2 = std::max(m2, 0.0);
  const double kurt = m2 > 0 ? (m4 / n) / ((m2 / n) * (m2 / n)) : 1.0;
  return {mean, std::sqrt(m2 / (n - 1.0)), kurt};
}

void check_summary_input(std::span<const double> x, std::span<const double> probs, const char* who) {
  if (x.size() < 2) fail(std::string(who) + ": need at least 2 samples, got n = " + str(x.size()));
  check_finite_data(x, who);
  for (double p : probs) check_prob(p, who);
}

}  // namespace

double quantile_sorted(std::span<const double> sorted, double prob) {
  if (sorted.empty()) fail("quantile_sorted: empty data (n = 0)");
  check_prob(prob, "quantile_sorted");
  check_sorted(sorted, "quantile_sorted", "sorted");
  return q7(sorted, prob);
}

std::vector<double> quantiles_unsorted(std::vector<double>& x, std::span<const double> probs) {
  if (x.empty()) fail("quantiles_unsorted: empty data (n = 0)");
  for (double p : probs) check_prob(p, "quantiles_unsorted");
  for (std::size_t i = 0; i < x.size(); ++i)
    if (std::isnan(x[i])) fail("quantiles_unsorted: x[" + str(i) + "] is NaN");
  return q7_select(x, probs);
}

Summary summarize_iid(std::span<const double> x, std::span<const double> probs) {
  check_summary_input(x, probs, "summarize_iid");
  const std::size_t n = x.size();
  const double dn = static_cast<double>(n);
  const Moments mo = moments(x);
  // Every probability the quantiles and their se need, then their order statistics by selection
  // (no sort of the whole sample).
  std::vector<double> need;
  for (double p : probs) {
    need.push_back(p);
    if (p > 0 && p < 1) {
      // Ranks n p -/+ sqrt(n p (1-p)), i.e. probabilities p -/+ sqrt(p (1-p) / n), clamped.
      const double half = std::sqrt(p * (1.0 - p) / dn);
      need.push_back(std::max(0.0, p - half));
      need.push_back(std::min(1.0, p + half));
    }
  }
  std::vector<double> s(x.begin(), x.end());
  const std::vector<double> v = q7_select(s, need);

  Summary r;
  r.n = n;
  r.batches = n;
  r.mean = {mo.mean, mo.sd / std::sqrt(dn)};
  r.std = {mo.sd, mo.sd * std::sqrt(std::max(mo.kurt - 1.0, 0.0) / (4.0 * dn))};
  r.probs.assign(probs.begin(), probs.end());
  std::size_t at = 0;
  for (double p : probs) {
    Estimate e{v[at++], nan_v};
    if (p > 0 && p < 1) {
      const double lo = v[at++], hi = v[at++];
      e.se = 0.5 * (hi - lo);
    }
    r.quantiles.push_back(e);
  }
  return r;
}

Summary summarize_batches(std::span<const double> x, std::size_t batches, std::span<const double> probs) {
  const char* who = "summarize_batches";
  if (batches == 0) fail("summarize_batches: batches must be >= 1, got 0");
  if (x.size() % batches != 0)
    fail("summarize_batches: batches = " + str(batches) + " does not divide n = " + str(x.size()));
  check_summary_input(x, probs, who);
  const std::size_t n = x.size();
  const std::size_t m = n / batches;
  if (m < 2)
    fail("summarize_batches: need at least 2 samples per batch, got n = " + str(n) + " in batches = " +
         str(batches));

  std::vector<double> s(x.begin(), x.end());
  const std::vector<double> pooled_q = q7_select(s, probs);
  const Moments pooled = moments(x);

  const std::size_t P = probs.size();
  std::vector<double> bmean(batches), bsd(batches), bq(batches * P);
  std::vector<double> tmp(m);
  for (std::size_t b = 0; b < batches; ++b) {
    const std::span<const double> xb = x.subspan(b * m, m);
    const Moments mb = moments(xb);
    bmean[b] = mb.mean;
    bsd[b] = mb.sd;
    std::copy(xb.begin(), xb.end(), tmp.begin());
    const std::vector<double> qb = q7_select(tmp, probs);
    for (std::size_t k = 0; k < P; ++k) bq[k * batches + b] = qb[k];
  }
  const double B = static_cast<double>(batches);
  auto se_of = [&](std::span<const double> v) {
    if (batches < 2) return nan_v;
    return moments(v).sd / std::sqrt(B);
  };

  Summary r;
  r.n = n;
  r.batches = batches;
  r.mean = {pooled.mean, se_of(bmean)};
  r.std = {pooled.sd, se_of(bsd)};
  r.probs.assign(probs.begin(), probs.end());
  for (std::size_t k = 0; k < P; ++k)
    r.quantiles.push_back({pooled_q[k], se_of(std::span<const double>(bq).subspan(k * batches, batches))});
  return r;
}

}  // namespace asperity
