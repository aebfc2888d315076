// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The drop kernel's SIMD variants by instruction set, for the tests (each must give the scalar
// reference's bits) and the benchmark. Kernel::simd runs best_isa().
#include <cstdint>
#include <span>

#include "asperity/core/drop_kernel.hpp"

namespace asperity::detail {

/// none: the scalar reference (also what simd runs where GCC's vector types are not available).
enum class SimdIsa { none, sse2, avx2, avx512f };

/// Whether this build and CPU can run `isa`.
bool isa_available(SimdIsa isa);
/// What Kernel::simd runs: avx512f, else avx2, else none (the SSE2 variant is slower than scalar).
SimdIsa best_isa();

/// draw_drops / drop_contacts by one variant; throws std::invalid_argument where !isa_available(isa).
void draw_drops_isa(SimdIsa isa, std::uint64_t seed, std::uint64_t first, std::span<Vec3> d, std::span<double> c,
                    std::span<double> s);
void drop_contacts_isa(SimdIsa isa, std::span<const Vec3> d, std::span<const double> c, std::span<const double> s,
                       std::span<const Nearest> nn, std::span<const Vec3> centres, double R, double a,
                       std::span<Contact> out);

}  // namespace asperity::detail
