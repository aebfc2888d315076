// SPDX-License-Identifier: GPL-3.0-or-later
// The CUDA instantiation of the drop kernel: one drop per thread through the scalar lane functions
// of drop_kernel_ops.hpp (the CPU reference's code). Built with -fmad=false (no contraction into
// FMA) and IEEE sqrt/division (nvcc's defaults -prec-sqrt=true -prec-div=true, no --use_fast_math),
// so each result is meant to carry the CPU's bits: test_drop_kernel_gpu checks it where a device exists.
#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

#include "asperity/core/drop_kernel_ops.hpp"
#include "core/drop_kernel_gpu.hpp"

namespace asperity::gpu {

namespace {

constexpr int kThreads = 256;

void check(cudaError_t e, const char* what) {
  if (e != cudaSuccess) throw std::runtime_error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(e));
}

__global__ void draw_kernel(std::uint64_t seed, std::uint64_t first, std::size_t n, double* dx, double* dy, double* dz,
                            double* c, double* s) {
  const std::size_t i = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  kernel::draw_one(seed, first + i, dx[i], dy[i], dz[i], c[i], s[i]);
}

__global__ void contact_kernel(std::size_t n, const double* in, double R, double a, double* out) {
  const std::size_t i = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const double* x = in;  // 9 arrays of n: dx dy dz c s ux uy uz k
  kernel::contact_quantities(x[i], x[n + i], x[2 * n + i], x[3 * n + i], x[4 * n + i], x[5 * n + i], x[6 * n + i],
                             x[7 * n + i], x[8 * n + i], R, a, out[i], out[n + i], out[2 * n + i], out[3 * n + i],
                             kernel::ScalarSqrt{});
}

// Device memory of `count` doubles, freed on scope exit.
struct DeviceArray {
  double* p = nullptr;
  explicit DeviceArray(std::size_t count) { check(cudaMalloc(&p, count * sizeof(double)), "cudaMalloc"); }
  ~DeviceArray() { cudaFree(p); }
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;
};

unsigned blocks(std::size_t n) { return unsigned((n + kThreads - 1) / kThreads); }

}  // namespace

bool device_available(std::string* why) {
  int count = 0;
  const cudaError_t e = cudaGetDeviceCount(&count);
  if (e == cudaSuccess && count > 0) return true;
  if (why) *why = e != cudaSuccess ? std::string(cudaGetErrorString(e)) : std::string("no CUDA device");
  return false;
}

void draw_drops(std::uint64_t seed, std::uint64_t first, std::size_t n, double* dx, double* dy, double* dz, double* c,
                double* s) {
  if (n == 0) return;
  DeviceArray d(5 * n);
  draw_kernel<<<blocks(n), kThreads>>>(seed, first, n, d.p, d.p + n, d.p + 2 * n, d.p + 3 * n, d.p + 4 * n);
  check(cudaGetLastError(), "draw_kernel launch");
  double* host[5] = {dx, dy, dz, c, s};
  for (std::size_t k = 0; k < 5; ++k)
    check(cudaMemcpy(host[k], d.p + k * n, n * sizeof(double), cudaMemcpyDeviceToHost), "cudaMemcpy");
}

void contact_quantities(std::size_t n, const double* dx, const double* dy, const double* dz, const double* c,
                        const double* s, const double* ux, const double* uy, const double* uz, const double* k, double R,
                        double a, double* r_xy, double* r_x, double* r_y, double* r_z) {
  if (n == 0) return;
  DeviceArray in(9 * n), out(4 * n);
  const double* src[9] = {dx, dy, dz, c, s, ux, uy, uz, k};
  for (std::size_t j = 0; j < 9; ++j)
    check(cudaMemcpy(in.p + j * n, src[j], n * sizeof(double), cudaMemcpyHostToDevice), "cudaMemcpy");
  contact_kernel<<<blocks(n), kThreads>>>(n, in.p, R, a, out.p);
  check(cudaGetLastError(), "contact_kernel launch");
  double* dst[4] = {r_xy, r_x, r_y, r_z};
  for (std::size_t j = 0; j < 4; ++j)
    check(cudaMemcpy(dst[j], out.p + j * n, n * sizeof(double), cudaMemcpyDeviceToHost), "cudaMemcpy");
}

}  // namespace asperity::gpu
