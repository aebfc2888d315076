// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Every file a user names is read through here: scene files, meshes (checked before the mesh
// library opens them) and checkpoints. A file is read only if it is a regular file no larger than
// the limit its kind states, so /dev/zero, a FIFO, a directory or a runaway file is refused by name
// before any byte is parsed, instead of exhausting memory or blocking forever.
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace asperity {

/// Bad input file: what() names the file (and the `what` it was read as) and why it was refused.
struct InputFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Size of `file` if it is a regular file (symbolic links are followed; the final object must be a
/// regular file) of at most `max_bytes`; throws InputFileError naming `what` and the file otherwise.
/// Opens without blocking (O_NONBLOCK: a FIFO never blocks) and checks the opened object, so the
/// check and the read that follows see the same file type.
std::uint64_t checked_input_size(const std::filesystem::path& file, std::uint64_t max_bytes, const std::string& what);

/// The whole content of `file`, under the same checks as checked_input_size; a read error or a file
/// that changes size while read is an InputFileError.
std::string read_bounded_file(const std::filesystem::path& file, std::uint64_t max_bytes, const std::string& what);

}  // namespace asperity
