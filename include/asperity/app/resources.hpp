// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Memory refused up front, not discovered: the peak resident memory of a run estimated from
// measured costs (per asperity of each contact index, per concurrently built sphere or body, per
// drop, per bounce sequence), and the memory this process may use.
#include <string>

#include "asperity/app/scene.hpp"

namespace asperity {

struct MemoryEstimate {
  double bytes = 0;     ///< estimated peak resident set [bytes]
  std::string detail;   ///< what it is made of, for the message ("3 spheres x 2e7 asperities x 73 B (grid) + ...")
};

/// The estimated peak RSS of running `s` as validate-geometry does, figures not counted (drawn
/// in-process by PLplot after the samples: ~17 MB more, measured 32.0 against 15.3 MB for N = 1000,
/// 2000 drops). Costs measured on x86-64 (docs/cli.md, Memory); within 25 % of the measured peak for
/// runs whose variable part dominates (tests/app/test_resources.cpp).
MemoryEstimate estimate_memory(const Scene& s);

/// The memory this process may use: physical RAM, lowered by a cgroup limit (memory.max) or
/// RLIMIT_AS when set. 0 when unknown.
double memory_limit_bytes();

/// Throws std::invalid_argument naming the values that drive the estimate when it exceeds
/// memory_limit_bytes(): the run is refused before it starts.
void check_memory(const Scene& s);

}  // namespace asperity
