// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Tangential contact laws for the impact of a rigid body on a plate, behind one interface
// (docs/tangential-laws.md derives each):
//  - kinematic: the paper's law, v'_t = eps_t v_t (Eq. 5; eps_t = 1 keeps v_t). One 3x3 solve.
//  - coulomb:   Coulomb friction mu along the impulse process (Routh/Stronge): the normal impulse
//               p is the clock, the contact velocity evolves as du/dp = K (n + f) with f = -mu s
//               while slipping (s the slip direction), the sticking impulse while |f| <= mu can hold
//               it, slip resuming in the direction the full inertia tensor dictates otherwise (slip
//               reversal included). The impact ends by a normal restitution rule: Newton's kinematic
//               (v'_n = -e v_n), Poisson's kinetic (p_f = (1 + e) p_c) or Stronge's energetic (the
//               normal force's work in restitution = e^2 x its work in compression).
//  - walton:    Walton's three-parameter law (e_n, mu, beta0) as an algebraic impulse: sticking with
//               tangential restitution beta0 (v'_t = -beta0 v_t) when the friction cone allows it,
//               else sliding with |P_t| = mu P_n along -v_t.
// stronge(mu) is coulomb with the energetic rule: the one law here that never creates kinetic
// energy, whatever the body, spin or slip history (tested on spheres, ellipsoids, cubes).
// Frame and units as impact.hpp (n out of the plate; SI).
#include <optional>
#include <string>
#include <string_view>

#include "asperity/core/impact.hpp"

namespace asperity {

/// A tangential contact law and its parameters (which fields apply depends on `model`; see the
/// file's comment and docs/tangential-laws.md). Build one with the factories; validate() checks it.
struct TangentialLaw {
  /// The law.
  enum class Model {
    kinematic,  ///< the paper's v'_t = eps_t v_t (Eq. 5)
    coulomb,    ///< Coulomb friction integrated along the impulse process (Routh/Stronge)
    walton      ///< Walton's algebraic three-parameter law (e_n, mu, beta0)
  };
  /// Normal restitution rule of the impulse process (coulomb only).
  enum class Normal {
    newton,     ///< kinematic: v'_n = -e v_n
    poisson,    ///< kinetic: p_f = (1 + e) p_c
    energetic   ///< Stronge: restitution work = e^2 x compression work
  };

  Model model = Model::kinematic;  ///< which law
  double eps_t = 1.0;       ///< kinematic: v'_t = eps_t v_t
  double mu = 0.0;          ///< coulomb, walton: friction coefficient, in [0, kMaxMu]
  static constexpr double kMaxMu = 1e12;  ///< every impact sticks long before; see validate()
  double beta0 = -1.0;      ///< walton: tangential restitution when sticking, v'_t = -beta0 v_t, in [-1, 1]
  Normal normal = Normal::energetic;  ///< coulomb: how the impact ends

  /// The paper's law, v'_t = eps_t v_t (1 keeps v_t, 0 sticks, -1 reverses it).
  static TangentialLaw kinematic(double eps_t = 1.0);
  /// Coulomb friction mu [1] along the impulse process, ended by the normal rule `normal`.
  static TangentialLaw coulomb(double mu, Normal normal);
  /// Walton's law: friction mu [1], tangential restitution beta0 in [-1, 1] when sticking.
  static TangentialLaw walton(double mu, double beta0);
  /// Coulomb friction with Stronge's energetic coefficient of restitution.
  static TangentialLaw stronge(double mu);

  /// "kinematic (eps_t = 1)", "coulomb (mu = 0.1, poisson)", ...
  std::string describe() const;

  /// Field-by-field equality (also of the fields the model ignores).
  friend bool operator==(const TangentialLaw&, const TangentialLaw&) = default;
};

/// "kinematic", "coulomb" or "walton" (what parse_tangential_model reads).
std::string_view to_string(TangentialLaw::Model m);
/// "newton", "poisson" or "energetic" (what parse_normal_rule reads).
std::string_view to_string(TangentialLaw::Normal n);
/// Parses "kinematic", "coulomb", "walton" / "newton", "poisson", "energetic"; throws
/// std::invalid_argument naming the value otherwise.
TangentialLaw::Model parse_tangential_model(std::string_view s);
/// Parses "newton", "poisson" or "energetic"; throws std::invalid_argument naming the value otherwise.
TangentialLaw::Normal parse_normal_rule(std::string_view s);

/// Throws std::invalid_argument naming the field: eps_t finite; mu finite and >= 0; beta0 in [-1, 1].
void validate(const TangentialLaw& law);

/// What the impulse process went through (coulomb; the algebraic laws fill what applies).
struct ImpactProcess {
  ImpactResult result;          ///< the impact, as solve_impact returns it
  double p_compression = 0;     ///< normal impulse at the end of compression [N s]
  double work_normal_compression = 0;   ///< int u_n dp over compression (<= 0) [J]
  double work_normal_restitution = 0;   ///< int u_n dp over restitution (>= 0) [J]
  double work = 0;              ///< total work of the impulse on the body, int u . dP [J]
  bool stuck = false;           ///< the contact stuck at some point (u_t = 0 held)
  bool slip_reversed = false;   ///< the slip resumed in a direction other than the initial one
  bool sliding = false;         ///< walton: the friction cone limited the impulse
  int steps = 0;                ///< integration steps of the process
};

/// The impact under `law` with the microscopic coefficient eps_n (e of the normal rule; Walton's
/// e_n). nullopt when the contact point does not approach the plate; throws std::invalid_argument
/// for non-finite input as solve_impact does, std::runtime_error if the process does not end
/// (a body that jams: the normal velocity stops increasing under friction).
std::optional<ImpactResult> solve_impact(const RigidBody& body, const ImpactState& s, double eps_n, const TangentialLaw& law);
/// The same with a speed-dependent eps_n, evaluated at the normal contact speed |v_n| before the
/// impact.
std::optional<ImpactResult> solve_impact(const RigidBody& body, const ImpactState& s, const Restitution& eps_n,
                                         const TangentialLaw& law);
/// The same with the process' details.
std::optional<ImpactProcess> solve_impact_process(const RigidBody& body, const ImpactState& s, double eps_n,
                                                  const TangentialLaw& law);

/// Kinetic energy of a rigid body, (1/2) M V^2 + (1/2) Omega . J Omega [J].
double kinetic_energy(const RigidBody& body, const Vec3& V, const Vec3& Omega);

}  // namespace asperity
