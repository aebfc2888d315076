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
// One Philox4x32-10 block per drop, no rejection (issue 30): counter (index lo, index hi, 0,
// Purpose::drop), key (seed lo, seed hi), so every thread, rank or resumed run draws the same bits.
// Its words (w0, w1, w2, w3) give z = w0 2^-31 + w1 2^-63 uniform on [-1, 1) (64 bits rounded to
// 53), the direction's longitude 2 pi w2 2^-32 and the azimuth 2 pi w3 2^-32: d = (rho cos, rho
// sin, z), rho = sqrt((1 - z)(1 + z)), uniform on the sphere (Archimedes). sin and cos are
// polynomials after an exact quadrant split (kernel::sincos_turn). Only +, -, * and sqrt (IEEE,
// correctly rounded; no FMA contraction: -ffp-contract=off here, nvcc -fmad=false), so every
// instantiation gives the same bits.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "asperity/core/contact.hpp"
#include "asperity/core/drop_kernel_ops.hpp"

namespace asperity {

/// Which instantiation of the drop kernel runs the drops. All give the same bits.
enum class Kernel { scalar, simd, gpu };

/// "scalar", "simd" or "gpu" (scene key ensemble.kernel, --kernel; parse_kernel reads it back).
std::string_view to_string(Kernel k);
/// Parses "scalar", "simd", "gpu"; throws std::invalid_argument naming the value otherwise.
Kernel parse_kernel(std::string_view name);
/// Whether this build can run `k` (gpu: only a CUDA build with a device).
bool kernel_available(Kernel k);

/// One drop's draw: the body-frame down direction and the world azimuth.
struct DropDraw {
  Vec3 d;  ///< unit down direction in the body frame (z and longitude from one Philox block)
  ///@{
  /// cos and sin of the world azimuth (polynomial, kernel::sincos_turn): (r_x, r_y) = r_xy (c, s).
  double c = 1, s = 0;
  ///@}
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
