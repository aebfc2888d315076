// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/laws/figure.hpp"

#include <cmath>

namespace asperity {

Curve sampled_curve(const std::function<double(double)>& f, std::string label, double lo, double hi, int segments) {
  Curve c;
  c.label = std::move(label);
  for (int i = 0; i <= segments; ++i) {
    const double t = lo + (hi - lo) * i / static_cast<double>(segments);
    const double y = f(t);
    c.x.push_back(t);
    c.y.push_back(std::isfinite(y) ? y : 0.0);
  }
  return c;
}

}  // namespace asperity
