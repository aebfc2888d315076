// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Counter-based random streams.
//
// Every random quantity in asperity is a pure function of (seed, purpose, stream index, draw number):
// sample i of a run draws from stream i, whichever thread computes it. This is what makes every
// result bit-identical for any thread count and schedule. The generator is Philox4x64-10
// (Random123), which passes BigCrush for any key/counter pattern.
#include <cstdint>

namespace asperity {

/// What a stream is used for; part of the key, so streams of different purposes never overlap.
enum class Purpose : std::uint32_t {
  sphere = 1,       ///< asperity positions of one explicit sphere
  orientation = 2,  ///< a random rotation of a drop
  fresh = 3,        ///< the cap of a fresh random sphere
  analysis = 4,     ///< randomisation inside statistical tests (e.g. the PIT at an atom)
  lazy_sphere = 5,  ///< counts and centres of the cells of one lazy sphere (lazy_sphere.hpp)
  bounce = 6,       ///< per-sequence draws of a bounce sequence (initial orientation, paper laws)
  bootstrap = 7,    ///< replicates of a sphere-block bootstrap (laws/block_ks.hpp)
  drop = 8,         ///< direction and azimuth of an explicit drop (Philox4x32 blocks, core/drop_kernel.hpp)
  test = 99,        ///< reserved for tests
};

/// A sequential view of one counter-based stream: (seed, purpose, index) -> u01, u01, ...
/// Cheap to construct (no state beyond 2 counters); construct one per sample.
class Stream {
 public:
  /// Stream `index` (and sub-stream `sub`) of `purpose` under `seed`. Distinct arguments give
  /// independent streams.
  Stream(std::uint64_t seed, Purpose purpose, std::uint64_t index, std::uint64_t sub = 0) noexcept;

  /// Uniform double in (0, 1]: never 0, so log(u) is always finite. Random123's u01:
  /// bits 2^-64 + 2^-65 (the product is exact, so a fused multiply-add gives the same value).
  double uniform() noexcept { return static_cast<double>(bits()) * 0x1p-64 + 0x1p-65; }
  /// Uniform double in [0, 1).
  double uniform0() noexcept { return 1.0 - uniform(); }
  /// Inline: the lazy sphere and the bootstrap draw ~10^8 of these per run; only every fourth
  /// call generates a Philox block (out of line).
  std::uint64_t bits() noexcept { return left_ ? buf_[4 - left_--] : refill(); }

 private:
  std::uint64_t key_[2];
  std::uint64_t sub_;
  std::uint64_t block_ = 0;  // counter of the next Philox block
  std::uint64_t buf_[4] = {0, 0, 0, 0};
  int left_ = 0;
  std::uint64_t refill() noexcept;  // next block into buf_, returns its first word
};

}  // namespace asperity
