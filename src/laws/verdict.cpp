// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/laws/verdict.hpp"

#include <cmath>

namespace asperity {

std::string_view to_string(Verdict v) {
  switch (v) {
    case Verdict::accept: return "accept";
    case Verdict::reject: return "reject";
    case Verdict::undecided: return "undecided";
    case Verdict::not_decisive: return "not-decisive";
    case Verdict::skipped: return "skipped";
  }
  return "?";
}

Verdict verdict_at(double p, double alpha) {
  if (std::isnan(p)) return Verdict::skipped;
  return p < alpha ? Verdict::reject : Verdict::accept;
}

}  // namespace asperity
