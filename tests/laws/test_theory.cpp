// SPDX-License-Identifier: GPL-3.0-or-later
// The analytic laws: internal consistency (pdf = cdf'), normalisation, limits, and agreement with
// direct Monte Carlo of the same definition.
#include <gtest/gtest.h>

#include <boost/math/quadrature/gauss_kronrod.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "asperity/core/geometry.hpp"
#include "asperity/core/random.hpp"
#include "asperity/laws/theory.hpp"

using namespace asperity;
using GK = boost::math::quadrature::gauss_kronrod<double, 31>;

namespace {

constexpr double R = 3e-3;

void expect_pdf_is_cdf_derivative(const Law& law, double lo, double hi, double rel) {
  for (int i = 1; i < 40; ++i) {
    const double t = lo + (hi - lo) * i / 40.0, h = (hi - lo) * 1e-5;
    const double num = (law.cdf(t + h) - law.cdf(t - h)) / (2 * h);
    EXPECT_NEAR(num, law.pdf(t), rel * law.pdf(t) + 1e-12 / (hi - lo)) << law.name << " at t = " << t;
  }
}

TEST(Theory, Eq14IsANormalisedRayleighWithSigmaSquaredOneOver2PiLambda) {
  const std::uint64_t n = 100000;
  const Law l = eq14_rxy(n, R);
  const double sigma = 1 / std::sqrt(2 * std::numbers::pi * areal_density(n, R));
  EXPECT_NEAR(GK::integrate(l.pdf, 0.0, 20 * sigma, 15, 1e-12), 1.0, 1e-10);
  EXPECT_NEAR(GK::integrate([&](double t) { return t * l.pdf(t); }, 0.0, 20 * sigma, 15, 1e-12),
              sigma * std::sqrt(std::numbers::pi / 2), 1e-9 * sigma);
  expect_pdf_is_cdf_derivative(l, 0, 5 * sigma, 1e-6);
}

TEST(Theory, Eq18IsTheNormalisedGaussianWithTheSameSigma) {
  // The final line of Eq. 18, sqrt(lambda) exp(-pi lambda t^2), is a normalised Gaussian with
  // variance 1/(2 pi lambda): exactly the marginal of the Rayleigh law of Eq. 14.
  const std::uint64_t n = 100000;
  const Law l = eq18_rx(n, R);
  const double lam = areal_density(n, R), sigma2 = 1 / (2 * std::numbers::pi * lam);
  for (double t : {0.0, 1e-6, 1e-5}) EXPECT_NEAR(l.pdf(t), std::sqrt(lam) * std::exp(-std::numbers::pi * lam * t * t), 1e-9 * std::sqrt(lam));
  const double s = std::sqrt(sigma2);
  EXPECT_NEAR(GK::integrate(l.pdf, -20 * s, 20 * s, 15, 1e-12), 1.0, 1e-10);
  EXPECT_NEAR(GK::integrate([&](double t) { return t * t * l.pdf(t); }, -20 * s, 20 * s, 15, 1e-12), sigma2, 1e-9 * sigma2);
}

TEST(Theory, ExactSphereLawForOneAsperityIsSinOfAUniformCosine) {
  // N = 1: cos(theta) uniform on [-1,1], r_xy = R sin(theta): F(t) = 1 - sqrt(1 - t^2/R^2).
  const Law l = exact_sphere_rxy(1, R);
  for (double s : {0.01, 0.3, 0.7, 0.99}) EXPECT_NEAR(l.cdf(s * R), 1 - std::sqrt(1 - s * s), 1e-14);
  EXPECT_EQ(l.cdf(0), 0.0);
  EXPECT_EQ(l.cdf(R), 1.0);
}

TEST(Theory, ExactSphereLawMatchesMonteCarloAtSmallN) {
  // Direct simulation of the definition: N = 5 uniform points, r_xy of the one nearest the
  // south pole. 20000 draws, KS; alpha = 0.001 with a fixed seed (deterministic).
  const std::uint64_t n = 5;
  std::vector<double> x;
  for (std::uint64_t i = 0; i < 20000; ++i) {
    double best = -2;
    Vec3 bu;
    for (std::uint64_t j = 0; j < n; ++j) {
      Stream s(77, Purpose::test, i, j);
      const Vec3 u = uniform_on_sphere(s.uniform0(), s.uniform0());
      if (-u.z() > best) best = -u.z(), bu = u;
    }
    x.push_back(R * std::hypot(bu.x(), bu.y()));
  }
  std::sort(x.begin(), x.end());
  EXPECT_GT(ks_one_sample(x, exact_sphere_rxy(n, R).cdf).p, 1e-3);
  // ... and Eq. 14 is visibly wrong at N = 5 (flat cap and Poisson both fail).
  EXPECT_LT(ks_one_sample(x, eq14_rxy(n, R).cdf).p, 1e-6);
}

TEST(Theory, ExactLawsAreSelfConsistent) {
  for (std::uint64_t n : {10u, 1000u, 100000u}) {
    const double sigma = 1 / std::sqrt(2 * std::numbers::pi * areal_density(n, R));
    const double hi = std::min(R * 0.999, 5 * sigma);
    expect_pdf_is_cdf_derivative(exact_sphere_rxy(n, R), 0, hi, 1e-5);
    const Law rx = exact_sphere_rx(n, R);
    expect_pdf_is_cdf_derivative(rx, -hi, hi, 1e-4);
    EXPECT_NEAR(rx.cdf(0), 0.5, 1e-12);
    EXPECT_NEAR(rx.cdf(-sigma) + rx.cdf(sigma), 1.0, 1e-12);
  }
}

TEST(Theory, ExactLawApproachesEq14LikeOneOverN) {
  // The flat-cap Poisson law is the N -> infinity limit at fixed lambda; the sup distance of the
  // cdfs must fall roughly like 1/N (cap curvature and binomial vs Poisson are both O(1/N)).
  auto sup = [](std::uint64_t n) {
    const Law a = exact_sphere_rxy(n, R), b = eq14_rxy(n, R);
    const double sigma = 1 / std::sqrt(2 * std::numbers::pi * areal_density(n, R));
    double d = 0;
    for (int i = 1; i < 400; ++i) d = std::max(d, std::abs(a.cdf(i * sigma / 50) - b.cdf(i * sigma / 50)));
    return d;
  };
  const double d3 = sup(1000), d5 = sup(100000);
  EXPECT_GT(d3, 1e-5);
  EXPECT_NEAR(d3 / d5, 100.0, 10.0);
}

TEST(Theory, CoreContactProbability) {
  // R (1 - cos theta*) = a: the cap where an asperity centre reaches below the central sphere.
  // Its area fraction is a/(2R), so P(no centre in it) = (1 - a/(2R))^N exactly.
  const double a = 6.5e-7;
  EXPECT_NEAR(core_contact_probability(100000, R, a), std::pow(1 - a / (2 * R), 100000.0), 1e-15);
  // The paper's R* = 2 sqrt(R a) doubles the cap: exp(-N a / R) is the SQUARE of the exact value to
  // leading order, 3.893e-10 at Fig. 3's parameters, not 1e-106; exact is 1.972e-5. Pinned to 1e-3
  // relative, and the square relation checked to its next order: exact^2 / paper =
  // exp(-N (a/2R)^2 + ...) = 1 - 1.2e-3.
  const double pe = core_contact_probability(100000, R, a), pp = core_contact_probability_paper(100000, R, a);
  EXPECT_NEAR(pe, 1.9719e-5, 1e-3 * 1.9719e-5);
  EXPECT_NEAR(pp, 3.8930e-10, 1e-3 * 3.8930e-10);
  EXPECT_NEAR(pe * pe / pp, std::exp(-100000.0 * (a / (2 * R)) * (a / (2 * R))), 1e-6);
}

TEST(Theory, CoreContactProbabilityAgainstMonteCarlo) {
  // Independent of the cap-area formula: N = 40 isotropic points (normalised Gaussian vectors),
  // a chosen so that P(core) ~ 0.37; the core touches iff no point has R (1 - cos theta) <= a,
  // theta its angle from the south pole. 20000 spheres: the count must lie within 4 sd of
  // n (1 - a/2R)^N; the paper's exp(-N a/R) (~0.14 here) is rejected by the same criterion.
  const std::uint64_t N = 40;
  const double aa = 2 * R * (1 - std::pow(0.37, 1.0 / N));
  const int n = 20000;
  int core = 0;
  Stream s(17, Purpose::orientation, 0);
  auto gauss = [&s] { return std::sqrt(-2 * std::log(s.uniform())) * std::cos(2 * std::numbers::pi * s.uniform0()); };
  for (int i = 0; i < n; ++i) {
    bool touched = false;
    for (std::uint64_t j = 0; j < N; ++j) {
      const double x = gauss(), y = gauss(), z = gauss();
      const double cos_theta = -z / std::sqrt(x * x + y * y + z * z);
      touched = touched || R * (1 - cos_theta) <= aa;
    }
    core += touched ? 0 : 1;
  }
  for (auto [p, good] : {std::pair{core_contact_probability(N, R, aa), true}, std::pair{core_contact_probability_paper(N, R, aa), false}}) {
    const double sd = std::sqrt(n * p * (1 - p));
    if (good) EXPECT_LT(std::abs(core - n * p), 4 * sd) << core << " vs " << n * p;
    else EXPECT_GT(std::abs(core - n * p), 4 * sd) << core << " vs " << n * p;
  }
}

TEST(Theory, QuenchedDeviationScalesAsOneOverSqrtN) {
  const double s1 = quenched_deviation_scale(1000), s2 = quenched_deviation_scale(100000);
  EXPECT_NEAR(s1 / s2, 10.0, 0.01);
  // 0.233/sqrt(N) for exactly N centres; a Poisson number of centres would give 0.42/sqrt(N): the
  // count fluctuation is removed (checked against 5 explicit spheres by bench/runtime_vs_error).
  EXPECT_NEAR(s1 * std::sqrt(1000.0), 0.233, 0.005);
}

}  // namespace

// KL(exact || Eq. 14) per drop, the finite-N correction as a law of N (docs/science-finite-n.md):
// the quadrature in s = sin^2(theta/2) against the direct integral of f log(f/g) over r_xy, and
// its large-N law 9/N^2. The direct integral of a 1 % wider Rayleigh differs by far more than the
// tolerance, so the agreement is not a property of any two nearby laws.
TEST(Theory, KlOfExactLawFromEq14MatchesTheDirectIntegralAndFallsAs9OverNSquared) {
  const double R = 3e-3;
  // At N = 5 the direct integrand has an inverse-square-root singularity at r_xy = R (the exact
  // density there), which the quadrature resolves to ~3e-4 only; from N = 50 on it is negligible.
  for (std::uint64_t n : {5ull, 50ull, 1000ull, 10000ull, 100000ull}) {
    const double kl = kl_exact_eq14(n), direct = kl_exact_eq14_direct(n, R);
    EXPECT_NEAR(kl, direct, (n < 50 ? 1e-3 : 1e-4) * kl) << "N = " << n;
    EXPECT_GT(kl, 0) << n;
  }
  // Independent of R (the law of s does not involve it).
  EXPECT_NEAR(kl_exact_eq14_direct(1000, 1.0), kl_exact_eq14(1000), 1e-4 * kl_exact_eq14(1000));
  for (std::uint64_t n : {100000ull, 1000000ull, 10000000ull}) {
    const double N = static_cast<double>(n);
    EXPECT_NEAR(kl_exact_eq14(n) * N * N, 9.0, 60.0 / N) << "N = " << n;  // 9 (1 + O(1/N))
  }
  // A wrong second law moves the direct integral by far more than the tolerance above.
  const Law e = exact_sphere_rxy(1000, R), wide = eq14_rxy(1000, R, 1.01);
  const double wrong = GK::integrate(
      [&](double t) { const double a = e.pdf(t), b = wide.pdf(t); return a > 0 && b > 0 ? a * std::log(a / b) : 0.0; },
      0.0, 2e-3, 15, 1e-12);
  EXPECT_GT(std::abs(wrong - kl_exact_eq14(1000)), 10.0 * kl_exact_eq14(1000));
  // Drops for an expected z: z^2 / (2 KL), i.e. ~ z^2 N^2 / 18.
  EXPECT_NEAR(lr_drops_for_z(10000, 5.0), 25.0 / (2.0 * kl_exact_eq14(10000)), 1e-6);
  EXPECT_THROW(kl_exact_eq14(1), std::invalid_argument);
}
