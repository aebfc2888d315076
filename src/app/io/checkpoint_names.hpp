// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The names of a streaming run's checkpoint files in its output directory (app/checkpoint.hpp
// writes and reads them): output names must never be one of them (output_staging.hpp).
#include <string_view>

namespace asperity {

inline constexpr const char* kCheckpointScene = "checkpoint.toml";
inline constexpr const char* kCheckpointState = "checkpoint.bin";

/// Whether `name` is a checkpoint file's name (checkpoint.toml, checkpoint.bin,
/// checkpoint.rank-R-of-P.bin): output_name_problem refuses such names for outputs.
inline bool is_checkpoint_name(std::string_view n) {
  constexpr std::string_view rank = "checkpoint.rank-", bin = ".bin";
  if (n == kCheckpointScene || n == kCheckpointState) return true;
  return n.size() >= rank.size() + bin.size() && n.substr(0, rank.size()) == rank &&
         n.substr(n.size() - bin.size()) == bin && n.find("-of-") != std::string_view::npos;
}

}  // namespace asperity
