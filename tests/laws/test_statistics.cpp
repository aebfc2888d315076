// SPDX-License-Identifier: GPL-3.0-or-later
// Tests of asperity/statistics.hpp.
//
// Every random test uses a fixed seed of asperity::Stream (counter-based Philox, portable and
// independent of the standard library's distributions), so every outcome is deterministic: a
// statistical assertion such as "p > 0.01 under H0" can fail only if the code changes. The
// thresholds are chosen so that a correct implementation fails them for only a tiny fraction of
// seeds (stated per test), i.e. the seed was not cherry-picked to make a wrong result pass.
#include "asperity/core/random.hpp"
#include "asperity/laws/statistics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace asperity;

constexpr double nan_v = std::numeric_limits<double>::quiet_NaN();
constexpr double inf_v = std::numeric_limits<double>::infinity();

// ---- data generators (inverse transform / Box-Muller on Philox uniforms) ----
struct Gen {
  Stream s;
  explicit Gen(std::uint64_t seed, std::uint64_t index = 0) : s(seed, Purpose::test, index) {}
  double uniform() { return s.uniform0(); }  // [0, 1)
  double normal() {
    const double r = std::sqrt(-2.0 * std::log(s.uniform()));  // uniform() in (0,1]
    return r * std::cos(2.0 * std::numbers::pi * s.uniform());
  }
  double exponential() { return -std::log(s.uniform()); }
  double rayleigh(double sigma) { return sigma * std::sqrt(-2.0 * std::log(s.uniform())); }
};

template <class F>
std::vector<double> draw(std::size_t n, F&& f, bool sorted = true) {
  std::vector<double> x(n);
  for (auto& v : x) v = f();
  if (sorted) std::sort(x.begin(), x.end());
  return x;
}

double normal_cdf(double x, double sd = 1.0) { return 0.5 * std::erfc(-x / (sd * std::numbers::sqrt2)); }
double rayleigh_cdf(double x, double sigma) { return x <= 0 ? 0.0 : -std::expm1(-x * x / (2 * sigma * sigma)); }
double uniform_cdf(double x) { return std::clamp(x, 0.0, 1.0); }

double sd_of(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m += x;
  m /= static_cast<double>(v.size());
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}
double rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

// D_n of a sorted uniform sample against U(0,1).
double ks_d_uniform(const std::vector<double>& u) {
  const double n = static_cast<double>(u.size());
  double D = 0;
  for (std::size_t i = 0; i < u.size(); ++i)
    D = std::max({D, static_cast<double>(i + 1) / n - u[i], u[i] - static_cast<double>(i) / n});
  return D;
}

template <class F>
std::string what_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "<no std::invalid_argument thrown>";
}

// =============================================================================================
// Kolmogorov distribution
// =============================================================================================

TEST(KolmogorovPvalue, ClosedFormsAndLimits) {
  for (std::size_t n : {1u, 2u, 5u, 10u, 1000u, 1000000u}) {
    const double dn = static_cast<double>(n);
    EXPECT_EQ(kolmogorov_pvalue(-1.0, n), 1.0);
    EXPECT_EQ(kolmogorov_pvalue(-inf_v, n), 1.0);
    EXPECT_EQ(kolmogorov_pvalue(0.0, n), 1.0);
    EXPECT_EQ(kolmogorov_pvalue(0.5 / dn, n), 1.0);  // D_n >= 1/(2n) always
    EXPECT_EQ(kolmogorov_pvalue(1.0, n), 0.0);
    EXPECT_EQ(kolmogorov_pvalue(inf_v, n), 0.0);
  }
  // n = 1: D_1 = max(U, 1-U), P(D_1 >= d) = 2(1-d) on [1/2, 1].
  for (double d : {0.5, 0.6, 0.75, 0.9, 0.999}) EXPECT_NEAR(kolmogorov_pvalue(d, 1), 2 * (1 - d), 1e-15);
  // Known closed forms (e.g. Simard & L'Ecuyer 2011, eq. for the extreme ranges):
  //   1/(2n) < d <= 1/n:  P(D_n < d) = n! (2d - 1/n)^n;   1 - 1/n <= d < 1: P(D_n >= d) = 2 (1-d)^n.
  for (std::size_t n : {2u, 3u, 7u, 20u, 60u}) {
    const double dn = static_cast<double>(n);
    for (double t : {0.55, 0.7, 0.9, 1.0}) {
      const double d = t / dn;
      const double K = std::exp(std::lgamma(dn + 1) + dn * std::log(2 * d - 1 / dn));
      EXPECT_NEAR(1.0 - kolmogorov_pvalue(d, n), K, 1e-13 * K + 1e-16) << "n=" << n << " d=" << d;
    }
    for (double t : {0.0, 0.3, 0.9}) {
      const double d = 1 - (1 - t) / dn;
      const double p = 2 * std::pow(1 - d, dn);
      EXPECT_NEAR(kolmogorov_pvalue(d, n), p, 1e-13 * p) << "n=" << n << " d=" << d;
    }
  }
}

// Reference values: exact rational arithmetic (Python fractions) with Steck's (1971)
// determinant formula P(a_i < U_(i) < b_i, i = 1..n) = n! det[(b_i - a_j)_+^(j-i+1)/(j-i+1)!],
// a_i = i/n - d, b_i = (i-1)/n + d -- an algorithm independent of Marsaglia-Tsang-Wang's. Steck's
// value for n = 10, d = 0.274, P(D < d) = 0.62847961545650428, reproduces the example quoted in
// the MTW paper (0.6284796154565043). The closed forms of the previous test check the formula.
TEST(KolmogorovPvalue, ExactReferenceValues) {
  struct Ref {
    std::size_t n;
    double d, p;  // p = P(D_n >= d)
  };
  const Ref refs[] = {
      {1, 0.8, 0.4},
      {3, 0.45, 0.4585},
      {5, 0.3, 0.664},
      {10, 0.274, 0.37152038454349572},
      {10, 0.1, 0.99963712},
      {10, 0.5, 0.00777741},
      {20, 0.15, 0.70446715494428716},
      {20, 0.25, 0.13762569836717624},
      {20, 0.35, 0.010754963444390500},
      {50, 0.1, 0.66231127046581854},
      {50, 0.2, 0.031438777769534506},
      {50, 0.3, 1.735326020271805482e-4},
      {50, 0.4, 9.8635633644100786e-8},  // Smirnov-tail branch
      {100, 0.05, 0.9532159710635725},
      {100, 0.1, 0.25269275700639013},
      {100, 0.15, 0.01983924212564604},
      {100, 0.2, 5.5519273280281019e-4},
      {100, 0.25, 5.4088717764348473e-6},
      {200, 0.06, 0.45015937456933736},
      {200, 0.12, 0.0057457604928326021},
      {400, 0.05, 0.26121260292565065},
      {400, 0.1, 6.1917972478748086e-4},
      {400, 0.105, 2.7086679544783518e-4},
      {800, 0.075, 2.327115351882202e-4},
  };
  for (const Ref& r : refs) {
    const double p = kolmogorov_pvalue(r.d, r.n);
    // Documented accuracy: 3e-11 relative (cancellation in 1 - P(D < d) / the neglected
    // double-crossing term of the Smirnov tail, both ~1e-11 at worst around n d^2 = 4.2).
    EXPECT_NEAR(p, r.p, 3e-11 * r.p) << "n=" << r.n << " d=" << r.d;
    if (r.n <= 20 || r.p > 0.01) {
      EXPECT_NEAR(p, r.p, 1e-13 * r.p) << "n=" << r.n << " d=" << r.d;
    }
  }
  // The MTW routine on its own: the paper's example.
  EXPECT_NEAR(kolmogorov_cdf_mtw(0.274, 10), 0.6284796154565043, 1e-14);
  // Smirnov one-sided: P(D_n^+ >= d) = (1-d)^n for d >= 1 - 1/n (single term); n = 1: 1 - d.
  const double q = std::pow(1 - 0.95, 10);  // (1-d)^n for the double nearest 0.95
  EXPECT_NEAR(smirnov_pvalue(0.95, 10), q, 1e-13 * q);
  EXPECT_NEAR(smirnov_pvalue(0.3, 1), 0.7, 1e-15);
}

// Independent check by simulation of the MTW example: R = 200000 samples of D_10.
// The fraction with D < 0.274 has binomial sd sqrt(0.628 * 0.372 / R) = 0.00108; tolerance 4 sd
// (a correct implementation fails with probability 6e-5).
TEST(KolmogorovPvalue, MonteCarloSmallN) {
  Gen g(101);
  const int R = 200000;
  int below = 0, below_tail = 0;
  std::vector<double> u(10);
  for (int r = 0; r < R; ++r) {
    for (double& v : u) v = g.uniform();
    std::sort(u.begin(), u.end());
    const double D = ks_d_uniform(u);
    below += D < 0.274;
    below_tail += D < 0.41;
  }
  const double sd = std::sqrt(0.63 * 0.37 / R);
  EXPECT_NEAR(static_cast<double>(below) / R, 1.0 - kolmogorov_pvalue(0.274, 10), 4 * sd);
  const double pt = kolmogorov_pvalue(0.41, 10);  // ~0.04
  EXPECT_NEAR(static_cast<double>(R - below_tail) / R, pt, 4 * std::sqrt(pt * (1 - pt) / R));
}

// Asymptotic critical values of sqrt(n) D: 1.2238 (10%), 1.3581 (5%), 1.6276 (1%). Q_KS at
// these points, summed to 30 digits with mpmath: 0.100023, 0.0499996, 0.0100015. At n = 10^6
// Stephens' correction changes lambda by 1.2e-4 relative, i.e. p by < 1e-3 relative.
TEST(KolmogorovPvalue, AsymptoticCriticalValues) {
  const std::size_t n = 1000000;
  const double sn = 1000.0;
  EXPECT_NEAR(kolmogorov_pvalue(1.2238 / sn, n), 0.100023, 2e-4);
  EXPECT_NEAR(kolmogorov_pvalue(1.3581 / sn, n), 0.0499996, 1e-4);
  EXPECT_NEAR(kolmogorov_pvalue(1.6276 / sn, n), 0.0100015, 3e-5);
  // Q_KS itself (Stephens' factor removed by passing d = lambda / (sqrt(n) + 0.12 + 0.11/sqrt(n))).
  const double f = std::sqrt(1e12) + 0.12 + 0.11 / std::sqrt(1e12);
  EXPECT_NEAR(kolmogorov_pvalue_asymptotic(0.5 / f, 1e12), 0.963945243664875, 1e-13);
  EXPECT_NEAR(kolmogorov_pvalue_asymptotic(1.0 / f, 1e12), 0.269999671677355, 1e-13);
  EXPECT_NEAR(kolmogorov_pvalue_asymptotic(1.3581 / f, 1e12), 0.0499996304316674, 1e-13);
  EXPECT_NEAR(kolmogorov_pvalue_asymptotic(2.0 / f, 1e12), 0.000670925255779695, 1e-15);
  // Large exact n: the exact and asymptotic values at the 5% point agree to Stephens' accuracy
  // (~0.1% at n = 10^4, measured; 1% tolerance).
  const double d = 1.3581 / 100.0;
  EXPECT_NEAR(1.0 - kolmogorov_cdf_mtw(d, 10000), kolmogorov_pvalue_asymptotic(d, 10000), 5e-4);
}

// The exact -> asymptotic switch at d_s = kmax/n is blended: p is continuous there; the exact
// 1 - P(D < d) -> 2 P(D+ >= d) switch at n d^2 = 4.2 is continuous to ~1e-11 (both exact).
TEST(KolmogorovPvalue, ContinuityBetweenBranches) {
  for (std::size_t n : {1000u, 2000u, 5000u, 30000u, 100000u}) {
    const double ds = static_cast<double>(kolmogorov_exact_kmax(n)) / static_cast<double>(n);
    ASSERT_GT(ds, 0.0);
    const double below = kolmogorov_pvalue(ds * (1 - 1e-12), n);
    const double above = kolmogorov_pvalue(ds * (1 + 1e-12), n);
    EXPECT_NEAR(below, above, 1e-9 * above + 1e-15) << "n=" << n << " d_s=" << ds;
    // Stephens' approximation there agrees with the exact value to ~1.2% (measured), so the
    // blend is a small correction.
    const double pe = 1.0 - kolmogorov_cdf_mtw(ds * (1 - 1e-12), n);
    EXPECT_NEAR(above, pe, 0.02 * pe + 1e-15) << "n=" << n;
  }
  EXPECT_EQ(kolmogorov_exact_kmax(200000), 0u);  // asymptotic only above 10^5
  for (std::size_t n : {20u, 100u, 400u}) {
    const double dt = std::sqrt(4.2 / static_cast<double>(n));
    const double below = kolmogorov_pvalue(dt * (1 - 1e-13), n);
    const double above = kolmogorov_pvalue(dt, n);
    EXPECT_NEAR(below, above, 1e-10 * above) << "n=" << n;
  }
}

TEST(KolmogorovPvalue, MonotoneAndInRange) {
  for (std::size_t n : {1u, 2u, 3u, 5u, 10u, 37u, 100u, 500u, 1000u, 3000u, 100000u, 10000000u}) {
    const double dn = static_cast<double>(n);
    double prev = 1.0;
    // log grid from below 1/(2n) to 1, plus a dense band around the exact/asymptotic switch.
    std::vector<double> ds;
    for (double d = 0.3 / dn; d < 1.05; d *= 1.06) ds.push_back(d);
    const double dsw = static_cast<double>(kolmogorov_exact_kmax(n)) / dn;
    for (int i = -12; i <= 4; ++i) ds.push_back(dsw * (1 + 0.002 * i));
    std::sort(ds.begin(), ds.end());
    for (double d : ds) {
      const double p = kolmogorov_pvalue(d, n);
      ASSERT_TRUE(p >= 0.0 && p <= 1.0) << "n=" << n << " d=" << d << " p=" << p;
      // rounding-level slack only
      ASSERT_LE(p, prev * (1 + 1e-12)) << "n=" << n << " d=" << d;
      prev = p;
    }
  }
}

// =============================================================================================
// One-sample KS
// =============================================================================================

TEST(KsOneSample, StatisticByHand) {
  const std::vector<double> x = {0.1, 0.4, 0.7};
  const KsResult r = ks_one_sample(x, uniform_cdf);
  // max(1/3 - .1, .1 - 0, 2/3 - .4, .4 - 1/3, 1 - .7, .7 - 2/3) = 0.3
  EXPECT_NEAR(r.D, 0.3, 1e-15);
  EXPECT_EQ(r.n, 3u);
  EXPECT_EQ(r.p, kolmogorov_pvalue(r.D, 3));
  // +-inf samples are fine when the cdf maps them to 0 / 1.
  const std::vector<double> y = {-inf_v, 0.0, inf_v};
  EXPECT_NEAR(ks_one_sample(y, [](double v) { return normal_cdf(v); }).D, 1.0 / 3.0, 1e-15);
}

// The pruned KS for expensive monotone cdfs returns ks_one_sample's D and p bit for bit: samples
// from a mixture of asymmetric Laplace laws (the bounce residuals' shape) with ties, tested against
// the true mixture, a 5 %-wrong scale (D large: few runs pruned), the mirrored law, a cdf flat over
// most of the sample and a step, at n around the stride and up to 10^5. Under the true
// law it must evaluate F far less often than n (the point of it).
TEST(KsOneSample, MonotoneVariantIsTheSameTestWithFewerEvaluations) {
  struct Part { double w, a1, a2; };
  const std::vector<Part> mix = {{0.5, 1.0, 0.3}, {0.3, 2.0, 0.1}, {0.2, 0.5, 0.5}};
  auto cdf_of = [&mix](double scale) {
    return [&mix, scale](double x) {
      double F = 0;
      for (const auto& m : mix) {
        const double a1 = scale * m.a1, a2 = scale * m.a2, t = a1 + a2;
        F += m.w * (x < 0 ? a1 / t * std::exp(x / a1) : 1.0 - a2 / t * std::exp(-x / a2));
      }
      return std::clamp(F, 0.0, 1.0);
    };
  };
  for (std::size_t n : {1u, 2u, 31u, 32u, 33u, 64u, 65u, 1000u, 100000u}) {
    Stream s(5, Purpose::test, n);
    std::vector<double> x(n);
    for (auto& v : x) {
      const double u = s.uniform();
      const Part* m = &mix[0];
      for (double c = mix[0].w; u > c && m != &mix.back(); c += (++m)->w) {}
      const double e = -std::log(s.uniform());
      v = s.uniform() < m->a1 / (m->a1 + m->a2) ? -m->a1 * e : m->a2 * e;
      if (n > 1000 && v > 0 && v < 0.01) v = 0.005;  // ties
    }
    std::sort(x.begin(), x.end());
    const auto flat = [](double v) { return v < -5 ? 0.0 : v > 5 ? 1.0 : 0.5; };
    const auto right = cdf_of(1.0);
    const auto mirrored = [&right](double v) { return 1.0 - right(-v); };
    for (const Cdf& F : std::vector<Cdf>{right, cdf_of(1.05), mirrored, flat,
                                         [](double v) { return v < 0 ? 1e-9 : 1.0; }}) {
      std::size_t calls = 0;
      const KsResult a = ks_one_sample(x, F);
      const KsResult b = ks_one_sample_monotone(x, [&](double v) { ++calls; return F(v); });
      EXPECT_EQ(a.D, b.D) << n;
      EXPECT_EQ(a.p, b.p) << n;
      EXPECT_EQ(a.n, b.n);
      EXPECT_LE(calls, n);
    }
    std::size_t calls = 0;
    const auto F = cdf_of(1.0);
    ks_one_sample_monotone(x, [&](double v) { ++calls; return F(v); });
    if (n == 100000) {
      EXPECT_LT(calls, n / 8) << "the pruning must pay under the true law";
    }
  }
}

// Under H0 the p-values must be U(0,1). 2000 repetitions, n = 200 (the exact branch):
//  - the number of p < 0.05 is Binomial(2000, 0.05): mean 100, sd 9.75; tolerance 4 sd (a
//    correct p-value fails with probability 6e-5, while a p-value off by 20% fails reliably);
//  - the same for p < 0.01 (mean 20, sd 4.45);
//  - a KS test of the 2000 p-values against U(0,1) gives p > 0.001 (fails for 0.1% of seeds).
TEST(KsOneSample, CalibratedUnderH0) {
  const int R = 2000;
  const std::size_t n = 200;
  std::vector<double> ps;
  for (int r = 0; r < R; ++r) {
    Gen g(202, static_cast<std::uint64_t>(r));
    const auto u = draw(n, [&] { return g.uniform(); });
    ps.push_back(ks_one_sample(u, uniform_cdf).p);
  }
  const double f05 = static_cast<double>(std::count_if(ps.begin(), ps.end(), [](double p) { return p < 0.05; })) / R;
  const double f01 = static_cast<double>(std::count_if(ps.begin(), ps.end(), [](double p) { return p < 0.01; })) / R;
  EXPECT_NEAR(f05, 0.05, 4 * std::sqrt(0.05 * 0.95 / R));
  EXPECT_NEAR(f01, 0.01, 4 * std::sqrt(0.01 * 0.99 / R));
  std::sort(ps.begin(), ps.end());
  EXPECT_GT(ks_one_sample(ps, uniform_cdf).p, 1e-3);
}

// Power: 10^5 samples of a law tested against the same law with a 5% larger scale. The
// expected D is ~0.03 (Rayleigh) and ~0.011 (normal), i.e. sqrt(n) D ~ 10 and ~3.6, so
// p ~ 1e-80 and ~1e-11: p < 1e-6 holds by a wide margin. The right law gives p > 0.01, which a
// correct implementation fails for 1% of seeds; the seed is fixed, so the outcome is
// deterministic.
TEST(KsOneSample, PowerAgainstWrongScale) {
  const std::size_t n = 100000;
  {
    Gen g(303);
    const auto x = draw(n, [&] { return g.rayleigh(2.0); });
    const KsResult wrong = ks_one_sample(x, [](double v) { return rayleigh_cdf(v, 2.0 * 1.05); });
    EXPECT_LT(wrong.p, 1e-6) << "D=" << wrong.D;
    const KsResult right = ks_one_sample(x, [](double v) { return rayleigh_cdf(v, 2.0); });
    EXPECT_GT(right.p, 0.01) << "D=" << right.D;
  }
  {
    Gen g(304);
    const auto x = draw(n, [&] { return g.normal(); });
    const KsResult wrong = ks_one_sample(x, [](double v) { return normal_cdf(v, 1.05); });
    EXPECT_LT(wrong.p, 1e-6) << "D=" << wrong.D;
    const KsResult right = ks_one_sample(x, [](double v) { return normal_cdf(v); });
    EXPECT_GT(right.p, 0.01) << "D=" << right.D;
  }
  {
    // A smaller sample (exact branch) also rejects a gross error: exponential vs U(0,1)-ish.
    Gen g(305);
    const auto x = draw(300, [&] { return g.exponential(); });
    EXPECT_LT(ks_one_sample(x, [](double v) { return rayleigh_cdf(v, 1.0); }).p, 1e-6);
    EXPECT_GT(ks_one_sample(x, [](double v) { return v <= 0 ? 0.0 : -std::expm1(-v); }).p, 0.01);
  }
}

// =============================================================================================
// Two-sample KS
// =============================================================================================

// Reference D: evaluate both ECDFs (right-continuous) at every value of the union.
double brute_d2(const std::vector<double>& a, const std::vector<double>& b) {
  double D = 0;
  auto ecdf = [](const std::vector<double>& s, double v) {
    return static_cast<double>(std::upper_bound(s.begin(), s.end(), v) - s.begin()) / static_cast<double>(s.size());
  };
  for (const auto* s : {&a, &b})
    for (double v : *s) D = std::max(D, std::fabs(ecdf(a, v) - ecdf(b, v)));
  return D;
}

TEST(KsTwoSample, Ties) {
  const std::vector<double> a = {0, 1, 1, 2}, b = {1, 1, 1, 3};
  // ECDFs: x=0: .25 vs 0; x=1: .75 vs .75; x=2: 1 vs .75; x=3: 1 vs 1 -> D = 1/4 (stepping a
  // alone past its first 1 would give a spurious 1/2).
  EXPECT_DOUBLE_EQ(ks_two_sample(a, b).D, 0.25);
  const KsResult same = ks_two_sample(a, a);
  EXPECT_EQ(same.D, 0.0);
  EXPECT_EQ(same.p, 1.0);
  const std::vector<double> c = {2, 2, 2}, d = {2, 2};
  EXPECT_EQ(ks_two_sample(c, d).D, 0.0);
  // Heavily tied integer data (rounded normals) of different sizes: D matches brute force.
  Gen g(401);
  const auto x = draw(500, [&] { return std::round(3 * g.normal()); });
  const auto y = draw(730, [&] { return std::round(3 * g.normal() + 0.5); });
  EXPECT_DOUBLE_EQ(ks_two_sample(x, y).D, brute_d2(x, y));
  EXPECT_DOUBLE_EQ(ks_two_sample(y, x).D, brute_d2(x, y));
  EXPECT_EQ(ks_two_sample(x, y).n, static_cast<std::size_t>(std::llround(500.0 * 730.0 / 1230.0)));
}

// Same law accepted (p > 0.01: fails for ~1% of seeds, the asymptotic p being close to uniform
// at these sizes), a shift of 0.3 sd rejected: D ~ 2 Phi(0.15) - 1 = 0.12, sqrt(n_eff) D ~ 4.1,
// p ~ 1e-14 < 1e-6.
TEST(KsTwoSample, AcceptsSameRejectsShift) {
  Gen g(402);
  const auto a = draw(3000, [&] { return g.normal(); });
  const auto b = draw(2000, [&] { return g.normal(); });
  const auto c = draw(2000, [&] { return g.normal() + 0.3; });
  const KsResult same = ks_two_sample(a, b);
  EXPECT_GT(same.p, 0.01) << same.D;
  EXPECT_DOUBLE_EQ(same.D, brute_d2(a, b));
  const KsResult shifted = ks_two_sample(a, c);
  EXPECT_LT(shifted.p, 1e-6) << shifted.D;
}

// Exact null distribution of the two-sample D for n = m (Gnedenko & Korolyuk 1951):
// P(D_{n,n} >= k/n) = 2 sum_{j>=1} (-1)^{j-1} C(2n, n - jk) / C(2n, n). (n = 1: P(D >= 1) = 1.)
double gnedenko_korolyuk(int n, int k) {
  double s = 0;
  for (int j = 1; j * k <= n; ++j) {
    const double t = std::exp(2 * std::lgamma(n + 1.0) - std::lgamma(n - j * k + 1.0) - std::lgamma(n + j * k + 1.0));
    s += (j % 2 == 1) ? t : -t;
  }
  return 2 * s;
}

// Level of the asymptotic two-sample test, n = m = 200, 1000 repetitions. D is a multiple of
// 1/200, so "p < 0.05" means D >= k*/200 for the smallest such k*; its exact probability
// under H0 (Gnedenko-Korolyuk) is the true level: 0.0521 (k* = 27; the Stephens-corrected
// asymptotic p is ~9% low at these sizes). The observed fraction must match it within 4
// binomial sd (sd = 0.007), and the level must be within 0.04..0.06 of the nominal 0.05.
TEST(KsTwoSample, CalibratedAgainstExactNull) {
  EXPECT_NEAR(gnedenko_korolyuk(1, 1), 1.0, 1e-14);
  const int n = 200;
  int kstar = 1;
  while (kolmogorov_pvalue_asymptotic(kstar / 200.0, 100.0) >= 0.05) ++kstar;
  const double level = gnedenko_korolyuk(n, kstar);
  EXPECT_GT(level, 0.04);
  EXPECT_LT(level, 0.06);
  const int R = 1000;
  int rej = 0;
  for (int r = 0; r < R; ++r) {
    Gen g(403, static_cast<std::uint64_t>(r));
    const auto a = draw(n, [&] { return g.uniform(); });
    const auto b = draw(n, [&] { return g.uniform(); });
    rej += ks_two_sample(a, b).p < 0.05;
  }
  EXPECT_NEAR(static_cast<double>(rej) / R, level, 4 * std::sqrt(level * (1 - level) / R)) << "k*=" << kstar;
}

// =============================================================================================
// Histogram and chi-square
// =============================================================================================

TEST(Histogram, CountsEdgesAndDensity) {
  const std::vector<double> x = {-1.0, 0.0, 0.25, 0.5, 0.999, 1.0, 2.0, -inf_v, inf_v};
  const Histogram h = make_histogram(x, 0.0, 1.0, 4);
  EXPECT_EQ(h.total, 9u);
  EXPECT_EQ(h.under, 2u);  // -1, -inf
  EXPECT_EQ(h.over, 3u);   // 1 (right edge is open), 2, inf
  EXPECT_EQ(h.counts, (std::vector<double>{1, 1, 1, 1}));
  EXPECT_DOUBLE_EQ(h.density(0), 1.0 / (9 * 0.25));
  EXPECT_DOUBLE_EQ(h.density_se(0), 1.0 / (9 * 0.25));
  EXPECT_DOUBLE_EQ(h.centre(1), 0.375);

  Gen g(501);
  const auto y = draw(20000, [&] { return g.normal(); }, false);
  const Histogram hn = make_histogram(y, -2.0, 2.5, 45);
  double integral = 0, inside = 0;
  int big = 0;
  for (std::size_t i = 0; i < hn.bins(); ++i) {
    integral += hn.density(i) * hn.width();
    inside += hn.counts[i];
    EXPECT_DOUBLE_EQ(hn.density_se(i), std::sqrt(hn.counts[i]) / (20000.0 * hn.width()));
    // Bin-averaged pdf; each density within 4.5 Poisson se (45 bins: all pass with prob.
    // 1 - 45 * 7e-6 for a correct histogram).
    const double pdf = (normal_cdf(hn.left(i) + hn.width()) - normal_cdf(hn.left(i))) / hn.width();
    big += std::fabs(hn.density(i) - pdf) > 4.5 * std::sqrt(pdf / (20000.0 * hn.width()));
  }
  EXPECT_EQ(big, 0);
  EXPECT_EQ(inside + static_cast<double>(hn.under + hn.over), 20000.0);
  EXPECT_NEAR(integral, 1.0 - static_cast<double>(hn.under + hn.over) / 20000.0, 1e-12);
  EXPECT_GT(hn.under, 0u);
  EXPECT_GT(hn.over, 0u);
}

TEST(Chi2, MergingByHand) {
  // U(0,1) cdf, 10 bins on [0,1), 20 samples: every bin expects 2, under/over expect 0.
  Histogram h;
  h.lo = 0;
  h.hi = 1;
  h.counts = {5, 3, 2, 1, 1, 1, 2, 1, 2, 2};
  h.total = 20;
  // min_expected 5, greedy from the left: [under,b0,b1,b2] (obs 10, exp 6), [b3,b4,b5] (3, 6),
  // [b6,b7,b8] (5, 6) + remainder [b9, over] (2, 2) -> (7, 8). chi2 = 16/6 + 9/6 + 1/8.
  const Chi2Result r = chi2_test(h, uniform_cdf, 5.0);
  EXPECT_EQ(r.dof, 2);
  EXPECT_NEAR(r.chi2, 16.0 / 6 + 9.0 / 6 + 1.0 / 8, 1e-12);
  EXPECT_NEAR(r.p, std::exp(-r.chi2 / 2), 1e-12);  // chi-square survival for 2 dof
  // min_expected 1: [under,b0], b1..b8, [b9,over] -> 10 cells.
  const Chi2Result r1 = chi2_test(h, uniform_cdf, 1.0);
  EXPECT_EQ(r1.dof, 9);
  double c = 0;
  for (double o : h.counts) c += (o - 2) * (o - 2) / 2;
  EXPECT_NEAR(r1.chi2, c, 1e-12);
  // Too few samples for two cells: documented dof 0, p NaN.
  Histogram tiny = h;
  tiny.counts = {1, 0, 0, 1, 0, 0, 0, 1, 0, 1};
  tiny.total = 4;
  const Chi2Result rt = chi2_test(tiny, uniform_cdf, 5.0);
  EXPECT_EQ(rt.dof, 0);
  EXPECT_TRUE(std::isnan(rt.p));
  // Under/over flow cells count: all 20 samples beyond hi with a cdf that puts mass there.
  Histogram out = h;
  out.counts.assign(10, 0.0);
  out.over = 20;
  const Chi2Result ro = chi2_test(out, uniform_cdf, 5.0);
  EXPECT_LT(ro.p, 1e-6);
}

// Right law accepted (p > 0.01, fails for 1% of seeds), 5% wrong scale rejected with 10^5
// samples (chi2 excess ~ n * sum (dp)^2/p ~ 10^2 over ~50 dof: p ~ 1e-10 or smaller).
TEST(Chi2, AcceptsRightRejectsWrong) {
  Gen g(601);
  const auto x = draw(100000, [&] { return g.normal(); }, false);
  const Histogram h = make_histogram(x, -4.0, 4.0, 50);
  const Chi2Result right = chi2_test(h, [](double v) { return normal_cdf(v); });
  EXPECT_GT(right.p, 0.01) << right.chi2 << " dof " << right.dof;
  EXPECT_EQ(right.dof, 50 + 2 - 1 - 2);  // under and over expect ~3.2 each: merged into neighbours
  const Chi2Result wrong = chi2_test(h, [](double v) { return normal_cdf(v, 1.05); });
  EXPECT_LT(wrong.p, 1e-6) << wrong.chi2 << " dof " << wrong.dof;
}

// Level: 1000 repetitions of 500 normals in 20 bins; fraction of p < 0.05 within 4 binomial sd.
TEST(Chi2, CalibratedUnderH0) {
  const int R = 1000;
  int rej = 0;
  for (int r = 0; r < R; ++r) {
    Gen g(602, static_cast<std::uint64_t>(r));
    const auto x = draw(500, [&] { return g.normal(); }, false);
    rej += chi2_test(make_histogram(x, -3.0, 3.0, 20), [](double v) { return normal_cdf(v); }).p < 0.05;
  }
  EXPECT_NEAR(static_cast<double>(rej) / R, 0.05, 4 * std::sqrt(0.05 * 0.95 / R));
}

// =============================================================================================
// Quantiles and summaries
// =============================================================================================

TEST(Quantile, Type7) {
  const std::vector<double> x = {1, 2, 3, 4};
  EXPECT_EQ(quantile_sorted(x, 0.0), 1.0);
  EXPECT_EQ(quantile_sorted(x, 1.0), 4.0);
  EXPECT_DOUBLE_EQ(quantile_sorted(x, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(quantile_sorted(x, 0.25), 1.75);  // R: quantile(1:4, 0.25) = 1.75
  EXPECT_DOUBLE_EQ(quantile_sorted(x, 0.9), 3.7);
  const std::vector<double> one = {7.5};
  EXPECT_EQ(quantile_sorted(one, 0.3), 7.5);
  const std::vector<double> withinf = {1, 2, inf_v};
  EXPECT_EQ(quantile_sorted(withinf, 0.5), 2.0);  // no 0 * inf
}

// The reported standard errors against the Monte Carlo spread of the estimators over R = 2000
// independent samples of n = 400. The spread itself is estimated to ~1/sqrt(2R) = 1.6% (more
// for heavy-tailed estimators), and the se formulas are large-n approximations (delta method,
// order-statistic interval): they agree with the truth to a few % here. We compare the RMS of
// the reported se with the MC sd within 10% (12% for the std of exponential data, whose
// kurtosis estimate is noisy and biased low at n = 400).
TEST(Summary, IidStandardErrorsMatchMonteCarlo) {
  const int R = 2000;
  const std::size_t n = 400;
  const std::vector<double> probs = {0.1, 0.5, 0.9};
  for (int law = 0; law < 2; ++law) {
    std::vector<double> mean, sd, q[3], se_mean, se_sd, se_q[3];
    for (int r = 0; r < R; ++r) {
      Gen g(701 + law, static_cast<std::uint64_t>(r));
      const auto x = draw(n, [&] { return law == 0 ? g.normal() : g.exponential(); }, false);
      const Summary s = summarize_iid(x, probs);
      EXPECT_EQ(s.n, n);
      EXPECT_EQ(s.batches, n);
      mean.push_back(s.mean.value);
      se_mean.push_back(s.mean.se);
      sd.push_back(s.std.value);
      se_sd.push_back(s.std.se);
      for (int k = 0; k < 3; ++k) {
        q[k].push_back(s.quantiles[k].value);
        se_q[k].push_back(s.quantiles[k].se);
      }
    }
    const char* name = law == 0 ? "normal" : "exponential";
    EXPECT_NEAR(rms(se_mean) / sd_of(mean), 1.0, 0.10) << name;
    EXPECT_NEAR(rms(se_sd) / sd_of(sd), 1.0, law == 0 ? 0.10 : 0.12) << name;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(rms(se_q[k]) / sd_of(q[k]), 1.0, 0.10) << name << " p=" << probs[k];
  }
}

TEST(Summary, IidValues) {
  const std::vector<double> x = {3, 1, 2, 5, 4};
  const std::vector<double> probs = {0.0, 0.5, 1.0};
  const Summary s = summarize_iid(x, probs);
  EXPECT_DOUBLE_EQ(s.mean.value, 3.0);
  EXPECT_DOUBLE_EQ(s.std.value, std::sqrt(2.5));
  EXPECT_DOUBLE_EQ(s.mean.se, std::sqrt(2.5 / 5));
  // kurtosis m4/m2^2 = (2*16 + 2*1)/5 / 2^2 = 1.7 -> se = s sqrt(0.7/20)
  EXPECT_DOUBLE_EQ(s.std.se, std::sqrt(2.5) * std::sqrt(0.7 / 20));
  EXPECT_EQ(s.quantiles[0].value, 1.0);
  EXPECT_EQ(s.quantiles[1].value, 3.0);
  EXPECT_EQ(s.quantiles[2].value, 5.0);
  EXPECT_TRUE(std::isnan(s.quantiles[0].se));  // documented: min/max se not estimable
  EXPECT_TRUE(std::isnan(s.quantiles[2].se));
  // median: probabilities 0.5 -/+ sqrt(0.25/5) = 0.276, 0.724 -> type 7 at h = 1.106, 2.894
  const double h = std::sqrt(0.25 / 5);
  EXPECT_NEAR(s.quantiles[1].se, 0.5 * ((1 + 4 * (0.5 + h)) - (1 + 4 * (0.5 - h))), 1e-12);
  // constant data: everything finite, se 0
  const std::vector<double> c(10, 2.0);
  const Summary sc = summarize_iid(c, std::vector<double>{0.5});
  EXPECT_EQ(sc.std.value, 0.0);
  EXPECT_EQ(sc.std.se, 0.0);
  EXPECT_EQ(sc.quantiles[0].se, 0.0);
}

// iid data cut into batches: the batch se estimates the same thing as the iid se. Averaged
// (RMS) over 200 repetitions of 50 batches x 40, the noise of the ratio is ~1/sqrt(2*49*200)
// = 0.7% and the small-batch bias of per-batch medians/std is a few %: tolerance 10%.
TEST(Summary, BatchesWithIidDataMatchIid) {
  const int R = 200;
  const std::vector<double> probs = {0.5, 0.9};
  std::vector<double> bm, im, bs, is, bq0, iq0, bq1, iq1;
  for (int r = 0; r < R; ++r) {
    Gen g(801, static_cast<std::uint64_t>(r));
    const auto x = draw(2000, [&] { return g.normal(); }, false);
    const Summary b = summarize_batches(x, 50, probs);
    const Summary i = summarize_iid(x, probs);
    EXPECT_EQ(b.batches, 50u);
    EXPECT_EQ(b.mean.value, i.mean.value);  // pooled values are the iid values
    EXPECT_EQ(b.std.value, i.std.value);
    EXPECT_EQ(b.quantiles[0].value, i.quantiles[0].value);
    bm.push_back(b.mean.se);
    im.push_back(i.mean.se);
    bs.push_back(b.std.se);
    is.push_back(i.std.se);
    bq0.push_back(b.quantiles[0].se);
    iq0.push_back(i.quantiles[0].se);
    bq1.push_back(b.quantiles[1].se);
    iq1.push_back(i.quantiles[1].se);
  }
  EXPECT_NEAR(rms(bm) / rms(im), 1.0, 0.10);
  EXPECT_NEAR(rms(bs) / rms(is), 1.0, 0.10);
  EXPECT_NEAR(rms(bq0) / rms(iq0), 1.0, 0.10);
  EXPECT_NEAR(rms(bq1) / rms(iq1), 1.0, 0.10);
}

// Strongly correlated batches: batch b = offset_b + small noise (offset ~ N(0,1), noise sd
// 0.1), 20 batches x 50. The pooled mean's true sd is sqrt(1/20 + 0.01/1000) = 0.2236; the iid
// formula claims ~sqrt(1.01/1000) = 0.032. Over 400 repetitions the batch se (RMS) must match the
// observed spread of the pooled mean (noise of that spread ~1/sqrt(800) = 3.5%, of the RMS
// ~1/sqrt(2*19*400) = 0.8%: tolerance 12%), and every single batch se exceeds 3x the iid se.
TEST(Summary, BatchesCaptureCorrelation) {
  const int R = 400;
  const std::size_t B = 20, M = 50;
  std::vector<double> means, se_b;
  for (int r = 0; r < R; ++r) {
    Gen g(901, static_cast<std::uint64_t>(r));
    std::vector<double> x;
    for (std::size_t b = 0; b < B; ++b) {
      const double offset = g.normal();
      for (std::size_t j = 0; j < M; ++j) x.push_back(offset + 0.1 * g.normal());
    }
    const Summary s = summarize_batches(x, B, std::vector<double>{0.5});
    const Summary i = summarize_iid(x, std::vector<double>{0.5});
    EXPECT_GT(s.mean.se, 3 * i.mean.se);
    means.push_back(s.mean.value);
    se_b.push_back(s.mean.se);
  }
  EXPECT_NEAR(sd_of(means), std::sqrt(1.0 / 20 + 0.01 / 1000), 0.12 * 0.2236);
  EXPECT_NEAR(rms(se_b) / sd_of(means), 1.0, 0.12);
}

TEST(Summary, SingleBatchHasNanSe) {
  const std::vector<double> x = {1, 2, 3, 4};
  const Summary s = summarize_batches(x, 1, std::vector<double>{0.5});
  EXPECT_DOUBLE_EQ(s.mean.value, 2.5);
  EXPECT_TRUE(std::isnan(s.mean.se));
  EXPECT_TRUE(std::isnan(s.std.se));
  EXPECT_TRUE(std::isnan(s.quantiles[0].se));
  EXPECT_EQ(s.batches, 1u);
}

// =============================================================================================
// Invalid input
// =============================================================================================

TEST(Statistics, InvalidInputThrows) {
  const std::vector<double> empty;
  const std::vector<double> ok = {0.1, 0.2, 0.3, 0.4};
  const std::vector<double> unsorted = {0.1, 0.3, 0.2};
  const std::vector<double> withnan = {0.1, nan_v, 0.3};
  const std::vector<double> probs = {0.5};

  EXPECT_THROW(kolmogorov_pvalue(nan_v, 10), std::invalid_argument);
  EXPECT_THROW(kolmogorov_pvalue(0.1, 0), std::invalid_argument);
  EXPECT_THROW(kolmogorov_pvalue_asymptotic(0.1, 0.0), std::invalid_argument);
  EXPECT_THROW(kolmogorov_cdf_mtw(nan_v, 3), std::invalid_argument);

  EXPECT_THROW(ks_one_sample(empty, uniform_cdf), std::invalid_argument);
  EXPECT_NE(what_of([&] { ks_one_sample(unsorted, uniform_cdf); }).find("0.3"), std::string::npos);
  EXPECT_THROW(ks_one_sample(withnan, uniform_cdf), std::invalid_argument);
  EXPECT_NE(what_of([&] { ks_one_sample(ok, [](double) { return nan_v; }); }).find("nan"), std::string::npos);
  EXPECT_THROW(ks_one_sample(ok, [](double) { return 1.5; }), std::invalid_argument);
  EXPECT_THROW(ks_two_sample(empty, ok), std::invalid_argument);
  EXPECT_THROW(ks_two_sample(ok, unsorted), std::invalid_argument);

  EXPECT_THROW(make_histogram(ok, 1.0, 1.0, 4), std::invalid_argument);
  EXPECT_THROW(make_histogram(ok, 0.0, inf_v, 4), std::invalid_argument);
  EXPECT_THROW(make_histogram(ok, 0.0, 1.0, 0), std::invalid_argument);
  EXPECT_THROW(make_histogram(withnan, 0.0, 1.0, 4), std::invalid_argument);
  const Histogram h0 = make_histogram(empty, 0.0, 1.0, 4);
  EXPECT_THROW(h0.density(0), std::invalid_argument);
  const Histogram h = make_histogram(ok, 0.0, 1.0, 4);
  EXPECT_THROW(h.density(4), std::out_of_range);
  EXPECT_THROW(chi2_test(h, uniform_cdf, 0.0), std::invalid_argument);
  EXPECT_THROW(chi2_test(h, [](double v) { return 1 - uniform_cdf(v); }), std::invalid_argument);
  EXPECT_THROW(chi2_test(h0, uniform_cdf), std::invalid_argument);
  Histogram bad = h;
  bad.total = 99;
  EXPECT_THROW(chi2_test(bad, uniform_cdf), std::invalid_argument);

  EXPECT_THROW(quantile_sorted(empty, 0.5), std::invalid_argument);
  EXPECT_THROW(quantile_sorted(ok, 1.5), std::invalid_argument);
  EXPECT_THROW(quantile_sorted(ok, nan_v), std::invalid_argument);
  EXPECT_THROW(quantile_sorted(unsorted, 0.5), std::invalid_argument);

  EXPECT_THROW(summarize_iid(std::vector<double>{1.0}, probs), std::invalid_argument);
  EXPECT_THROW(summarize_iid(withnan, probs), std::invalid_argument);
  EXPECT_THROW(summarize_iid(ok, std::vector<double>{-0.1}), std::invalid_argument);
  const std::vector<double> big(1000, 1.0);
  const std::string msg = what_of([&] { summarize_batches(big, 7, probs); });
  EXPECT_NE(msg.find("7"), std::string::npos) << msg;
  EXPECT_NE(msg.find("1000"), std::string::npos) << msg;
  EXPECT_THROW(summarize_batches(big, 0, probs), std::invalid_argument);
  EXPECT_THROW(summarize_batches(big, 1000, probs), std::invalid_argument);  // 1 sample per batch
}

}  // namespace
