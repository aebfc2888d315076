// SPDX-License-Identifier: GPL-3.0-or-later
// The reference: a linear scan in canonical order. Every other backend is tested against it.
#include "core/contact/detail.hpp"

namespace asperity::detail {
namespace {

class Brute final : public ContactQuery {
 public:
  explicit Brute(std::span<const Vec3> c) : c_(c) {}
  Backend backend() const override { return Backend::brute; }
  Nearest lowest(const Vec3& d) const override { return brute_lowest(c_, d); }
  using ContactQuery::lowest;
  std::size_t memory_bytes() const override { return 0; }

 private:
  std::span<const Vec3> c_;
};

}  // namespace

std::unique_ptr<ContactQuery> make_brute(std::span<const Vec3> centres) {
  return std::make_unique<Brute>(centres);
}

}  // namespace asperity::detail

namespace asperity {
Nearest brute_lowest(std::span<const Vec3> centres, const Vec3& d) {
  detail::TopTwo t;
  const auto n = static_cast<std::uint32_t>(centres.size());
  for (std::uint32_t i = 0; i < n; ++i) t.offer(i, contact_key(centres[i], d));
  return t.result();
}
}  // namespace asperity
