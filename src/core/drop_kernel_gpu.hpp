// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The CUDA instantiation of the drop kernel (drop_kernel.cu; built when ASPERITY_WITH_CUDA): the
// same inline functions as the CPU's (drop_kernel_ops.hpp), one drop per thread, compiled with
// -fmad=false so that every operation rounds as on the CPU. Host functions on plain arrays (no
// Eigen in the CUDA translation unit). Not yet wired into the explicit drop path (Kernel::gpu).
#include <cstddef>
#include <cstdint>
#include <string>

namespace asperity::gpu {

/// Whether a CUDA device can be used; `why` says why not.
bool device_available(std::string* why = nullptr);

/// Drops [first, first + n) of `seed` on the device: down directions (dx, dy, dz) and azimuths
/// (c, s), each n doubles of host memory. Throws std::runtime_error on a CUDA error.
void draw_drops(std::uint64_t seed, std::uint64_t first, std::size_t n, double* dx, double* dy, double* dz, double* c,
                double* s);

/// The contact quantities of n drops on the device, as drop_contacts computes them: (u, k) the
/// lowest asperity's centre and key per drop; out r_xy, r_x, r_y, r_z (n doubles each, host memory).
void contact_quantities(std::size_t n, const double* dx, const double* dy, const double* dz, const double* c,
                        const double* s, const double* ux, const double* uy, const double* uz, const double* k, double R,
                        double a, double* r_xy, double* r_x, double* r_y, double* r_z);

}  // namespace asperity::gpu
