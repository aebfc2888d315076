// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// File writes that never leave a partial file: every file of a run goes through here.
#include <filesystem>
#include <string>

namespace asperity {

/// Writes `text` to `file` atomically (temporary + rename): never a partial file.
void write_file_atomic(const std::filesystem::path& file, const std::string& text);

}  // namespace asperity
