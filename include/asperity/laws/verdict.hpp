// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The verdict of a statistical test on a law: one enum for every report (no strings compared by
// hand). Its spelling in report.json and tables is to_string's.
#include <string>
#include <string_view>

namespace asperity {

/// What a test concluded about a law.
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

/// What every test of a sample against a law reports, whichever run made it: the sphere runs'
/// rows (TestReport, app/report.hpp) and the radii and mesh-body runs' checks (LawCheck,
/// experiments/body_experiments.hpp) extend it with their statistics.
struct LawTest {
  std::string quantity;               ///< e.g. "r_xy", "r_x", "eps", "omega_x_after", "core_contacts"
  std::string law;                    ///< e.g. "eq14", "exact-sphere", "exact-levels", "gauss-lambda"
  bool decisive = false;              ///< counts towards the exit status
  Verdict verdict = Verdict::skipped;  ///< the outcome (skipped until the test is made)
  std::string note;                   ///< how the p-value was made, or why the law was not tested
};

/// A decisive test rejected its law (the run exits 1).
inline bool rejects(const LawTest& t) { return t.decisive && t.verdict == Verdict::reject; }
/// A decisive test that could not be evaluated (skipped) or not decided (undecided): the run says so.
inline bool unresolved(const LawTest& t) {
  return t.decisive && (t.verdict == Verdict::skipped || t.verdict == Verdict::undecided);
}

}  // namespace asperity
