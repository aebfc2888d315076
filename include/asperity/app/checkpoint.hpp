#pragma once
// Checkpoints of a streaming run (issue 14, item 4): the statistics so far, where to continue and
// the scene, in the run's output directory, written atomically (write_file_atomic):
//   checkpoint.toml  the scene (to_toml; `validate-geometry --resume DIR` runs it again)
//   checkpoint.bin   the StreamState (binary, this machine's byte order) and the scene's key
// Continuing from a checkpoint ends with the same bits as a run never interrupted
// (experiments/streaming.hpp). A run that completes removes its checkpoint files.
#include <filesystem>
#include <string>

#include "asperity/app/scene.hpp"
#include "asperity/experiments/streaming.hpp"

namespace asperity {

inline constexpr const char* kCheckpointScene = "checkpoint.toml";
inline constexpr const char* kCheckpointState = "checkpoint.bin";

/// What must match between a checkpoint and the run that continues it: the scene as TOML with
/// the run-control fields (threads) cleared.
std::string checkpoint_key(const Scene& s);

/// Writes both files into `dir` (the state last). Throws std::runtime_error naming the file.
void write_checkpoint(const std::filesystem::path& dir, const Scene& s, const StreamState& st);

/// Reads dir/checkpoint.bin; throws std::invalid_argument naming the file when it is missing,
/// damaged, or written for another scene (checkpoint_key differs).
StreamState read_checkpoint(const std::filesystem::path& dir, const Scene& s);

/// Removes both files if present (a completed run's own checkpoint).
void remove_checkpoint(const std::filesystem::path& dir);

}  // namespace asperity
