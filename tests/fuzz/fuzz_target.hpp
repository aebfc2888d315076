// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Shared by every fuzz target: how one input is split into arguments.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace asperity::fuzz {

/// One argument per line ('\n'); the bytes are taken as they are (no unescaping), so a corpus
/// file is a readable command line, one option or value per line.
inline std::vector<std::string> split_lines(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> out(1);
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == '\n')
      out.emplace_back();
    else
      out.back().push_back(static_cast<char>(data[i]));
  }
  if (out.back().empty()) out.pop_back();
  return out;
}

}  // namespace asperity::fuzz
