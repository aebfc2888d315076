// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The drop kernel's arithmetic (drop_kernel.hpp says what a drop is and which streams it draws):
// plain inline functions over a lane type, for the host (scalar and SIMD, drop_kernel.cpp) and
// CUDA (drop_kernel.cu). Only <cstdint>, no Eigen: nvcc compiles it for the device as it is.
#include <cstdint>

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

namespace kernel {

/// Philox4x32-10 (Salmon et al., SC'11), Random123's constants; U32 a scalar or vector lane type,
/// mulhilo(a, m, hi, lo) the high and low words of the 64-bit products a m.
template <class U32, class MulHiLo>
ASPERITY_HD_INLINE void philox4x32_10(U32 (&c)[4], std::uint32_t k0, std::uint32_t k1, MulHiLo mulhilo) {
  for (int r = 0; r < 10; ++r) {
    U32 hi0, lo0, hi1, lo1;
    mulhilo(c[0], 0xD2511F53u, hi0, lo0);
    mulhilo(c[2], 0xCD9E8D57u, hi1, lo1);
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
  /// The 64-bit product a m as its high and low words (Philox's multiply).
  ASPERITY_HD_INLINE void operator()(std::uint32_t a, std::uint32_t m, std::uint32_t& hi, std::uint32_t& lo) const {
    const std::uint64_t p = static_cast<std::uint64_t>(a) * m;
    hi = static_cast<std::uint32_t>(p >> 32), lo = static_cast<std::uint32_t>(p);
  }
  /// x as a double (exact: every int32 is a double).
  ASPERITY_HD_INLINE double operator()(std::int32_t x) const { return static_cast<double>(x); }
};
/// The scalar square root, correctly rounded on both sides, so that CPU and GPU agree bit for bit.
struct ScalarSqrt {
  // IEEE sqrt, correctly rounded on the CPU and on CUDA (double sqrt is IEEE there).
#if defined(__CUDA_ARCH__)
  /// sqrt(x), IEEE round-to-nearest.
  __device__ __forceinline__ double operator()(double x) const { return __dsqrt_rn(x); }
#else
  /// sqrt(x), IEEE round-to-nearest.
  ASPERITY_HD_INLINE double operator()(double x) const { return __builtin_sqrt(x); }
#endif
};

/// Attempt `sub` = 2 a + w (attempt a of disk w) of drop `index`: a point in [-1, 1)^2 and its s;
/// true when 0 < s < 1 (inside the open disk, not the origin: the azimuth divides by sqrt(s)).
ASPERITY_HD_INLINE bool disk_attempt(std::uint64_t seed, std::uint64_t index, std::uint32_t sub, double& x, double& y,
                                     double& s) {
  std::uint32_t c[4] = {static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(index >> 32), sub, kPurposeDrop};
  const ScalarLanes L;
  philox4x32_10(c, static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32), L);
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

}  // namespace asperity
