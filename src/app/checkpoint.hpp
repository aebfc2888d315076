// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Checkpoints of a streaming run (issue 14, item 4; issue 24, items 2 and 4): the statistics so
// far, where to continue and the scene, in the run's output directory:
//   checkpoint.toml  the scene (to_toml; `validate-geometry --resume DIR` runs it again)
//   checkpoint.bin   the StreamState (format 3: binary, this machine's byte order, marked: another
//                    order is refused), the scene's key (checkpoint_key: the scene and its planned
//                    design, so that checkpoint.toml and the state cannot be paired with another
//                    scene's) and a CRC-64 over everything before it.
// A run split across P > 1 processes (validate-geometry under mpirun) writes one state per process,
// checkpoint.rank-R-of-P.bin, each holding that process's share (experiments/streaming.hpp); it is
// resumed with the same P.
// Trust: a state file is read only if it is a regular file (not a link, FIFO or device) of exactly
// the size this scene's state has (checked before reading), its checksum matches, its key is this
// scene's, and its counts agree with each other (stream_state_problem). Anything else is refused,
// naming the file. Writes (AtomicDirectory): both files are staged complete and synced, then
// renamed, the scene first; a failure leaves the previous complete pair or none.
// Continuing from a checkpoint ends with the same bits as a run never interrupted
// (experiments/streaming.hpp). A run that completes removes its checkpoint files.
#include <filesystem>
#include <string>
#include <string_view>

#include "app/io/checkpoint_names.hpp"
#include "asperity/app/plan.hpp"
#include "asperity/experiments/streaming.hpp"

namespace asperity {

/// What must match between a checkpoint and the run that continues it: the scene as given, as TOML
/// with the fields that change no result (threads, plots, out) cleared, and the design the plan
/// resolved from it (spheres and backend "auto").
std::string checkpoint_key(const Plan& p);

/// The state file of a share: checkpoint.bin for one process, checkpoint.rank-R-of-P.bin otherwise.
std::string checkpoint_state_name(const StreamShare& share);

/// Writes the scene (rank 0 only) and p.control.share's state into `dir`. Throws std::runtime_error naming
/// the file; then `dir` holds the previous complete checkpoint, or none.
void write_checkpoint(const std::filesystem::path& dir, const Plan& p, const StreamState& st);

/// Reads p.control.share's state file in `dir`; throws std::invalid_argument naming the file when it is
/// missing, not a regular file, of another size, damaged, of another format, written for another
/// scene, or inconsistent (see the top of this file).
StreamState read_checkpoint(const std::filesystem::path& dir, const Plan& p);

/// plan()'s check of a streaming run, before the output directory is touched (throws
/// std::invalid_argument, saying what to do): a resumed run's checkpoint is read whole
/// (read_checkpoint); a new run refuses a directory holding checkpoint files (an interrupted run's,
/// or a scene file without its state). A run that does not stream (p.streams false): nothing.
void check_checkpoint_files(const Plan& p);

/// A state as bytes (the state file's format) and back. `what` names the source in messages.
std::string stream_state_bytes(const Plan& p, const StreamState& st);
StreamState stream_state_from_bytes(const std::string& bytes, const Plan& p, const std::string& what);

/// The checksum a state file ends with (CRC-64/XZ of every byte before it): for tests that craft
/// well-formed but inconsistent files.
std::uint64_t checkpoint_checksum(std::string_view bytes);

/// The size of every state file of plan p (the format has no optional parts).
std::size_t checkpoint_state_size(const Plan& p);

/// Removes the scene file and the state files of s.share.ranks processes if present (a completed
/// run's own checkpoint, or the one it continued).
void remove_checkpoint(const std::filesystem::path& dir, const StreamShare& share = {});

}  // namespace asperity
