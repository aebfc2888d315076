// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/laws/theory_radii.hpp"

#include <cmath>
// Boost 1.74's pchip calls isnan unqualified from a template; make it visible (fixed upstream later).
using std::isnan;
#include "laws/theory_detail.hpp"
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/special_functions/erf.hpp>

#include <algorithm>
#include <memory>
#include <numbers>
#include <stdexcept>

#include "core/format.hpp"

#include "asperity/core/random.hpp"

namespace asperity {
namespace {

constexpr double pi = std::numbers::pi;

struct Levels {
  std::vector<double> rho, f;
};

Levels levels_of(const RadiusDistribution& d) {
  validate(d);
  Levels l;
  if (d.kind == RadiusDistribution::Kind::fixed) {
    l.rho = {d.radius};
    l.f = {1.0};
  } else if (d.kind == RadiusDistribution::Kind::levels) {
    for (std::size_t i = 0; i < d.levels.size(); ++i)
      if (d.fractions[i] > 0) l.rho.push_back(d.levels[i]), l.f.push_back(d.fractions[i]);
  } else {
    throw std::invalid_argument("exact laws and fresh spheres need fixed or level radii, got " + d.describe());
  }
  return l;
}

void check(std::uint64_t n, double R, const Levels& l) {
  if (n < 1) throw std::invalid_argument("N must be >= 1, got 0");
  const double rmax = *std::max_element(l.rho.begin(), l.rho.end());
  if (!(R > rmax) || !std::isfinite(R))
    throw std::invalid_argument("radius must be finite and larger than every asperity radius, got " + detail::num(R));
}

// P(X_win > x) by the closed form on each linear piece of 1 - G_k.
struct ExactLevels {
  double n, R;
  Levels l;

  double one_minus_G(std::size_t k, double x) const {
    double g = 0;
    for (std::size_t m = 0; m < l.rho.size(); ++m)
      g += l.f[m] * std::clamp(x + (l.rho[m] - l.rho[k]) / (2.0 * R), 0.0, 1.0);
    return std::max(0.0, 1.0 - g);
  }
  double powN(double base, double e) const { return base > 0 ? std::exp(e * std::log(base)) : 0.0; }

  double survival_x(double x) const {
    if (x <= 0) return 1.0;
    if (x >= 1) return 0.0;
    double total = 0;
    for (std::size_t k = 0; k < l.rho.size(); ++k) {
      std::vector<double> cuts{x, 1.0};
      for (std::size_t m = 0; m < l.rho.size(); ++m) {
        const double delta = (l.rho[m] - l.rho[k]) / (2.0 * R);
        for (double c : {-delta, 1.0 - delta})
          if (c > x && c < 1.0) cuts.push_back(c);
      }
      std::sort(cuts.begin(), cuts.end());
      for (std::size_t p = 0; p + 1 < cuts.size(); ++p) {
        const double x1 = cuts[p], x2 = cuts[p + 1];
        if (!(x2 > x1)) continue;
        const double a1 = one_minus_G(k, x1), a2 = one_minus_G(k, x2);
        const double beta = (a1 - a2) / (x2 - x1);  // slope of G on this piece, >= f_k > 0
        // N f_k int (1-G)^(N-1) = f_k (a1^N - a2^N)/beta
        if (beta > 1e-300) total += l.f[k] * (powN(a1, n) - powN(a2, n)) / beta;
        else total += n * l.f[k] * powN(a1, n - 1) * (x2 - x1);
      }
    }
    return std::clamp(total, 0.0, 1.0);
  }
  // r_xy <= t  <=>  X <= x(t) or X >= 1 - x(t).
  double survival_rxy(double t) const {
    if (t <= 0) return 1.0;
    if (t >= R) return 0.0;
    const double s = t / R, c = std::sqrt((1.0 - s) * (1.0 + s));
    const double x = 0.5 * s * s / (1.0 + c);
    return std::max(0.0, survival_x(x) - survival_x(1.0 - x));
  }
};

double rx_tail(const ExactLevels& e, double t) {
  if (t >= e.R) return 0.0;
  const double phi_max = std::acos(t / e.R);
  auto f = [&](double phi) { return e.survival_rxy(t / std::cos(phi)); };
  return boost::math::quadrature::gauss_kronrod<double, 31>::integrate(f, 0.0, phi_max, 8, 1e-12) / pi;
}

}  // namespace

FreshContact fresh_levels_contact(std::uint64_t n, double R, const RadiusDistribution& d, std::uint64_t seed,
                                  std::uint64_t drop) {
  const Levels l = levels_of(d);
  check(n, R, l);
  std::vector<double> cum(l.f.size());
  double acc = 0;
  for (std::size_t m = 0; m < l.f.size(); ++m) cum[m] = (acc += l.f[m]);
  const double rho_max = *std::max_element(l.rho.begin(), l.rho.end());
  Stream s(seed, Purpose::fresh, drop, 7);
  FreshContact c;
  double x = 0, best = -std::numeric_limits<double>::infinity(), best_x = 0, best_phi = 0;
  for (std::uint64_t k = 0; k < n; ++k) {
    // X_(k+1) = X_(k) + (1 - X_(k)) (1 - U^(1/(N-k))).
    const double u = s.uniform();
    x += (1.0 - x) * -std::expm1(std::log(u) / static_cast<double>(n - k));
    if (rho_max - 2.0 * R * x < best) break;  // no later asperity can reach lower
    const double v = s.uniform0(), phi = 2.0 * pi * s.uniform0();
    std::uint32_t m = 0;
    while (m + 1 < cum.size() && v >= cum[m]) ++m;
    ++c.examined;
    const double score = l.rho[m] - 2.0 * R * x;
    if (score > best) best = score, best_x = x, best_phi = phi, c.level = m, c.rho = l.rho[m];
  }
  const double sin_t = 2.0 * std::sqrt(best_x * (1.0 - best_x)), cos_t = 1.0 - 2.0 * best_x;
  c.r = Vec3(R * sin_t * std::cos(best_phi), R * sin_t * std::sin(best_phi), -R * cos_t - c.rho);
  c.core = best < 0;
  return c;
}

Law levels_sphere_rxy(std::uint64_t n, double R, const RadiusDistribution& d) {
  const Levels l = levels_of(d);
  check(n, R, l);
  const auto e = std::make_shared<ExactLevels>(ExactLevels{static_cast<double>(n), R, l});
  Law law;
  law.name = "exact-levels";
  law.description = "exact finite-N law of r_xy with level radii " + d.describe();
  law.cdf = [e](double t) { return 1.0 - e->survival_rxy(t); };
  law.pdf = [e](double t) {
    const double h = std::max(1e-12, 1e-5 * t);
    return (e->survival_rxy(t - h) - e->survival_rxy(t + h)) / (2 * h);
  };
  return law;
}

Law levels_sphere_rx(std::uint64_t n, double R, const RadiusDistribution& d, double scale) {
  const Levels l = levels_of(d);
  check(n, R, l);
  const ExactLevels e{static_cast<double>(n), R, l};
  // Table on [0, t_max]: 12 sigma of the flat law of the SMALLEST level density's Gaussian covers
  // every level's tail.
  double fmin = 1.0;
  for (double f : l.f) fmin = std::min(fmin, f);
  const double lam = static_cast<double>(n) * fmin / (4.0 * pi * R * R);
  const double t_max = std::min(R, 12.0 / std::sqrt(2.0 * pi * lam));
  const auto table = detail::tabulate_tail(t_max, 801, [&](double t) { return rx_tail(e, t); });
  Law law;
  law.name = scale == 1.0 ? "exact-levels" : "exact-levels-x" + detail::num(scale);
  law.description = "exact finite-N law of r_x with level radii " + d.describe() + " (quadrature)";
  law.cdf = [table, t_max, scale](double t) {
    const double a = std::abs(t) / scale;
    const double tail = a <= t_max ? std::max(0.0, (*table)(a)) : 0.0;
    return t >= 0 ? 1.0 - tail : tail;
  };
  law.pdf = [table, t_max, scale](double t) {
    const double a = std::abs(t) / scale;
    return a < t_max ? -table->prime(a) / scale : 0.0;
  };
  return law;
}

Law gaussian_rx(double lambda, std::string name) {
  if (!(lambda > 0) || !std::isfinite(lambda))
    throw std::invalid_argument("areal density must be finite and > 0, got " + detail::num(lambda));
  const double sigma = 1.0 / std::sqrt(2.0 * pi * lambda);
  Law law = detail::centred_gaussian(sigma);
  law.name = std::move(name);
  law.description = "Gaussian, sigma^2 = 1/(2 pi lambda), lambda = " + detail::num(lambda) + " 1/m^2";
  return law;
}

}  // namespace asperity
