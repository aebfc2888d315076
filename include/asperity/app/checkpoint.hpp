// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Checkpoints of a streaming run (issue 14, item 4): the statistics so far, where to continue and
// the scene, in the run's output directory, written atomically (write_file_atomic):
//   checkpoint.toml  the scene (to_toml; `validate-geometry --resume DIR` runs it again)
//   checkpoint.bin   the StreamState (binary, this machine's byte order, marked: another order is
//                    refused) and the scene's key
// A run split across P > 1 processes (validate-geometry under mpirun) writes one state per process,
// checkpoint.rank-R-of-P.bin, each holding that process's share (experiments/streaming.hpp); it is
// resumed with the same P.
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

/// The state file of s.share: checkpoint.bin for one process, checkpoint.rank-R-of-P.bin otherwise.
std::string checkpoint_state_name(const StreamShare& share);

/// Writes the scene (rank 0 only) and s.share's state into `dir` (the state last). Throws
/// std::runtime_error naming the file.
void write_checkpoint(const std::filesystem::path& dir, const Scene& s, const StreamState& st);

/// Reads s.share's state file in `dir`; throws std::invalid_argument naming the file when it is
/// missing, damaged, or written for another scene (checkpoint_key differs).
StreamState read_checkpoint(const std::filesystem::path& dir, const Scene& s);

/// A state as bytes (the state file's format) and back: how the processes of a split run send
/// their shares to rank 0. `what` names the source in messages.
std::string stream_state_bytes(const Scene& s, const StreamState& st);
StreamState stream_state_from_bytes(const std::string& bytes, const Scene& s, const std::string& what);

/// Removes the scene file and the state files of s.share.ranks processes if present (a completed
/// run's own checkpoint, or the one it continued).
void remove_checkpoint(const std::filesystem::path& dir, const StreamShare& share = {});

}  // namespace asperity
