#pragma once
// The verdict of a statistical test on a law: one enum for every report (no strings compared by
// hand). Its spelling in report.json and tables is to_string's.
#include <string_view>

namespace asperity {

enum class Verdict {
  accept,        ///< p >= alpha
  reject,        ///< p < alpha
  undecided,     ///< the test's smallest attainable p is not below alpha (e.g. too few bootstrap replicates)
  not_decisive,  ///< the design cannot decide this law (e.g. one explicit sphere: its own law)
  skipped,       ///< the law could not be evaluated at these parameters (the note says why)
};

/// "accept", "reject", "undecided", "not-decisive", "skipped".
std::string_view to_string(Verdict v);

/// accept or reject at level alpha; skipped for a NaN p.
Verdict verdict_at(double p, double alpha);

}  // namespace asperity
