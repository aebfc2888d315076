// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Laws of the paper's Sec. IV for the macroscopic restitution coefficient eps and the spin after
// the impact, each "as printed" and "as corrected" (derivations in docs/sec4-derivations.md).
//
// Frame (impact.hpp): z up, plate normal n = +z, the body approaches with V = (0, 0, -u), u > 0,
// spin Omega = (Omega_x, Omega_y, 0). Contact vector r = (r_x, r_y, r_z), r_z ~ -(R + a); the
// flat-cap Poisson model of Sec. III gives r_x, r_y iid Normal(0, sigma^2), sigma^2 = 1/(2 pi lambda).
// Mass properties: J = (2/5) M R^2 (central sphere), I_g = J/M = (2/5) R^2. eps_t = 1.
//
// Corrected laws (exact solve of Eq. 7 with eps_t = 1, expanded to the order that matters):
//   eps     = eps_n(u) + b^2/(4 alpha) - alpha W,   W = (r_perp + b/(2 alpha))^2 + r_par^2,
//             W/sigma^2 ~ noncentral chi-square(2 dof, (b/(2 alpha))^2/sigma^2),
//             alpha = (1 + eps_n(u))/(I_g + (R+a)^2),  b = |Omega| ((1 + eps_n(u))/u + eps_n'(u)),
//             r_perp = r . (-Omega_y, Omega_x)/|Omega|, r_par the other component;
//   Omega'_x ~ Normal(Omega_x, sigma_c^2),  sigma_c = (1 + eps_n(u)) u sigma/(I_g + (R+a)^2).
// By default (core_contacts = false, the paper's model) the lowest asperity always touches. With
// core_contacts = true the bare central sphere touches when no asperity centre lies within the
// polar angle theta* of the pole, R (1 - cos theta*) = a, i.e. when r_xy > r* = sqrt(2 a R - a^2):
// probability p0 = exp(-r*^2/(2 sigma^2)) (= exp(-5) = 0.67% at Fig. 5's a = 1e-4 R). Such a
// contact is central (r = (0, 0, -R)): eps = eps_n(u) and Omega' = Omega exactly. The law is then
// a mixture with an atom of mass p0 at that value; its cdf is right-continuous. A one-sample KS
// test assumes a continuous cdf: test samples against such a law with the randomized probability
// integral transform at the atom (tests/test_theory_impact.cpp shows how).
//
// Printed laws follow the paper literally (paper frame: z along n into the plate, V_z = +u,
// Omega_x = omega_x as given, I = J/M, r_z = R + a, eps_n = eps_n(u)); Eq. 28 as printed is not a
// density: its Law is the printed pdf divided by its (signed) integral over its real support,
// and its description states the raw integral.
#include <cstdint>
#include <string>
#include <vector>

#include "asperity/core/restitution.hpp"
#include "asperity/laws/theory.hpp"

namespace asperity {

/// The scene of the Sec. IV laws: one rough sphere hitting the plate at normal incidence with
/// spin, with the paper's viscoelastic eps_n(v) (Pade [1/4], restitution.hpp). Frame as in the
/// file's comment; validate() checks it.
struct ImpactScene {
  std::uint64_t asperities = 100000;  ///< N
  double radius = 3e-3;               ///< R [m]
  double asperity_radius = 6.5e-7;    ///< a [m]
  double speed = 1.3;                 ///< u = -V.n > 0 [m/s]
  double omega_x = 0.2;               ///< [rad/s]
  double omega_y = 0.0;               ///< [rad/s]
  double beta = 0.0467;               ///< Pade [1/4] material constant [(s/m)^(1/5)]
  bool core_contacts = false;         ///< corrected laws only: include bare-sphere contacts (atom of mass p0)
  /// Eq. 23 read literally: J = (2/5) M rho^2 with rho the ASPERITY radius, I_g = (2/5) a^2 (the
  /// default, and the code's physics, is the central sphere's J = (2/5) M R^2; the asperities add
  /// ~N (a/R)^3 to it). For the README's table and a test that explicit geometry rejects it.
  bool literal_eq23 = false;
};

/// Throws std::invalid_argument naming the field: N >= 1, R > 0, 0 <= a < R, u > 0, beta > 0,
/// all finite.
void validate(const ImpactScene& s);

/// Distribution of eps. Names: "eq28-printed", "eq28-corrected".
/// `alpha_scale` multiplies alpha (1 = the law; tests use 1.05 as a deliberately wrong law).
Law eq28_printed(const ImpactScene& s);
/// The corrected law of eps (see the file's comment), with the core-contact atom if
/// s.core_contacts; alpha_scale as above. Name "eq28-corrected".
Law eq28_corrected(const ImpactScene& s, double alpha_scale = 1.0);

/// The paper's own route (Eqs. 26-27: r_x + r_y ~ r_xy Rayleigh, r_z = R + a constant) carried
/// out correctly: eps(s) = -1 + Q (u + Omega_x s)/(u (s^2 + c^2)), c^2 = I_g + r_z^2,
/// Q = (1 + eps_n(u)) c^2, s ~ Rayleigh(sigma), with every non-negative preimage of eps(s) (two
/// when Omega_x > 0). Paper frame as for eq28_printed (omega_x as given, omega_y unused).
/// Name: "eq28-paper-route".
Law eq28_paper_route(const ImpactScene& s);

/// Distribution of Omega'_x. Names: "eq33-printed", "eq33-corrected" (Gaussians; the corrected
/// one with an atom at Omega_x if core_contacts). `sigma_scale` multiplies sigma_c.
Law eq33_printed(const ImpactScene& s);
/// Normal(Omega_x, sigma_c^2), with an atom at Omega_x if s.core_contacts. Name "eq33-corrected".
Law eq33_corrected(const ImpactScene& s, double sigma_scale = 1.0);

/// Numbers behind the laws (SI), for reports, tests and docs/sec4-derivations.md.
struct ImpactLawParameters {
  double lambda = 0;     ///< N/(4 pi R^2) [1/m^2]
  double sigma = 0;      ///< sqrt(1/(2 pi lambda)) [m]
  double inertia = 0;    ///< I_g = (2/5) R^2 [m^2]
  double c2 = 0;         ///< I_g + (R + a)^2 [m^2]
  double eps_n = 0;      ///< eps_n(u)
  double eps_n_prime = 0;  ///< d eps_n/dv at u [s/m]
  double alpha = 0;      ///< (1 + eps_n)/c2 [1/m^2]
  double b = 0;          ///< |Omega| ((1 + eps_n)/u + eps_n') [1/m]
  double shift = 0;      ///< b/(2 alpha) [m]
  double noncentrality = 0;  ///< (shift/sigma)^2
  double eps_max = 0;    ///< eps_n + b^2/(4 alpha): the supremum of eps (asperity contacts)
  double sigma_c = 0;    ///< corrected std of Omega'_x [rad/s]
  double sigma_printed = 0;  ///< Eq. 33 as printed (I -> J in the prefactor) [rad/s]
  double r_star = 0;     ///< sqrt(2 a R - a^2): r_xy beyond which the core touches [m]
  double p_core = 0;     ///< exp(-r*^2/(2 sigma^2)): probability of a core contact (flat cap)
};
/// The numbers of the scene s at its speed s.speed (validates s).
ImpactLawParameters impact_law_parameters(const ImpactScene& s);
/// The same with eps_n from `eps_n`, which must be viscoelastic_pade14(s.beta) (the same values bit
/// for bit): for callers that evaluate many speeds of one scene (the paper's bounce procedure,
/// once per impact), without building the Pade law each time.
ImpactLawParameters impact_law_parameters(const ImpactScene& s, const Restitution& eps_n);

/// The map of eq28_paper_route for generative use: eps at r_xy = s [m], impact speed u [m/s] and
/// spin Omega_x [rad/s] (paper frame, as given), with eps_n and c^2 from `p` (the scene at speed u):
///   eps = eps_n + (1 + eps_n) s (Omega_x c^2 - u s) / (u (s^2 + c^2)),
/// i.e. -1 + Q (u + Omega_x s)/(u (s^2 + c^2)) written without cancellation. With s ~ Rayleigh(sigma)
/// it draws from eq28-paper-route (both preimages included by construction: Eq. 28 repaired).
double eq28_paper_route_eps(const ImpactLawParameters& p, double u, double omega_x, double s);

/// Semi-analytic law of the residual eps - eps_n(u_k) at impact k of a sequence dropped at speed
/// s.speed without spin, for explicit geometry with independent contacts (derivation:
/// docs/sec4-derivations.md Sec. 11). The spin before impact k is the sum of the kicks
/// -K_j (r_y, -r_x) of impacts j < k, a planar Gaussian with per-component variance
/// S_k^2 = sum_j sigma_c(u_j)^2 (speeds u_{j+1} = u_j (eps_n(u_j) - 2 alpha_j sigma^2), deterministic
/// to ~1e-4). The corrected Eq. 28 gives residual = -alpha (|r|^2 + 2 r.D), D = beta1 Omega/(2 alpha)
/// (rotated by 90 degrees) ~ planar Normal(0, tau^2), tau = beta1 S_k/(2 alpha), independent of r ~
/// planar Normal(0, sigma^2). The quadratic form |r|^2 + 2 r.D has eigenvalues
/// lambda_+- = (sigma^2 +- sqrt(sigma^4 + 4 sigma^2 tau^2))/2, each twice, so
///   residual = a2 E2 - a1 E1,  a1 = 2 alpha lambda_+,  a2 = -2 alpha lambda_-,  E1, E2 ~ Exp(1):
/// exactly the asymmetric Laplace law of Eq. 2 with mode eps_n(u_k), left rate 1/a1, right rate 1/a2
/// (one-sided at k = 1, a2 = 0). Mean -2 alpha sigma^2 at every k.
/// The paper's procedure (Eq. 26 with a signed Omega_x, r_y drawn independently) has, impact by
/// impact, the same marginal with beta1 -> (1 + eps_n)/u: Omega_x s, s ~ Rayleigh, Omega_x ~
/// Normal(0, S_k^2) given s is Normal(0, S_k^2 s^2), as |Omega| r_perp is. `paper_route` selects that.
struct BounceResidualLaw {
  unsigned k = 1;      ///< impact number, 1 for the first
  double speed = 0;    ///< u_k [m/s]
  double eps_n = 0;    ///< eps_n(u_k)
  double spin_sd = 0;  ///< S_k [rad/s]
  double tau = 0;      ///< [m]
  ///@{
  /// Scales below / above the mode [1]: residual = a2 E2 - a1 E1 (a2 = 0 at k = 1).
  double a1 = 0, a2 = 0;
  ///@}
  double rate_below() const { return 1.0 / a1; }  ///< 1/a1: the Laplace rate left of the mode [1]
  /// 1/a2: the rate right of the mode; +inf at k = 1 (one-sided law) [1].
  double rate_above() const { return a2 > 0 ? 1.0 / a2 : 1.0 / 0.0; }
  double cdf(double t) const;  ///< of the residual
  double mean() const { return a2 - a1; }  ///< of the residual: a2 - a1 = -2 alpha sigma^2
};
/// Laws for k = 1 ... k_max (index k - 1); fewer when the linearised speed of impact k is not > 0.
std::vector<BounceResidualLaw> bounce_residual_laws(const ImpactScene& s, unsigned k_max, bool paper_route = false);

}  // namespace asperity
