// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Text for a file, taken out of an ostringstream that may have failed: a stringbuf that cannot
// grow reports end-of-file (libstdc++ catches the allocation failure), the stream sets badbit and
// drops everything after -- a table or a restitution file silently cut short. Taken through here,
// a failed stream is an error naming the file instead.
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace asperity::detail {

inline std::string checked_text(std::ostringstream&& os, const std::string& file) {
  if (!os) throw std::runtime_error("cannot write " + file + ": out of memory while formatting it");
  return std::move(os).str();
}

}  // namespace asperity::detail
