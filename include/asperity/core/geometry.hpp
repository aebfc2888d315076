// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Rough spheres: a central sphere of radius R (the paper's varrho) carrying N spherical asperities
// of radius a (the paper's rho) whose centres lie ON the central sphere (paper Eq. 11).
//
// Units: SI (metres). Asperity centres are stored as unit vectors u_i in the body frame; the
// centre of asperity i is R*u_i. Storing unit vectors keeps the near-pole comparisons
// scale-free: heights near the pole differ by ~R*theta^2/2, nanometres on a 3 mm sphere.
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products of Vec3 everywhere

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace asperity {

/// A 3-vector of doubles: a position [m], velocity [m/s] or unit direction [1], as each use states.
using Vec3 = Eigen::Vector3d;

/// Asperity indices are 32-bit (Nearest::index, support queries): a body carries 1 .. 2^32-1
/// asperities. The one statement of that rule; check_asperity_count applies it.
inline constexpr std::uint64_t kMaxAsperities = (std::uint64_t{1} << 32) - 1;
/// Throws std::invalid_argument "<what> must be in [1, 2^32-1], got <n>" unless 1 <= n <= kMaxAsperities.
void check_asperity_count(std::uint64_t n, std::string_view what = "asperities");

/// Parameters of a rough sphere. All lengths in metres.
struct SphereParams {
  std::uint64_t asperities = 100000;  ///< N >= 1
  double radius = 3e-3;               ///< R (varrho), central sphere radius [m]
  double asperity_radius = 6.5e-7;    ///< a (rho), asperity radius [m], 0 < a < R

  /// Field-by-field equality.
  friend bool operator==(const SphereParams&, const SphereParams&) = default;
};

/// Supported lengths [m]: every derived quantity (R^3 x density, squared lengths and their sums in
/// the statistics) then stays a normal double. Outside, results would overflow or underflow.
inline constexpr double kMinLength = 1e-15;  ///< smallest asperity radius a [m]
inline constexpr double kMaxLength = 1e6;    ///< largest central radius R [m]

/// Throws std::invalid_argument naming the offending field and value if the parameters are not
/// finite, positive, a < R, and within [kMinLength, kMaxLength].
void validate(const SphereParams& p);

/// An explicit rough sphere in its body frame.
struct RoughSphere {
  SphereParams params;        ///< N, R and a it was made with
  std::vector<Vec3> centres;  ///< unit vectors u_i (asperity centre = R*u_i)
};

/// N centres uniform on the unit sphere; centre i is a pure function of (seed, sphere_id, i),
/// so generation is parallel and bit-identical for any thread count.
RoughSphere make_rough_sphere(const SphereParams& p, std::uint64_t seed, std::uint64_t sphere_id);

/// A uniform point on the unit sphere from two uniforms in [0,1) (z = 1-2u, phi = 2 pi v).
Vec3 uniform_on_sphere(double u, double v);

/// Canonical ordering key of a centre for the down direction d (both unit vectors): the squared
/// chord |u - d|^2 = 2 - 2 u.d. Smaller key = lower centre. Evaluated as a fixed expression
/// (the library is built without FMA contraction) so that every backend computes the same bits;
/// the chord form keeps full relative precision near the pole, where 1 - u.d cancels.
inline double contact_key(const Vec3& u, const Vec3& d) noexcept {
  const double x = u.x() - d.x(), y = u.y() - d.y(), z = u.z() - d.z();
  return x * x + y * y + z * z;
}

}  // namespace asperity
