// SPDX-License-Identifier: GPL-3.0-or-later
// The CUDA instantiation of the drop kernel (drop_kernel.cu) against the scalar reference, bit for
// bit. Label gpu; skipped where no CUDA device is present (CI, the development machine).
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "asperity/core/drop_kernel.hpp"
#include "asperity/core/geometry.hpp"
#include "core/drop_kernel_gpu.hpp"

using namespace asperity;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Empty when a device can be used, else why not (GTEST_SKIP must be in the test body to end it).
std::string no_device() {
  std::string why;
  return gpu::device_available(&why) ? std::string() : "no CUDA device: " + why;
}

}  // namespace

TEST(DropKernelGpu, DrawsEqualTheScalarReference) {
  if (const std::string why = no_device(); !why.empty()) GTEST_SKIP() << why;
  for (std::uint64_t first : {std::uint64_t{0}, std::uint64_t{(1ull << 32) - 100}}) {
    constexpr std::size_t n = 100003;
    std::vector<Vec3> d(n);
    std::vector<double> c(n), s(n), gx(n), gy(n), gz(n), gc(n), gs(n);
    draw_drops(Kernel::scalar, 77, first, d, c, s);
    gpu::draw_drops(77, first, n, gx.data(), gy.data(), gz.data(), gc.data(), gs.data());
    for (std::size_t i = 0; i < n; ++i)
      ASSERT_TRUE(same_bits(d[i].x(), gx[i]) && same_bits(d[i].y(), gy[i]) && same_bits(d[i].z(), gz[i]) &&
                  same_bits(c[i], gc[i]) && same_bits(s[i], gs[i]))
          << first << " " << i;
  }
}

TEST(DropKernelGpu, ContactsEqualTheScalarReference) {
  if (const std::string why = no_device(); !why.empty()) GTEST_SKIP() << why;
  const auto centres = make_rough_sphere(SphereParams{20000, 3e-3, 6.5e-7}, 5, 0).centres;
  const auto grid = make_contact_query(Backend::grid, centres);
  constexpr std::size_t n = 20000;
  std::vector<Vec3> d(n);
  std::vector<double> c(n), s(n);
  draw_drops(Kernel::scalar, 3, 0, d, c, s);
  std::vector<Nearest> nn(n);
  grid->lowest(d, nn);
  std::vector<Contact> ref(n);
  drop_contacts(Kernel::scalar, d, c, s, nn, centres, 3e-3, 6.5e-7, ref);
  std::vector<double> col[9], out[4];
  for (auto& v : col) v.resize(n);
  for (auto& v : out) v.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& u = centres[nn[i].index];
    const double x[9] = {d[i].x(), d[i].y(), d[i].z(), c[i], s[i], u.x(), u.y(), u.z(), nn[i].key};
    for (int j = 0; j < 9; ++j) col[j][i] = x[j];
  }
  gpu::contact_quantities(n, col[0].data(), col[1].data(), col[2].data(), col[3].data(), col[4].data(), col[5].data(),
                          col[6].data(), col[7].data(), col[8].data(), 3e-3, 6.5e-7, out[0].data(), out[1].data(),
                          out[2].data(), out[3].data());
  for (std::size_t i = 0; i < n; ++i)
    ASSERT_TRUE(same_bits(ref[i].r_xy, out[0][i]) && same_bits(ref[i].r.x(), out[1][i]) &&
                same_bits(ref[i].r.y(), out[2][i]) && same_bits(ref[i].r.z(), out[3][i]))
        << i;
}
