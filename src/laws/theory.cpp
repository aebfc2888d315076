// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/laws/theory.hpp"

#include <cmath>
// Boost 1.74's pchip calls isnan unqualified from a template; make it visible (fixed upstream later).
using std::isnan;
#include "laws/theory_detail.hpp"
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/special_functions/erf.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <tuple>

namespace asperity {

namespace {
constexpr double pi = std::numbers::pi;

void check(std::uint64_t n, double R) {
  if (n < 1) throw std::invalid_argument("law: N must be >= 1");
  if (!(R > 0) || !std::isfinite(R)) throw std::invalid_argument("law: R must be finite and > 0");
}

// For s = t/R in [0,1]: x = (1 - c)/2 with c = sqrt(1 - s^2), without cancellation.
double half_versine(double s) {
  const double c = std::sqrt((1.0 - s) * (1.0 + s));
  return 0.5 * s * s / (1.0 + c);
}

struct ExactRxy {
  double n, R;
  // Survival S(t) = ((1+c)/2)^N - ((1-c)/2)^N = (1-x)^N - x^N.
  double survival(double t) const {
    if (t <= 0) return 1.0;
    if (t >= R) return 0.0;
    const double x = half_versine(t / R);
    const double far = x > 0 ? std::exp(n * std::log(x)) : 0.0;
    return std::exp(n * std::log1p(-x)) - far;
  }
  double pdf(double t) const {
    if (t <= 0 || t >= R) return 0.0;
    const double s = t / R, c = std::sqrt((1.0 - s) * (1.0 + s));
    const double x = half_versine(s);
    const double far = x > 0 ? std::exp((n - 1) * std::log(x)) : (n == 1 ? 1.0 : 0.0);
    // dF/dt = N [(1-x)^(N-1) + x^(N-1)] dx/dt, dx/dt = s / (2 c R).
    return n * (std::exp((n - 1) * std::log1p(-x)) + far) * s / (2.0 * c * R);
  }
};
}  // namespace

double areal_density(std::uint64_t n, double R) { return static_cast<double>(n) / (4.0 * pi * R * R); }

Law eq14_rxy(std::uint64_t n, double R, double scale) {
  check(n, R);
  // With scale s: sigma -> s sigma, i.e. lambda -> lambda / s^2.
  const double lam = areal_density(n, R) / (scale * scale);
  Law law;
  law.name = scale == 1.0 ? "eq14" : "eq14-x" + std::to_string(scale);
  law.description = "Eq. 14: Rayleigh, flat cap + Poisson, sigma^2 = 1/(2 pi lambda)";
  law.cdf = [lam](double t) { return t <= 0 ? 0.0 : -std::expm1(-lam * pi * t * t); };
  law.pdf = [lam](double t) { return t < 0 ? 0.0 : 2.0 * pi * lam * t * std::exp(-lam * pi * t * t); };
  law.mean = std::sqrt(pi / 2.0) / std::sqrt(2.0 * pi * lam);  // sigma sqrt(pi/2)
  return law;
}

Law exact_sphere_rxy(std::uint64_t n, double R) {
  check(n, R);
  const ExactRxy e{static_cast<double>(n), R};
  Law law;
  law.name = "exact-sphere";
  law.description = "exact finite-N law on the sphere: P(theta_min > theta) = ((1+cos theta)/2)^N";
  law.cdf = [e](double t) { return 1.0 - e.survival(t); };
  law.pdf = [e](double t) { return e.pdf(t); };
  // E[r_xy] = int_0^R S(t) dt; S is negligible beyond ~12 sigma of the flat law for large N.
  const double hi = std::min(R, 12.0 / std::sqrt(2.0 * pi * areal_density(n, R)));
  law.mean = boost::math::quadrature::gauss_kronrod<double, 31>::integrate([e](double t) { return e.survival(t); }, 0.0,
                                                                            hi, 10, 1e-12);
  return law;
}

Law eq18_rx(std::uint64_t n, double R, double scale) {
  check(n, R);
  const double sigma = scale / std::sqrt(2.0 * pi * areal_density(n, R));
  Law law = detail::centred_gaussian(sigma);
  law.name = scale == 1.0 ? "eq18" : "eq18-x" + std::to_string(scale);
  law.description = "Eq. 18: Gaussian, p(t) = sqrt(lambda) exp(-pi lambda t^2)";
  return law;
}

namespace {
// Upper tail mass (1/pi) int_0^{pi/2} S(t/cos phi) dphi of r_x for t >= 0.
double rx_tail(const ExactRxy& e, double t) {
  if (t >= e.R) return 0.0;
  // Beyond phi* = acos(t/R) the integrand vanishes: integrate on [0, phi*] only (no kink).
  const double phi_max = std::acos(t / e.R);
  auto f = [&](double phi) { return e.survival(t / std::cos(phi)); };
  const double v = boost::math::quadrature::gauss_kronrod<double, 31>::integrate(f, 0.0, phi_max, 8, 1e-12);
  return v / pi;
}
double rx_density(const ExactRxy& e, double t) {
  t = std::abs(t);
  if (t >= e.R) return 0.0;
  // p(t) = (1/pi) int_t^R f(u)/sqrt(u^2 - t^2) du; with u = sqrt(t^2 + v^2) the integrand
  // f(u)/u is smooth and finite, also at t = 0.
  auto f = [&](double v) {
    const double u = std::hypot(t, v);
    return u > 0 ? e.pdf(u) / u : 0.0;
  };
  const double v_max = std::sqrt((e.R - t) * (e.R + t));
  return boost::math::quadrature::gauss_kronrod<double, 31>::integrate(f, 0.0, v_max, 15, 1e-11) / pi;
}
}  // namespace

Law exact_sphere_rx(std::uint64_t n, double R) {
  check(n, R);
  // The table costs ~3000 quadratures (~0.1 s): the last one is kept (analysis and figures of a
  // run ask for the same law). A Law is immutable, so sharing it is safe.
  static std::mutex mutex;
  static std::optional<std::tuple<std::uint64_t, double, Law>> last;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (last && std::get<0>(*last) == n && std::get<1>(*last) == R) return std::get<2>(*last);
  }
  const ExactRxy e{static_cast<double>(n), R};
  // Tabulate the tail on [0, t_max]: t_max = 12 sigma of the flat law (tail < 1e-30 there for
  // large N) but never beyond R. Outside the table the quadrature is used directly.
  const double sigma = 1.0 / std::sqrt(2.0 * pi * areal_density(n, R));
  const double t_max = std::min(R, 12.0 * sigma);
  const auto table = detail::tabulate_tail(t_max, 3001, [&](double t) { return rx_tail(e, t); });
  Law law;
  law.name = "exact-sphere";
  law.description = "exact finite-N law of r_x = r_xy cos(phi) on the sphere (quadrature)";
  law.cdf = [e, table, t_max](double t) {
    const double a = std::abs(t);
    const double tail = a <= t_max ? (*table)(a) : rx_tail(e, a);
    return t >= 0 ? 1.0 - tail : tail;
  };
  law.pdf = [e](double t) { return rx_density(e, t); };
  std::lock_guard<std::mutex> lock(mutex);
  last.emplace(n, R, law);
  return law;
}

double model_error_scale(std::uint64_t n, double R) {
  const Law a = eq14_rxy(n, R), b = exact_sphere_rxy(n, R);
  const double hi = std::min(R, 12.0 / std::sqrt(2.0 * pi * areal_density(n, R)));
  double d = 0;
  for (int i = 1; i <= 4000; ++i) {
    const double t = hi * i / 4000.0;
    d = std::max(d, std::abs(a.cdf(t) - b.cdf(t)));
  }
  return d;
}

namespace {
// The log ratio r = log(p/q) of the folded s = sin^2(theta/2) on [0, 1/2] (kl_exact_eq14):
// p = N (1-s)^(N-1) (1 + (s/(1-s))^(N-1)), q = N (1 - 2s) exp(-N s (1-s)); the O(1) terms of
// (N-1) log(1-s) + N s (1-s) cancel to O(1/N), so they are grouped before adding.
double kl_log_ratio(double n, double s) {
  const double fold = s > 0 ? std::exp((n - 1) * std::log(s / (1.0 - s))) : (n == 1 ? 1.0 : 0.0);
  return (n - 1) * (std::log1p(-s) + s) + s - n * s * s + std::log1p(fold) - std::log1p(-2.0 * s);
}
}  // namespace

double kl_exact_eq14(std::uint64_t n_int) {
  if (n_int < 2) throw std::invalid_argument("kl_exact_eq14: N must be >= 2");
  const double n = static_cast<double>(n_int);
  // KL = int p log(p/q) = int [p log(p/q) - p + q] + int (p - q); the first integrand is
  // q (1 + (r - 1) e^r) ~ q r^2 / 2 >= 0 (no cancellation between large terms), the second is
  // 1 - (1 - exp(-N/4)) exactly (p has mass 1 on [0, 1/2], q its Rayleigh mass below t = R).
  auto term = [n](double s) {
    if (s >= 0.5) return 0.0;
    const double r = kl_log_ratio(n, s);
    const double q = n * (1.0 - 2.0 * s) * std::exp(-n * s * (1.0 - s));
    const double em1 = std::expm1(r);
    const double p = q * (1.0 + em1);
    if (!(q > 0)) return 0.0;                 // q underflowed: p (<= q e^r) is negligible there too
    if (std::abs(r) > 0.5) return p * r - p + q;  // no cancellation to avoid
    return q * (r * em1 + (r - em1));
  };
  double sum = 0, lo = 0;
  for (int k = 1; lo < 0.5 && k <= 96; ++k) {  // pieces of width 1/N: p and q vary on that scale
    const double hi = std::min(0.5, k / n);
    sum += boost::math::quadrature::gauss_kronrod<double, 31>::integrate(term, lo, hi, 6, 1e-11);
    lo = hi;
  }
  if (lo < 0.5) sum += boost::math::quadrature::gauss_kronrod<double, 31>::integrate(term, lo, 0.5, 10, 1e-11);
  return sum + std::exp(-n / 4.0);
}

double kl_exact_eq14_direct(std::uint64_t n, double R) {
  const Law e = exact_sphere_rxy(n, R), q = eq14_rxy(n, R);
  auto f = [&](double t) {
    const double pe = e.pdf(t), pq = q.pdf(t);
    return pe > 0 && pq > 0 ? pe * std::log(pe / pq) : 0.0;
  };
  const double sigma = 1.0 / std::sqrt(2.0 * pi * areal_density(n, R));
  const double hi = std::min(R, 14.0 * sigma);
  double sum = 0, lo = 0;
  for (int k = 1; lo < hi; ++k) {
    const double b = std::min(hi, k * 0.25 * sigma);
    sum += boost::math::quadrature::gauss_kronrod<double, 61>::integrate(f, lo, b, 8, 1e-10);
    lo = b;
  }
  return sum;
}

double lr_drops_for_z(std::uint64_t n, double z) { return z * z / (2.0 * kl_exact_eq14(n)); }

double core_contact_probability(std::uint64_t n, double R, double a) {
  return std::exp(static_cast<double>(n) * std::log1p(-a / (2.0 * R)));
}

double core_contact_probability_paper(std::uint64_t n, double R, double a) {
  return std::exp(-static_cast<double>(n) * a / R);
}

}  // namespace asperity

namespace asperity {

double quenched_cdf_sd(std::uint64_t n, double mu) {
  if (mu <= 0) return 0.0;
  auto lens = [](double u) {  // overlap of two unit disks whose centres are u apart
    return u >= 2 ? 0.0 : 2.0 * std::acos(0.5 * u) - 0.5 * u * std::sqrt(4.0 - u * u);
  };
  auto g = [&](double u) { return u * std::expm1(mu * lens(u) / pi); };
  const double G = 2.0 * boost::math::quadrature::gauss_kronrod<double, 31>::integrate(g, 0.0, 2.0, 15, 1e-10);
  // Law of total variance: a Poisson process is a mixture over the count; one sphere has exactly
  // N centres, so the part due to a random count, (d E[F]/dN)^2 Var(N) = (mu e^{-mu})^2 / N, is
  // removed. (G >= mu, so the difference is never negative.)
  const double e = std::exp(-mu);
  const double var = (mu * e * e * G - mu * mu * e * e) / static_cast<double>(n);
  return std::sqrt(std::max(0.0, var));
}

double quenched_deviation_scale(std::uint64_t n) {
  double best = 0;
  for (double mu = 0.01; mu < 8.0; mu += 0.01) best = std::max(best, quenched_cdf_sd(n, mu));
  return best;
}

}  // namespace asperity
