#include "asperity/core/orientation.hpp"

#include <cmath>
#include <numbers>

#include "asperity/core/random.hpp"

namespace asperity {

Rotation random_rotation(Stream& s) {
  // K. Shoemake, "Uniform random rotations", Graphics Gems III (1992): a unit quaternion
  // uniform on S^3 is exactly a Haar-distributed rotation.
  const double u1 = s.uniform0(), u2 = s.uniform0(), u3 = s.uniform0();
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const double t2 = 2.0 * std::numbers::pi * u2, t3 = 2.0 * std::numbers::pi * u3;
  Rotation q(a * std::cos(t2), a * std::sin(t2), b * std::sin(t3), b * std::cos(t3));  // (w,x,y,z)
  return q.normalized();
}

}  // namespace asperity
