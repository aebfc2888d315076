#pragma once
// Numbers in error messages: full precision, so the offending value is named exactly.
#include <sstream>
#include <string>

namespace asperity::detail {

inline std::string num(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

}  // namespace asperity::detail
