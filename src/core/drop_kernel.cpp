// SPDX-License-Identifier: GPL-3.0-or-later
// The CPU instantiations of the drop kernel (drop_kernel.hpp): the scalar reference, one drop at a
// time, and SIMD, kW drops per vector with GCC vector types, one body compiled for avx512f, avx2
// and SSE2 (the x86-64 baseline), chosen once from the CPU (detail::best_isa). Both call the same inline functions; vector
// lanes perform the same IEEE operations in the same order as the scalar code, so the bits agree.
// One Philox block per drop, no rejection: every lane of a vector is a drop.
#include "asperity/core/drop_kernel.hpp"

#include "core/drop_kernel_detail.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define ASPERITY_DROP_SIMD 1
#include <immintrin.h>
#else
#define ASPERITY_DROP_SIMD 0  // other compilers: simd runs the scalar reference (the same bits)
#endif
// The scalar reference is never auto-vectorised, so that it is what a one-lane machine would do.
#if defined(__GNUC__) && !defined(__clang__)
#define ASPERITY_NO_VECTORIZE __attribute__((optimize("no-tree-vectorize")))
#else
#define ASPERITY_NO_VECTORIZE
#endif

namespace asperity {

std::string_view to_string(Kernel k) {
  switch (k) {
    case Kernel::scalar: return "scalar";
    case Kernel::simd: return "simd";
    case Kernel::gpu: return "gpu";
  }
  return "?";
}

Kernel parse_kernel(std::string_view name) {
  for (Kernel k : {Kernel::scalar, Kernel::simd, Kernel::gpu})
    if (name == to_string(k)) return k;
  throw std::invalid_argument("unknown kernel \"" + std::string(name) + "\" (scalar, simd, gpu)");
}

// The CUDA kernel (drop_kernel.cu) is built and tested on its own; the drop path does not run it yet.
bool kernel_available(Kernel k) { return k != Kernel::gpu; }

namespace {

using kernel::ScalarSqrt;

double gap_of(double k1, double k2, double R) {
  return std::isfinite(k2) ? 0.5 * R * (k2 - k1) : std::numeric_limits<double>::infinity();
}

ASPERITY_NO_VECTORIZE void draw_scalar(std::uint64_t seed, std::uint64_t first,
                                                                 std::span<Vec3> d, std::span<double> c,
                                                                 std::span<double> s) {
  for (std::size_t i = 0; i < d.size(); ++i) {
    double x, y, z;
    kernel::draw_one(seed, first + i, x, y, z, c[i], s[i]);
    d[i] = Vec3(x, y, z);
  }
}

ASPERITY_NO_VECTORIZE void contacts_scalar(std::span<const Vec3> d, std::span<const double> c,
                                                                     std::span<const double> s,
                                                                     std::span<const Nearest> nn,
                                                                     std::span<const Vec3> centres, double R, double a,
                                                                     std::span<Contact> out) {
  for (std::size_t i = 0; i < d.size(); ++i) {
    const Vec3& u = centres[nn[i].index];
    Contact& o = out[i];
    double rx, ry, rz;
    kernel::contact_quantities(d[i].x(), d[i].y(), d[i].z(), c[i], s[i], u.x(), u.y(), u.z(), nn[i].key, R, a, o.r_xy,
                               rx, ry, rz, ScalarSqrt{});
    o.index = nn[i].index;
    o.r = Vec3(rx, ry, rz);
    o.gap = gap_of(nn[i].key, nn[i].runner_up_key, R);
    o.core = core_touches_first(nn[i].key, R, a);
  }
}

#if ASPERITY_DROP_SIMD
#pragma GCC diagnostic ignored "-Wpsabi"  // vector types never cross a non-inline boundary
constexpr std::size_t kW = 8;             // drops per vector (iota below)
using u32v = std::uint32_t __attribute__((vector_size(4 * kW)));
using i32v = std::int32_t __attribute__((vector_size(4 * kW)));
using f64v = double __attribute__((vector_size(8 * kW)));

using u64v = std::uint64_t __attribute__((vector_size(4 * kW)));  // the same bits as u32v, pairs of lanes
using i64v = std::int64_t __attribute__((vector_size(8 * kW)));

// The vector lanes of the kernel's inline functions: Philox's mulhilo and the int -> double
// conversion. The high words by the widening multiply of the even and of the odd 32-bit lanes
// (u32v read as u64v pairs: (a & 0xffffffff) m and (a >> 32) m are vpmuludq / pmuludq), put back in
// place by a shift and a mask; the low words by the 32-bit multiply. One source for every target
// (avx512f, avx2, SSE2): plain GCC vector arithmetic, no intrinsics.
struct VectorLanes {
  [[gnu::always_inline]] void operator()(u32v a, std::uint32_t m, u32v& hi, u32v& lo) const {
    const u64v w = reinterpret_cast<u64v>(a), M = u64v{} + m;
    const u64v even = ((w & 0xFFFFFFFFu) * M) >> 32, odd = ((w >> 32) * M) & 0xFFFFFFFF00000000u;
    hi = reinterpret_cast<u32v>(even | odd);
    lo = a * m;
  }
  [[gnu::always_inline]] f64v operator()(i32v x) const { return __builtin_convertvector(x, f64v); }
};
// With AVX2 the high words by one primitive: vpmuludq on the even and on the odd lanes, blended
// (GCC turns the u64 products above into shift-and-add sequences for the constant multipliers:
// ~3x the instructions). Only this primitive differs; Philox itself is the shared philox4x32_10.
// Not always_inline: GCC refuses to force an avx2 function into the default-target philox4x32_10;
// it inlines it once that one sits in the avx2 and avx512f clones (checked: no call in their code).
struct Avx2Lanes : VectorLanes {
  using VectorLanes::operator();
  __attribute__((target("avx2"))) void operator()(u32v a, std::uint32_t m, u32v& hi, u32v& lo) const {
    const __m256i x = reinterpret_cast<__m256i>(a), M = _mm256_set1_epi32(static_cast<int>(m));
    const __m256i even = _mm256_srli_epi64(_mm256_mul_epu32(x, M), 32);
    const __m256i odd = _mm256_mul_epu32(_mm256_srli_epi64(x, 32), M);
    hi = reinterpret_cast<u32v>(_mm256_blend_epi32(even, odd, 0xAA));
    lo = a * m;
  }
};
// mask ? a : b on double lanes, the mask a comparison of 32-bit lanes (0 or all ones), widened to
// 64 bits by sign extension and applied as and/andnot/or: the same bits as a lane-wise ?: (issue 39:
// `m != 0 ? a : b` on 8-double vectors compiled to per-lane branches under AVX2, 59 of the draw's
// 122 instructions per drop).
struct VectorSel {
  [[gnu::always_inline]] f64v operator()(i32v m, f64v a, f64v b) const {
    const i64v w = __builtin_convertvector(m, i64v);
    return reinterpret_cast<f64v>((w & reinterpret_cast<i64v>(a)) | (~w & reinterpret_cast<i64v>(b)));
  }
};
struct VectorSqrt {
  // Lane by lane; GCC emits the vector sqrt (IEEE, correctly rounded) given -fno-math-errno and
  // -fno-rounding-math (this file: CGAL's -frounding-math would keep it scalar; the kernel runs in
  // the default rounding mode only).
  [[gnu::always_inline]] f64v operator()(f64v x) const {
    f64v r;
    for (std::size_t l = 0; l < kW; ++l) r[l] = __builtin_sqrt(x[l]);
    return r;
  }
};

// Drops first .. first + n - 1, kW per step: one Philox block per drop (counter (index lo, index hi,
// 0, purpose), the low words with their carry), then drop_from_block, as draw_one does lane by lane.
template <class Lanes, class Sqrt>
[[gnu::always_inline]] inline void draw_simd(std::uint64_t seed, std::uint64_t first, std::span<Vec3> d, std::span<double> c, std::span<double> s) {
  const std::size_t n = d.size();
  const u32v zero = {}, iota = {0, 1, 2, 3, 4, 5, 6, 7};
  const Lanes L;
  for (std::size_t i = 0; i < n; i += kW) {
    // A tail shorter than kW computes whole vectors and stores its lanes only.
    const std::uint64_t f = first + i;
    const auto lo0 = static_cast<std::uint32_t>(f);
    const u32v lo = zero + lo0 + iota;
    const u32v wrapped = reinterpret_cast<u32v>(lo < lo0);  // all ones where the low word wrapped
    u32v w[4] = {lo, zero + static_cast<std::uint32_t>(f >> 32) - wrapped, zero, zero + kernel::kPurposeDrop};
    kernel::philox4x32_10(w, static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32), L);
    f64v dx, dy, dz, cc, sn;
    kernel::drop_from_block<f64v>(reinterpret_cast<i32v>(w[0]), reinterpret_cast<i32v>(w[1] ^ 0x80000000u),
                                  reinterpret_cast<i32v>(w[2]), reinterpret_cast<i32v>(w[3]), dx, dy, dz, cc, sn, L,
                                  VectorSel{}, Sqrt{});
    for (std::size_t l = 0; l < kW && i + l < n; ++l) {
      d[i + l] = Vec3(dx[l], dy[l], dz[l]);
      c[i + l] = cc[l], s[i + l] = sn[l];
    }
  }
}

template <class Sqrt>
[[gnu::always_inline]] inline void contacts_simd(std::span<const Vec3> d, std::span<const double> c, std::span<const double> s,
                   std::span<const Nearest> nn, std::span<const Vec3> centres, double R, double a,
                   std::span<Contact> out) {
  const std::size_t n = d.size();
  for (std::size_t i = 0; i < n; i += kW) {
    f64v dx{}, dy{}, dz{}, cc{}, sn{}, ux{}, uy{}, uz{}, k{};
    for (std::size_t l = 0; l < kW && i + l < n; ++l) {
      const Vec3& u = centres[nn[i + l].index];
      dx[l] = d[i + l].x(), dy[l] = d[i + l].y(), dz[l] = d[i + l].z();
      cc[l] = c[i + l], sn[l] = s[i + l];
      ux[l] = u.x(), uy[l] = u.y(), uz[l] = u.z(), k[l] = nn[i + l].key;
    }
    f64v rxy, rx, ry, rz;
    kernel::contact_quantities(dx, dy, dz, cc, sn, ux, uy, uz, k, R, a, rxy, rx, ry, rz, Sqrt{});
    for (std::size_t l = 0; l < kW && i + l < n; ++l) {
      const Nearest& r = nn[i + l];
      Contact& o = out[i + l];
      o.index = r.index;
      o.r = Vec3(rx[l], ry[l], rz[l]);
      o.r_xy = rxy[l];
      o.gap = gap_of(r.key, r.runner_up_key, R);
      o.core = core_touches_first(r.key, R, a);
    }
  }
}
// The clones (function multi-versioning by hand, so that tests can run each one): the same body
// compiled for each target; the default one is SSE2, which every x86-64 has.
__attribute__((target("avx512f"))) void draw_avx512(std::uint64_t seed, std::uint64_t first, std::span<Vec3> d,
                                                     std::span<double> c, std::span<double> s) {
  draw_simd<Avx2Lanes, VectorSqrt>(seed, first, d, c, s);
}
__attribute__((target("avx2"))) void draw_avx2(std::uint64_t seed, std::uint64_t first, std::span<Vec3> d,
                                               std::span<double> c, std::span<double> s) {
  draw_simd<Avx2Lanes, VectorSqrt>(seed, first, d, c, s);
}
void draw_sse2(std::uint64_t seed, std::uint64_t first, std::span<Vec3> d, std::span<double> c, std::span<double> s) {
  draw_simd<VectorLanes, VectorSqrt>(seed, first, d, c, s);
}
__attribute__((target("avx512f"))) void contacts_avx512(std::span<const Vec3> d, std::span<const double> c,
                                                        std::span<const double> s, std::span<const Nearest> nn,
                                                        std::span<const Vec3> centres, double R, double a,
                                                        std::span<Contact> out) {
  contacts_simd<VectorSqrt>(d, c, s, nn, centres, R, a, out);
}
__attribute__((target("avx2"))) void contacts_avx2(std::span<const Vec3> d, std::span<const double> c,
                                                   std::span<const double> s, std::span<const Nearest> nn,
                                                   std::span<const Vec3> centres, double R, double a,
                                                   std::span<Contact> out) {
  contacts_simd<VectorSqrt>(d, c, s, nn, centres, R, a, out);
}
void contacts_sse2(std::span<const Vec3> d, std::span<const double> c, std::span<const double> s,
                   std::span<const Nearest> nn, std::span<const Vec3> centres, double R, double a,
                   std::span<Contact> out) {
  contacts_simd<VectorSqrt>(d, c, s, nn, centres, R, a, out);
}
#endif  // ASPERITY_DROP_SIMD

void check_sizes(std::size_t n, std::size_t a, std::size_t b, const char* what) {
  if (a != n || b != n) throw std::invalid_argument(std::string(what) + ": spans of different sizes");
}

}  // namespace

void draw_drops(Kernel k, std::uint64_t seed, std::uint64_t first, std::span<Vec3> d, std::span<double> c,
                std::span<double> s) {
  check_sizes(d.size(), c.size(), s.size(), "draw_drops");
  if (k == Kernel::gpu) throw std::invalid_argument("draw_drops: the gpu kernel runs on the device (drop_kernel.cu)");
  if (k == Kernel::simd) return detail::draw_drops_isa(detail::best_isa(), seed, first, d, c, s);
  draw_scalar(seed, first, d, c, s);
}

DropDraw draw_drop(std::uint64_t seed, std::uint64_t index) {
  DropDraw r;
  double x, y, z;
  kernel::draw_one(seed, index, x, y, z, r.c, r.s);
  r.d = Vec3(x, y, z);
  return r;
}

void drop_contacts(Kernel k, std::span<const Vec3> d, std::span<const double> c, std::span<const double> s,
                   std::span<const Nearest> nn, std::span<const Vec3> centres, double R, double a,
                   std::span<Contact> out) {
  check_sizes(d.size(), c.size(), s.size(), "drop_contacts");
  check_sizes(d.size(), nn.size(), out.size(), "drop_contacts");
  if (k == Kernel::gpu) throw std::invalid_argument("drop_contacts: the gpu kernel runs on the device (drop_kernel.cu)");
  if (k == Kernel::simd) return detail::drop_contacts_isa(detail::best_isa(), d, c, s, nn, centres, R, a, out);
  contacts_scalar(d, c, s, nn, centres, R, a, out);
}

namespace detail {

bool isa_available(SimdIsa isa) {
#if ASPERITY_DROP_SIMD
  switch (isa) {
    case SimdIsa::avx512f: return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx2");  // its mulhi is AVX2's
    case SimdIsa::avx2: return __builtin_cpu_supports("avx2");
    case SimdIsa::sse2: return true;
    case SimdIsa::none: return true;
  }
  return false;
#else
  return isa == SimdIsa::none;
#endif
}

SimdIsa best_isa() {
  // Resolved once (the CPU does not change under a running process). Not SSE2: its variant runs
  // more instructions than the scalar code (no 32-bit vector multiply; callgrind: 460 against 386
  // per drop), so a CPU without AVX2 runs the scalar reference.
  static const SimdIsa best = [] {
    for (SimdIsa i : {SimdIsa::avx512f, SimdIsa::avx2})
      if (isa_available(i)) return i;
    return SimdIsa::none;
  }();
  return best;
}

void draw_drops_isa(SimdIsa isa, std::uint64_t seed, std::uint64_t first, std::span<Vec3> d, std::span<double> c,
                    std::span<double> s) {
  check_sizes(d.size(), c.size(), s.size(), "draw_drops");
  if (!isa_available(isa)) throw std::invalid_argument("draw_drops: this CPU lacks the instruction set asked for");
  switch (isa) {
#if ASPERITY_DROP_SIMD
    case SimdIsa::avx512f: return draw_avx512(seed, first, d, c, s);
    case SimdIsa::avx2: return draw_avx2(seed, first, d, c, s);
    case SimdIsa::sse2: return draw_sse2(seed, first, d, c, s);
#endif
    default: return draw_scalar(seed, first, d, c, s);
  }
}

void drop_contacts_isa(SimdIsa isa, std::span<const Vec3> d, std::span<const double> c, std::span<const double> s,
                       std::span<const Nearest> nn, std::span<const Vec3> centres, double R, double a,
                       std::span<Contact> out) {
  check_sizes(d.size(), c.size(), s.size(), "drop_contacts");
  check_sizes(d.size(), nn.size(), out.size(), "drop_contacts");
  if (!isa_available(isa)) throw std::invalid_argument("drop_contacts: this CPU lacks the instruction set asked for");
  switch (isa) {
#if ASPERITY_DROP_SIMD
    case SimdIsa::avx512f: return contacts_avx512(d, c, s, nn, centres, R, a, out);
    case SimdIsa::avx2: return contacts_avx2(d, c, s, nn, centres, R, a, out);
    case SimdIsa::sse2: return contacts_sse2(d, c, s, nn, centres, R, a, out);
#endif
    default: return contacts_scalar(d, c, s, nn, centres, R, a, out);
  }
}

}  // namespace detail

}  // namespace asperity
