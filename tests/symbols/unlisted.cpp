// SPDX-License-Identifier: GPL-3.0-or-later
// A library without asperity's export list: every template it instantiates is exported (as the
// CGAL, Boost and std instantiations of the product's libraries were), so symbols.foreign.power
// must fail on it: the symbol check can fail.
#include <cstddef>
#include <utility>

namespace unlisted {
template <std::size_t I> int instantiation() {
  static volatile int value = static_cast<int>(I);
  return value;
}
template <std::size_t... I> int sum_all(std::index_sequence<I...>) {
  // Taking each address makes the compiler emit all 64 weak instantiations.
  static int (*const table[])() = {&instantiation<I>...};
  int total = 0;
  for (auto* f : table) total += f();
  return total;
}
}  // namespace unlisted

int unlisted_instantiations() { return unlisted::sum_all(std::make_index_sequence<64>{}); }
