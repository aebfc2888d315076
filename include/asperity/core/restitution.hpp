// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Microscopic coefficients of normal restitution eps_n(v) of a smooth contact, as functions of the
// normal contact speed v = |(V + Omega x r) . n| [m/s] (paper, text after Eq. 21).
#include <functional>
#include <memory>
#include <string>

namespace asperity {

/// eps_n(v) for v >= 0 [m/s]. Implementations must be finite and in [0, 1] for all finite v >= 0.
class Restitution {
 public:
  virtual ~Restitution() = default;
  /// eps_n at the normal contact speed v >= 0 [m/s]; in [0, 1].
  virtual double operator()(double v) const = 0;
  /// A description for reports, e.g. "constant(0.9)" or "viscoelastic-pade14(beta=0.0467)".
  virtual std::string name() const = 0;
};

/// eps_n = e for every speed.
std::unique_ptr<Restitution> constant_restitution(double e);

/// Viscoelastic spheres, Pade [1/4] of the series Eq. 8 (paper Eq. 9; Ramirez et al. PRE 60, 4465
/// (1999); Mueller & Poeschel PRE 84, 021302 (2011)):
///   eps_n = (1 + c1 v*) / (1 + b1 v* + b2 v*^2 + b3 v*^3 + b4 v*^4),  v* = beta^(1/2) v^(1/10),
/// c1 = b1 = 0.501086, b2 = 1.15345, b3 = 0.577977, b4 = 0.532178. beta [(s/m)^(1/5)] is the
/// material constant (0.0467 for the steel spheres of Montaine et al. 2011). Exact limits:
/// eps_n(0) = 1, eps_n -> 0 as v -> inf.
std::unique_ptr<Restitution> viscoelastic_pade14(double beta = 0.0467);

/// A user-supplied eps_n(v); values are checked at every call (finite, in [0,1]).
std::unique_ptr<Restitution> function_restitution(std::function<double(double)> f, std::string name);

/// v* of Eq. 9, exposed for tests and plots.
double pade_vstar(double v, double beta);

}  // namespace asperity
