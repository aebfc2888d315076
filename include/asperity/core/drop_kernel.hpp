// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The batched drop kernel (issue 26): the per-drop arithmetic of an explicit drop, written once as
// plain inline functions over a lane type, instantiated as a scalar reference (the oracle of the
// tests), as SIMD on the CPU (GCC vector types, function multi-versioning: the build assumes no
// AVX2) and, where nvcc compiles it, for CUDA (ASPERITY_HD).
//
// A drop is a pure function of (seed, drop index): a body-frame down direction d uniform on the
// sphere and a world azimuth (c, s) = (cos phi, sin phi) uniform on the circle, independent. This is
// a Haar rotation in other coordinates (q = R_z(phi) q_0(d)): the world horizontal direction of the
// contact point is phi plus an angle that depends on d only, hence uniform and independent of d,
// so (r_x, r_y) = r_xy (c, s) has the law the full rotation gives, without rotating anything.
//
// Streams without transcendental functions: Marsaglia's disk method (Ann. Math. Statist. 43 (1972)
// 645) for d -- (x, y) uniform in the unit disk by rejection, s = x^2 + y^2, then
// d = (2 x sqrt(1 - s), 2 y sqrt(1 - s), 1 - 2 s) -- and a second disk point, normalised, for the
// azimuth. Attempt a of disk w (0: direction, 1: azimuth) is the Philox4x32-10 block with counter
// (index lo, index hi, 2 a + w, Purpose::drop) and key (seed lo, seed hi), so every thread, rank or
// resumed run draws the same bits. Only +, -, *, / and sqrt (IEEE, correctly rounded; no FMA
// contraction: -ffp-contract=off here, nvcc -fmad=false), so every instantiation gives the same
// bits.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "asperity/core/contact.hpp"

#if defined(__CUDACC__)
#define ASPERITY_HD __host__ __device__
#define ASPERITY_HD_INLINE __host__ __device__ __forceinline__
#else
#define ASPERITY_HD
// Always inlined: the SIMD clones (target avx2, avx512f) must inline these instead of calling a
// copy compiled for the default target with vector arguments.
#define ASPERITY_HD_INLINE inline __attribute__((always_inline))
#endif

namespace asperity {

/// Which instantiation of the drop kernel runs the drops. All give the same bits.
enum class Kernel { scalar, simd, gpu };

std::string_view to_string(Kernel k);
/// Parses "scalar", "simd", "gpu"; throws std::invalid_argument naming the value otherwise.
Kernel parse_kernel(std::string_view name);
/// Whether this build can run `k` (gpu: only a CUDA build with a device).
bool kernel_available(Kernel k);

namespace kernel {

/// Philox4x32-10 (Salmon et al., SC'11), Random123's constants; U32/U64 a scalar or vector lane
/// type whose U64 lanes hold the products of 32-bit words.
template <class U32, class Widen, class Narrow>
ASPERITY_HD_INLINE void philox4x32_10(U32 (&c)[4], std::uint32_t k0, std::uint32_t k1, Widen widen, Narrow narrow) {
  for (int r = 0; r < 10; ++r) {
    const auto p0 = widen(c[0]) * std::uint64_t{0xD2511F53u}, p1 = widen(c[2]) * std::uint64_t{0xCD9E8D57u};
    const U32 hi0 = narrow(p0 >> 32), lo0 = narrow(p0), hi1 = narrow(p1 >> 32), lo1 = narrow(p1);
    c[0] = hi1 ^ c[1] ^ k0;
    c[1] = lo1;
    c[2] = hi0 ^ c[3] ^ k1;
    c[3] = lo0;
    k0 += 0x9E3779B9u, k1 += 0xBB67AE85u;
  }
}

inline constexpr std::uint32_t kPurposeDrop = 8;  // == Purpose::drop (random.hpp)

/// A coordinate in [-1, 1) from two words: (int32) hi 2^-31 + lo 2^-63, one correctly rounded sum
/// (63 random bits rounded to 53). I32/D: the signed word and double lane types.
template <class D, class I32, class ToD>
ASPERITY_HD_INLINE D coordinate(I32 hi, I32 lo_flipped, ToD to_d) {
  // lo_flipped = lo ^ 2^31 as signed: lo = lo_flipped + 2^31, exactly, in double.
  return to_d(hi) * 0x1p-31 + (to_d(lo_flipped) + 2147483648.0) * 0x1p-63;
}

/// Marsaglia's map from a disk point (x, y), s = x^2 + y^2 in (0, 1), to the unit sphere.
template <class D, class Sqrt>
ASPERITY_HD_INLINE void sphere_point(D x, D y, D s, D& dx, D& dy, D& dz, Sqrt sq) {
  const D f = 2.0 * sq(1.0 - s);
  dx = x * f, dy = y * f, dz = 1.0 - 2.0 * s;
}

/// The world azimuth (c, s) from a disk point: the point normalised.
template <class D, class Sqrt>
ASPERITY_HD_INLINE void azimuth(D x, D y, D s, D& c, D& sn, Sqrt sq) {
  const D r = sq(s);
  c = x / r, sn = y / r;
}

/// The contact quantities of one drop whose lowest asperity has centre u (unit) and key k = |u - d|^2,
/// on a sphere of radius R with asperity radius a. r_xy = R |u x d| (no cancellation near the pole),
/// (r_x, r_y) = r_xy (c, s), r_z = -(R (1 - k/2) + a) (the contact point below the centre).
template <class D, class Sqrt>
ASPERITY_HD_INLINE void contact_quantities(D dx, D dy, D dz, D c, D s, D ux, D uy, D uz, D k, double R, double a, D& r_xy,
                                           D& r_x, D& r_y, D& r_z, Sqrt sq) {
  const D cx = uy * dz - uz * dy, cy = uz * dx - ux * dz, cz = ux * dy - uy * dx;
  r_xy = R * sq((cx * cx + cy * cy) + cz * cz);
  r_x = r_xy * c, r_y = r_xy * s;
  r_z = -(R * (1.0 - 0.5 * k) + a);
}


/// The scalar lane operations (CPU reference and CUDA threads).
struct ScalarLanes {
  ASPERITY_HD_INLINE std::uint64_t operator()(std::uint32_t x) const { return x; }
  ASPERITY_HD_INLINE std::uint32_t operator()(std::uint64_t x) const { return static_cast<std::uint32_t>(x); }
  ASPERITY_HD_INLINE double operator()(std::int32_t x) const { return static_cast<double>(x); }
};
struct ScalarSqrt {
  // IEEE sqrt, correctly rounded on the CPU and on CUDA (nvcc's default -prec-sqrt=true).
  ASPERITY_HD_INLINE double operator()(double x) const { return __builtin_sqrt(x); }
};

/// Attempt `sub` = 2 a + w (attempt a of disk w) of drop `index`: a point in [-1, 1)^2 and its s;
/// true when 0 < s < 1 (inside the open disk, not the origin: the azimuth divides by sqrt(s)).
ASPERITY_HD_INLINE bool disk_attempt(std::uint64_t seed, std::uint64_t index, std::uint32_t sub, double& x, double& y,
                                     double& s) {
  std::uint32_t c[4] = {static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(index >> 32), sub, kPurposeDrop};
  const ScalarLanes L;
  philox4x32_10(c, static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32), L, L);
  x = coordinate<double>(static_cast<std::int32_t>(c[0]), static_cast<std::int32_t>(c[1] ^ 0x80000000u), L);
  y = coordinate<double>(static_cast<std::int32_t>(c[2]), static_cast<std::int32_t>(c[3] ^ 0x80000000u), L);
  s = x * x + y * y;
  return s < 1.0 && s > 0.0;
}

/// Disk w of drop `index` from attempt a0 on (rejection: 1 - pi/4 of the attempts fail).
ASPERITY_HD_INLINE void disk_from(std::uint64_t seed, std::uint64_t index, std::uint32_t w, std::uint32_t a0, double& x,
                                  double& y, double& s) {
  for (std::uint32_t a = a0;; ++a)
    if (disk_attempt(seed, index, 2 * a + w, x, y, s)) return;
}

/// One drop by the scalar reference: down direction d and azimuth (c, sn).
ASPERITY_HD_INLINE void draw_one(std::uint64_t seed, std::uint64_t index, double& dx, double& dy, double& dz, double& c,
                                 double& sn) {
  double x, y, s;
  disk_from(seed, index, 0, 0, x, y, s);
  sphere_point(x, y, s, dx, dy, dz, ScalarSqrt{});
  disk_from(seed, index, 1, 0, x, y, s);
  azimuth(x, y, s, c, sn, ScalarSqrt{});
}

}  // namespace kernel

/// One drop's draw: the body-frame down direction and the world azimuth.
struct DropDraw {
  Vec3 d;
  double c = 1, s = 0;
};

/// Drops [first, first + n) of `seed` into d, c, s (each of n entries), by kernel k (scalar or
/// simd; the same bits). Throws std::invalid_argument for gpu (drop_kernel.cu runs its own).
void draw_drops(Kernel k, std::uint64_t seed, std::uint64_t first, std::span<Vec3> d, std::span<double> c,
                std::span<double> s);

/// Drop `index` by the scalar reference.
DropDraw draw_drop(std::uint64_t seed, std::uint64_t index);

/// The contacts of a batch: for each i, the drop (d[i], c[i], s[i]) answered by nn[i] on the centres.
/// Contact::r = (r_xy c, r_xy s, -(R (1 - key/2) + a)); gap and core as make_contact.
void drop_contacts(Kernel k, std::span<const Vec3> d, std::span<const double> c, std::span<const double> s,
                   std::span<const Nearest> nn, std::span<const Vec3> centres, double R, double a,
                   std::span<Contact> out);

}  // namespace asperity
