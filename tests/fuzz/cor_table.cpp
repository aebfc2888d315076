// SPDX-License-Identifier: GPL-3.0-or-later
// Fuzz target: the restitution-table reader a DEM code compiles (include/asperity/cor_table.h, C99).
// Contract checked on every input: asperity_cor_parse returns 0 with a well-formed table (grids
// ascending, sizes consistent, every sample finite and nondecreasing in u), or -1 with a message and
// an empty table; anything else (a crash, a sanitizer report, a hang, a NaN) is a bug.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "asperity/cor_table.h"

namespace {
[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "cor_table.h: %s\n", what);
  std::abort();
}

void check_samples(const asperity_cor_table& t) {
  const double lo_s = t.speeds[0] * 0.5, hi_s = t.speeds[t.n_speeds - 1] * 2.0;
  const double lo_w = t.spins[0] - 1.0, hi_w = t.spins[t.n_spins - 1] + 1.0;
  for (const double spin : {lo_w, t.spins[0], 0.5 * (lo_w + hi_w), hi_w})
    for (const double speed : {lo_s, t.speeds[0], 0.5 * (lo_s + hi_s), hi_s}) {
      double prev = -INFINITY;
      for (int k = 0; k <= 16; ++k) {
        const double u = k / 16.0, e = asperity_cor_sample_spin(&t, spin, speed, u);
        if (!std::isfinite(e)) fail("a sample is not finite");
        if (e < prev) fail("samples decrease in u");
        prev = e;
        const double w = asperity_cor_sample_omega(&t, spin, speed, u, 1.0 - u);
        if (t.n_bands > 0 ? !std::isfinite(w) : !std::isnan(w)) fail("omega sample");
      }
    }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 8192) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);  // NUL-terminated by c_str()
  asperity_cor_table t;
  char err[128] = "";
  if (asperity_cor_parse(&t, text.c_str(), err, sizeof err) != 0) {
    if (err[0] == '\0') fail("refused without a message");
    if (t.eps || t.speeds || t.probs || t.spins || t.omega || t.n_speeds) fail("a refused table is not empty");
    return 0;
  }
  if (t.n_speeds < 1 || t.n_probs < 2 || t.n_spins < 1 || !t.eps || !t.speeds || !t.probs || !t.spins) fail("accepted a malformed table");
  if ((t.n_bands > 0) != (t.omega != nullptr)) fail("bands without omega rows");
  check_samples(t);
  asperity_cor_free(&t);
  return 0;
}
