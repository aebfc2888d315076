// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Numbers in error messages: the shortest text that reads back to the same double, so the
// offending value is named exactly and as the user would write it (1e+200, not 9.99...97e+199).
#include <charconv>
#include <cstdio>
#include <string>

namespace asperity::detail {

/// printf-style text of one number (tables and figure titles), e.g. fmt("%.3f", x).
inline std::string fmt(const char* f, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

inline std::string num(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace asperity::detail
