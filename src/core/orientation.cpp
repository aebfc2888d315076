// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/core/orientation.hpp"

#include <cmath>
#include <cstdint>
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

namespace {

// A point uniform in the open unit disk, 0 < x^2 + y^2 < 1 (the origin is rejected too: s2 divides).
// x = w 2^-63 for a signed word w: a uniform grid on [-1, 1), exact in double up to rounding of w.
struct Disk {
  double x, y, s;
};
Disk in_disk(Stream& st) {
  for (;;) {
    const double x = static_cast<double>(static_cast<std::int64_t>(st.bits())) * 0x1p-63;
    const double y = static_cast<double>(static_cast<std::int64_t>(st.bits())) * 0x1p-63;
    const double s = x * x + y * y;
    if (s < 1.0 && s > 0.0) return {x, y, s};
  }
}

}  // namespace

Rotation random_rotation_marsaglia(Stream& st) {
  const Disk a = in_disk(st), b = in_disk(st);
  const double f = std::sqrt((1.0 - a.s) / b.s);
  return Rotation(a.x, a.y, b.x * f, b.y * f);  // (w, x, y, z)
}

}  // namespace asperity
