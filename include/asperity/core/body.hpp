// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// General rough bodies (beyond the paper): a rigid base body carrying N spherical asperities of
// UNEQUAL radii. Asperity i is a ball with centre c_i and radius rho_i in the BODY frame, with
// the origin at the centre of mass (so the contact vector r of impact.hpp is the contact point
// itself, rotated into the world). The paper's rough sphere is the special case c_i = R u_i,
// rho_i = a; the equal-radius API (RoughSphere, ContactQuery) is untouched.
//
// Units: SI (m, kg, kg m^2). Every random quantity is a pure function of (seed, body id, index):
// asperity i draws from Stream(seed, Purpose::sphere, body_id, i), whichever thread builds it.
#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

#include "asperity/core/geometry.hpp"

namespace asperity {

class Stream;

/// How asperity radii are drawn: all equal, lognormal, or discrete levels.
struct RadiusDistribution {
  /// Which family; selects the fields that apply (the others keep their defaults and are ignored).
  enum class Kind {
    fixed,      ///< every asperity has `radius`
    lognormal,  ///< ln(rho) ~ Normal(ln(median), sigma^2)
    levels      ///< rho = levels[m] with probability fractions[m]
  };
  Kind kind = Kind::fixed;  ///< the family; set by the factories below
  double radius = 6.5e-7;             ///< fixed: rho [m]
  double median = 6.5e-7;             ///< lognormal: median exp(mu) [m]
  double sigma = 0.5;                 ///< lognormal: sd of ln(rho) [1]
  std::vector<double> levels;         ///< levels: radii [m]
  std::vector<double> fractions;      ///< levels: probabilities (sum 1 within 1e-9)

  /// All radii equal to rho [m]. Not validated here: validate() (or the body factories) checks it.
  static RadiusDistribution fixed(double rho);
  /// Lognormal radii with median exp(mu) = `median` [m] and sd of ln(rho) `sigma` [1] (sigma = 0
  /// is fixed(median)). Unbounded: some laws (theory_radii.hpp) refuse it. Not validated here.
  static RadiusDistribution lognormal(double median, double sigma);
  /// Discrete radii: levels[m] [m] with probability fractions[m] (at most kMaxRadiusLevels levels,
  /// fractions summing to 1 within 1e-9). Not validated here: validate() checks it.
  static RadiusDistribution discrete(std::vector<double> levels, std::vector<double> fractions);
  /// "fixed(6.5e-07)", "lognormal(6.5e-07,0.5)", "levels(2e-06:0.2,5e-07:0.8)".
  std::string describe() const;

  /// Field-by-field equality (also of the fields the kind ignores).
  friend bool operator==(const RadiusDistribution&, const RadiusDistribution&) = default;
};

/// Throws std::invalid_argument naming the offending field and value (radii finite and > 0,
/// sigma finite and >= 0, fractions in [0,1] summing to 1, levels non-empty and equal in length).
void validate(const RadiusDistribution& d);

/// Most radius levels a distribution may have: the exact level law (theory_radii.hpp) costs
/// ~levels^3 per evaluation (measured at 1e5 drops: 8 levels 90 s, 16 levels 236 s of analysis).
inline constexpr std::size_t kMaxRadiusLevels = 16;

/// One radius from the stream (fixed: no draw; levels: one uniform; lognormal: two uniforms,
/// Box-Muller). Pure function of the stream's state.
double sample_radius(const RadiusDistribution& d, Stream& s);

/// A rigid body with asperity balls, in its body frame (origin = centre of mass).
struct RoughBody {
  std::string name;                ///< "sphere", or the mesh file stem
  std::vector<Vec3> centres;       ///< c_i [m], relative to the centre of mass
  std::vector<double> radii;       ///< rho_i [m]
  double mass = 1;                 ///< M [kg] (base body only: asperity mass neglected, as in the paper)
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();  ///< J about the centre of mass, body frame [kg m^2]
  double base_radius = 0;          ///< sphere bodies: the central radius R [m]; 0 for meshes
  double area = 0;                 ///< surface area of the base body the centres lie on [m^2]

  /// Number of asperities N.
  std::size_t size() const { return centres.size(); }
  /// The largest asperity radius max rho_i [m]; 0 for a body without asperities.
  double max_radius() const;
};

/// A rough sphere with radii from `radii`: the SAME centres R u_i as make_rough_sphere(p, seed,
/// sphere_id) (u, v are the stream's first two uniforms), radius i from the same stream's next
/// draws. Mass 4/3 pi R^3 density, J = (2/5) M R^2 (central sphere, as in the paper).
/// p.asperity_radius is ignored. Throws std::invalid_argument if any drawn radius is >= R.
RoughBody make_rough_sphere_body(const SphereParams& p, const RadiusDistribution& radii, std::uint64_t seed,
                                 std::uint64_t sphere_id, double density = 7850);

}  // namespace asperity
