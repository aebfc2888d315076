// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Analytic laws for the contact vector of a rough sphere (paper Sec. III), each as a value with
// a pdf and a cdf, so that tests, plots and reports can treat laws uniformly.
//
// Notation: N asperities with centres uniform on a central sphere of radius R; a = asperity
// radius; lambda = N/(4 pi R^2) is the areal density. theta_min = polar angle of the centre
// nearest to the south pole; r_xy = R sin(theta_min); r_x = r_xy cos(phi), phi uniform.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "asperity/laws/statistics.hpp"

namespace asperity {

/// A one-dimensional law with a continuous cdf.
struct Law {
  std::string name;         ///< report name, e.g. "eq14", "exact-sphere", "eq18"
  std::string description;  ///< one line for humans
  Cdf cdf;                  ///< F(x) = P(X <= x), right-continuous (atoms included)
  /// Density (of the continuous part, for a law with an atom): what the figures overlay.
  std::function<double(double)> pdf;
  double mean = 0;          ///< expectation of the law [same unit as its variable]
};

/// lambda = N / (4 pi R^2) [1/m^2]
double areal_density(std::uint64_t n, double R);

/// Paper Eq. 13/14: flat cap, Poisson points: F(t) = 1 - exp(-lambda pi t^2) (Rayleigh with
/// sigma^2 = 1/(2 pi lambda)). `scale` multiplies the Rayleigh scale (1 = the paper's law; tests
/// use 1.05 as a deliberately wrong law).
Law eq14_rxy(std::uint64_t n, double R, double scale = 1.0);

/// Exact finite-N law of r_xy on the sphere: P(theta_min > theta) = ((1+cos theta)/2)^N, and
/// r_xy = R sin(theta_min) folds theta_min > pi/2 back, so
/// F(t) = 1 - ((1+c)/2)^N + ((1-c)/2)^N with c = sqrt(1 - t^2/R^2), 0 <= t <= R.
/// Evaluated with log1p so that it is accurate for N up to 2^32 and t << R.
Law exact_sphere_rxy(std::uint64_t n, double R);

/// Paper Eq. 18 (its final line): r_x ~ Normal(0, sigma^2), sigma^2 = 1/(2 pi lambda), i.e.
/// p(t) = sqrt(lambda) exp(-pi lambda t^2). `scale` multiplies sigma.
Law eq18_rx(std::uint64_t n, double R, double scale = 1.0);

/// Exact finite-N law of r_x = r_xy cos(phi) with r_xy from exact_sphere_rxy:
/// F(t) = 1 - (1/pi) int_0^{pi/2} S(t / cos phi) dphi for t >= 0 (S = 1 - F_rxy), symmetric.
/// Evaluated by adaptive Gauss-Kronrod quadrature, tabulated once (pchip, |error| < 1e-9 in the
/// bulk) so that a KS test over 10^6 samples costs no quadrature per sample.
Law exact_sphere_rx(std::uint64_t n, double R);

/// KS distance between Eq. 14 and the exact finite-N law of r_xy, sup_t |F_eq14(t) - F_exact(t)|
/// (on 4000 points up to 12 sigma): the model error of the paper's flat-cap Poisson approximation.
double model_error_scale(std::uint64_t n, double R);

/// Kullback-Leibler divergence KL(exact || Eq. 14) of r_xy per drop [nats]: the expected log
/// likelihood ratio of one drop when the exact finite-N law holds, the quantity the likelihood-ratio
/// test of a streaming run measures. In s = sin^2(theta/2) (r_xy = 2R sqrt(s (1 - s)), monotone on
/// s <= 1/2) the exact law of the folded s is N (1-s)^(N-1) + N s^(N-1) and Eq. 14's is
/// N (1 - 2s) exp(-N s (1 - s)) (Eq. 14's mass beyond r_xy = R, exp(-N/4), is not reached by the
/// exact law and does not enter this direction); the integral over s in [0, 1/2] is done by
/// Gauss-Kronrod quadrature on pieces of width ~1/N. For large N it is 9/N^2 (1 + O(1/N))
/// (docs/science-finite-n.md derives it); independent of R. Throws for n < 2.
double kl_exact_eq14(std::uint64_t n);
/// The same divergence by direct numerical integration over r_xy of the two laws' densities,
/// int f_exact log(f_exact / f_eq14) dt (the check of kl_exact_eq14; slower, less accurate for N > 10^6).
double kl_exact_eq14_direct(std::uint64_t n, double R);
/// Drops an iid likelihood-ratio test needs for an expected z of the test of Eq. 14 when the exact
/// law holds: E[z] = 2 KL sqrt(n) / sd, with sd^2 ~ 2 KL for a small divergence, so n = z^2 / (2 KL).
double lr_drops_for_z(std::uint64_t n, double z);

/// Probability that the bare central sphere touches the plate before any asperity, for a fresh
/// random sphere: no centre within polar angle theta* of the pole, where
/// R (1 - cos theta*) = a. Exactly (1 - a/(2R))^N.
double core_contact_probability(std::uint64_t n, double R, double a);

/// The paper's estimate of the same probability (Sec. III B): exp(-lambda pi R*^2) with
/// R* = 2 sqrt(R a), i.e. exp(-N a / R). Kept to report next to the exact value.
double core_contact_probability_paper(std::uint64_t n, double R, double a);

}  // namespace asperity

namespace asperity {

/// Standard deviation, over random spheres, of ONE sphere's own (quenched) cdf of r_xy at the
/// point where the ensemble cdf equals 1 - exp(-mu) (mu = lambda pi t^2), in the flat Poisson
/// (Boolean-model) approximation for exactly N centres: Var = (mu e^{-2 mu} G(mu) - mu^2 e^{-2 mu})/N
/// (the second term removes the count fluctuation of a Poisson process), with
/// G(mu) = 2 int_0^2 u (exp(mu L(u)/pi) - 1) du and L(u) the overlap area of two unit disks at
/// distance u. Rotations of one sphere converge to that sphere's law, which differs from the
/// ensemble law by about this much: a KS test with many more rotations than ~1/sd^2 must reject.
double quenched_cdf_sd(std::uint64_t n, double mu);
/// max over mu of quenched_cdf_sd: the typical size of the quenched deviation of one sphere.
double quenched_deviation_scale(std::uint64_t n);

}  // namespace asperity
