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

/// sin and cos of the angle 2 pi w 2^-32 (w a 32-bit word read as signed), by polynomials in a fixed
/// operation order (+, -, * only), so that scalar, SIMD and CUDA give the same bits. The quadrant q
/// = round(w / 2^30) is split off in integers (exact), r = w - q 2^30 in [-2^29, 2^29] becomes x =
/// 2 pi r 2^-32 in [-pi/4, pi/4), and sin x, cos x are their Taylor polynomials to x^15 and x^16
/// (truncation < 7e-17 relative; a few ulp in all), then rotated by q quarter turns. I32: signed lanes; Sel:
/// sel(mask, a, b) lane-wise, mask from a comparison of I32 lanes.
template <class D, class I32, class ToD, class Sel>
ASPERITY_HD_INLINE void sincos_turn(I32 w, D& sn, D& cs, ToD to_d, Sel sel) {
  // w = q 2^30 + r, r in [-2^29, 2^29): r is w mod 2^30 moved into that range (no overflow anywhere).
  const I32 low = w & 0x3FFFFFFF;
  const I32 r = low - ((low & 0x20000000) << 1);
  const I32 q = ((w >> 29) + 1) >> 1;  // arithmetic shifts: round(w / 2^30), ties up; mod 4 below
  const D x = to_d(r) * 1.4629180792671596e-09;                      // 2 pi / 2^32
  const D x2 = x * x;
  const D ps = ((((((-7.6471637318198164759e-13 * x2 + 1.6059043836821614599e-10) * x2 - 2.5052108385441718775e-08) * x2 +
                   2.7557319223985890653e-06) * x2 - 1.9841269841269841270e-04) * x2 + 8.3333333333333333333e-03) * x2 -
                0.16666666666666666667) * x2;
  const D s0 = x + x * ps;
  const D pc = (((((((4.7794773323873852974e-14 * x2 - 1.1470745597729724714e-11) * x2 + 2.0876756987868098979e-09) * x2 -
                    2.7557319223985890653e-07) * x2 + 2.4801587301587301587e-05) * x2 - 1.3888888888888888889e-03) * x2 +
                 4.1666666666666666667e-02) * x2 - 0.5) * x2;
  const D c0 = 1.0 + pc;
  // Quarter turns (q mod 4): 1: (sin, cos) = (c0, -s0); 2: (-s0, -c0); 3: (-c0, s0).
  const I32 odd = q & 1, neg_s = q & 2, neg_c = (q + 1) & 2;
  const D a = sel(odd != 0, c0, s0), b = sel(odd != 0, s0, c0);
  sn = sel(neg_s != 0, -a, a);
  cs = sel(neg_c != 0, -b, b);
}

/// A drop from its one Philox4x32-10 block (w0, w1, w2, w3): z = coordinate(w0, w1) uniform on [-1,
/// 1) (64 bits, rounded to 53), the direction's longitude 2 pi w2 2^-32 and the world azimuth 2 pi
/// w3 2^-32, so d = (rho cos, rho sin, z) with rho = sqrt((1 - z)(1 + z)) is uniform on the sphere
/// (Archimedes) and independent of the azimuth (c, sn). No rejection: one block per drop.
template <class D, class I32, class ToD, class Sel, class Sqrt>
ASPERITY_HD_INLINE void drop_from_block(I32 w0, I32 w1_flipped, I32 w2, I32 w3, D& dx, D& dy, D& dz, D& c, D& sn, ToD to_d,
                                        Sel sel, Sqrt sq) {
  dz = coordinate<D>(w0, w1_flipped, to_d);
  const D rho = sq((1.0 - dz) * (1.0 + dz));
  D s2, c2;
  sincos_turn<D>(w2, s2, c2, to_d, sel);
  dx = rho * c2, dy = rho * s2;
  sincos_turn<D>(w3, sn, c, to_d, sel);
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

/// The scalar select (the lanes' `mask ? a : b`).
struct ScalarSel {
  /// m ? a : b.
  ASPERITY_HD_INLINE double operator()(bool m, double a, double b) const { return m ? a : b; }
};

/// One drop by the scalar reference: down direction d and azimuth (c, sn), from the Philox4x32-10
/// block with counter (index lo, index hi, 0, kPurposeDrop) and key (seed lo, seed hi).
ASPERITY_HD_INLINE void draw_one(std::uint64_t seed, std::uint64_t index, double& dx, double& dy, double& dz, double& c,
                                 double& sn) {
  std::uint32_t w[4] = {static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(index >> 32), 0u, kPurposeDrop};
  const ScalarLanes L;
  philox4x32_10(w, static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32), L);
  drop_from_block<double>(static_cast<std::int32_t>(w[0]), static_cast<std::int32_t>(w[1] ^ 0x80000000u),
                          static_cast<std::int32_t>(w[2]), static_cast<std::int32_t>(w[3]), dx, dy, dz, c, sn, L,
                          ScalarSel{}, ScalarSqrt{});
}

}  // namespace kernel

}  // namespace asperity
