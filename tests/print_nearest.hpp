// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Readable GoogleTest failure messages for EXPECT_EQ on Nearest.
#include <ostream>

#include "asperity/core/contact.hpp"

namespace asperity {
inline void PrintTo(const Nearest& n, std::ostream* os) {
  os->precision(17);
  *os << "{index " << n.index << ", key " << n.key << ", runner_up " << n.runner_up << ", runner_up_key "
      << n.runner_up_key << "}";
}
}  // namespace asperity
