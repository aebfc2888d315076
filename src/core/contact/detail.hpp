// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Shared machinery of the contact backends (not installed).
#include <limits>
#include <memory>
#include <span>

#include "asperity/core/contact.hpp"

namespace asperity::detail {

/// Running canonical top-two over offered (key, index) pairs.
class TopTwo {
 public:
  void offer(std::uint32_t i, double k) noexcept {
    if (key_less(k, i, k1_, i1_)) {
      k2_ = k1_, i2_ = i1_, k1_ = k, i1_ = i;
    } else if (i != i1_ && key_less(k, i, k2_, i2_)) {
      k2_ = k, i2_ = i;
    }
  }
  void offer(std::span<const Vec3> c, const Vec3& d, std::uint32_t i) noexcept {
    offer(i, contact_key(c[i], d));
  }
  double first_key() const noexcept { return k1_; }
  double second_key() const noexcept { return k2_; }
  Nearest result() const noexcept {
    Nearest n{i1_, k1_, i2_, k2_};
    if (i2_ == kNone) n.runner_up = i1_;  // N == 1
    return n;
  }

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  double k1_ = kInf, k2_ = kInf;
  std::uint32_t i1_ = kNone, i2_ = kNone;
};

/// Relative key tolerance under which a backend's own distance arithmetic may order two
/// candidates differently from contact_key. Rounding differences are ~1e-16 relative; 1e-12
/// leaves a wide margin and still triggers on fewer than 1e-6 of random queries at N = 1e7.
inline constexpr double kTieTolerance = 1e-12;

std::unique_ptr<ContactQuery> make_brute(std::span<const Vec3> centres);
std::unique_ptr<ContactQuery> make_nanoflann(std::span<const Vec3> centres);
std::unique_ptr<ContactQuery> make_cgal(std::span<const Vec3> centres);
std::unique_ptr<ContactQuery> make_fcl(std::span<const Vec3> centres);
std::unique_ptr<ContactQuery> make_grid(std::span<const Vec3> centres);
/// The grid with an explicit cells-per-face-edge `side` and face `margin` (0 = automatic), for
/// tests and benchmarks of coarse and fine grids.
std::unique_ptr<ContactQuery> make_grid_with(std::span<const Vec3> centres, int side, double margin);

}  // namespace asperity::detail
