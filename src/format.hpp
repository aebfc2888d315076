#pragma once
// Numbers in error messages: the shortest text that reads back to the same double, so the
// offending value is named exactly and as the user would write it (1e+200, not 9.99...97e+199).
#include <charconv>
#include <string>

namespace asperity::detail {

inline std::string num(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace asperity::detail
