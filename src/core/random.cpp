// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/core/random.hpp"

#include <Random123/philox.h>
#include <Random123/uniform.hpp>

namespace asperity {

Stream::Stream(std::uint64_t seed, Purpose purpose, std::uint64_t index, std::uint64_t sub) noexcept
    : key_{seed, (static_cast<std::uint64_t>(purpose) << 56) ^ index}, sub_(sub) {}

std::uint64_t Stream::refill() noexcept {
  r123::Philox4x64 gen;
  r123::Philox4x64::ctr_type ctr = {{block_++, sub_, 0, 0}};
  r123::Philox4x64::key_type key = {{key_[0], key_[1]}};
  auto out = gen(ctr, key);
  for (int i = 0; i < 4; ++i) buf_[i] = out.v[i];
  left_ = 3;
  return buf_[0];
}

// The inline uniform() must stay Random123's u01 (the streams of every run depend on it).
static_assert(0x1p-64 == 1.0 / (static_cast<double>(~std::uint64_t{0}) + 1.0));

}  // namespace asperity
