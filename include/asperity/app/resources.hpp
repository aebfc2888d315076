// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Memory refused up front, not discovered: the peak resident memory of a run estimated from
// measured costs (per asperity of each contact index, per concurrently built sphere or body, per
// drop, per bounce sequence), and the memory this process may use.
#include <stdexcept>
#include <string>

#include "asperity/app/cor_table.hpp"
#include "asperity/app/plan.hpp"

namespace asperity {

struct MemoryEstimate {
  double bytes = 0;     ///< estimated peak resident set [bytes]
  std::string detail;   ///< what it is made of, for the message ("3 spheres x 2e7 asperities x 73 B (grid) + ...")
};

/// The estimated peak RSS of running plan `p` (its design as planned) as validate-geometry does, figures not counted (drawn
/// in-process by PLplot after the samples: ~17 MB more, measured 32.0 against 15.3 MB for N = 1000,
/// 2000 drops). Costs measured on x86-64 (docs/cli.md, Memory); within 25 % of the measured peak for
/// runs whose variable part dominates, one test per kind of run (tests/app/test_resources.cpp). A
/// mesh body's size is read from its file's header (mesh_file_size): nothing is parsed here.
MemoryEstimate estimate_memory(const Plan& p);

/// The memory this process may use: physical RAM, lowered to what the kernel has available now
/// (MemAvailable), a cgroup limit (memory.max) or RLIMIT_AS when set. 0 when unknown.
double memory_limit_bytes();

/// A run refused because its estimate exceeds what this process may use (Python: MemoryError).
struct MemoryRefused : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// Throws MemoryRefused naming the values that drive the estimate when it exceeds
/// memory_limit_bytes(): the run is refused before it starts (plan() calls it).
void check_memory(const Plan& p);

/// Measured bytes per asperity of an explicit sphere with a contact index of backend `b` (brute:
/// the centres alone).
double bytes_per_asperity(Backend b);

/// Bytes of an explicit sphere of `asperities` centres with a contact index of backend `b`
/// (brute: the centres alone), as estimate_memory counts them.
double sphere_bytes(std::uint64_t asperities, Backend b);

/// Bytes of making a restitution table (make_cor_table, one speed's drops at a time) and holding
/// it with its CSV text; estimate_memory counts it for outputs.cor_table, asperity.cor_table checks it.
double cor_table_bytes(const CorTableSpec& spec);

/// Throws MemoryRefused when `bytes` exceed memory_limit_bytes(); `what` says what needs them
/// ("make_rough_sphere: 1000000000 asperities x 24 B"), `lower` the parameters that decide.
void check_bytes(double bytes, const std::string& what, const std::string& lower);


}  // namespace asperity
