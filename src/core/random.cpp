#include "asperity/core/random.hpp"

#include <Random123/philox.h>
#include <Random123/uniform.hpp>

namespace asperity {

Stream::Stream(std::uint64_t seed, Purpose purpose, std::uint64_t index, std::uint64_t sub) noexcept
    : key_{seed, (static_cast<std::uint64_t>(purpose) << 56) ^ index}, sub_(sub) {}

std::uint64_t Stream::bits() noexcept {
  if (left_ == 0) {
    r123::Philox4x64 gen;
    r123::Philox4x64::ctr_type ctr = {{block_++, sub_, 0, 0}};
    r123::Philox4x64::key_type key = {{key_[0], key_[1]}};
    auto out = gen(ctr, key);
    for (int i = 0; i < 4; ++i) buf_[i] = out.v[i];
    left_ = 4;
  }
  return buf_[4 - left_--];
}

double Stream::uniform() noexcept { return r123::u01<double>(bits()); }

}  // namespace asperity
