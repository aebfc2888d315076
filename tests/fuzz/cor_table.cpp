// SPDX-License-Identifier: GPL-3.0-or-later
// Fuzz target: the restitution-table reader a DEM code compiles (include/asperity/cor_table.h, C99).
// Contract checked on every input: asperity_cor_parse returns 0 with a well-formed table (grids
// ascending, sizes consistent, every sample finite and nondecreasing in u) that it read EXACTLY --
// checked by an independent reading below (std::regex for the number grammar, the counts of line 1,
// every stored value equal to its text, the stated ranges) -- or -1 with a message and an empty
// table; anything else (a crash, a sanitizer report, a hang, a NaN, a table accepted that the strict
// reading refuses) is a bug. regressions/cor_table/ holds tables the reader once accepted wrongly.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <regex>
#include <string>
#include <vector>

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
        if (e >= 0.0 && e <= 1.0) {  // the contact-model conversions of a drawn eps, and back
          const double g = asperity_cor_linear_gamma(e, 1e5, 2e-3), a = asperity_cor_tsuji_alpha(e);
          if (!(g >= 0.0 && g <= 2.0 * std::sqrt(2e2) * (1.0 + 1e-15)) || !(a >= 0.0 && a <= std::sqrt(5.0) * (1.0 + 1e-15)))
            fail("a conversion left its range");
          if (std::abs(asperity_cor_linear_eps(g, 1e5, 2e-3) - e) > 1e-9 || std::abs(asperity_cor_tsuji_eps(a) - e) > 1e-9)
            fail("a conversion does not invert");
        }
        const double w = asperity_cor_sample_omega(&t, spin, speed, u, 1.0 - u);
        if (t.n_bands > 0 ? !std::isfinite(w) : !std::isnan(w)) fail("omega sample");
      }
    }
}
std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (const char c : s) {
    if (c == sep) out.push_back(cur), cur.clear();
    else cur += c;
  }
  out.push_back(cur);
  return out;
}

// The value of a field that must be a plain decimal literal, equal to `stored` and in [lo, hi].
void exact(const std::string& field, double stored, double lo, double hi) {
  static const std::regex number("[+-]?([0-9]+(\\.[0-9]*)?|\\.[0-9]+)([eE][+-]?[0-9]+)?");
  if (field.size() > 64 || !std::regex_match(field, number)) fail("accepted a field that is not a plain decimal number");
  char* end = nullptr;
  const double x = std::strtod(field.c_str(), &end);  // the fuzzer runs in the "C" locale
  if (end != field.c_str() + field.size() || !std::isfinite(x) || x != stored) fail("a stored value differs from its text");
  if (!(x >= lo && x <= hi)) fail("accepted a value out of the stated range");
}

// The independent strict reading of an accepted table.
void check_exact(const std::string& text, const asperity_cor_table& t) {
  if (text.empty() || text.back() != '\n') fail("accepted a text whose last line has no line end");
  std::vector<std::string> lines = split(text.substr(0, text.size() - 1), '\n');
  for (auto& l : lines)
    if (!l.empty() && l.back() == '\r') l.pop_back();
  const long K = t.n_spins, S = t.n_speeds, P = t.n_probs, B = t.n_bands;
  const std::string first = t.format == 1 ? "# asperity-cor-table format=1 speeds=" + std::to_string(S) + " probabilities=" + std::to_string(P)
                                          : "# asperity-cor-table format=2 spins=" + std::to_string(K) + " speeds=" + std::to_string(S) +
                                                " probabilities=" + std::to_string(P) + " bands=" + std::to_string(B);
  if (lines[0] != first) fail("line 1 does not state the counts of the accepted table");
  std::vector<std::string> rows;
  for (std::size_t i = 1; i < lines.size(); ++i)
    if (!lines[i].empty() && lines[i][0] != '#') rows.push_back(lines[i]);
  if (static_cast<long>(rows.size()) != 1 + K * S * (1 + B)) fail("accepted a table whose row count differs from line 1");
  const std::vector<std::string> head = split(rows[0], ',');
  const std::size_t keys = t.format == 1 ? 1 : 3;
  if (static_cast<long>(head.size()) != static_cast<long>(keys) + P) fail("header columns");
  for (long j = 0; j < P; ++j) {
    const std::string& h = head[keys + static_cast<std::size_t>(j)];
    if (h.compare(0, 2, "p=") != 0) fail("header column without p=");
    exact(h.substr(2), t.probs[j], 0.0, 1.0);
  }
  for (std::size_t r = 1; r < rows.size(); ++r) {
    const std::vector<std::string> f = split(rows[r], ',');
    if (static_cast<long>(f.size()) != static_cast<long>(keys) + P) fail("accepted a row with the wrong number of fields");
    const long block = static_cast<long>(r - 1) / (1 + B), within = static_cast<long>(r - 1) % (1 + B);
    const long k = block / S, i = block % S;
    const double* q = within == 0 ? t.eps + (k * S + i) * P : t.omega + ((k * S + i) * B + within - 1) * P;
    if (t.format == 2) {
      exact(f[0], t.spins[k], -1e6, 1e6);
      if (f[2] != (within == 0 ? std::string("eps") : "omega_x:" + std::to_string(within - 1))) fail("row kind");
    }
    exact(f[t.format == 1 ? 0 : 1], t.speeds[i], std::numeric_limits<double>::denorm_min(), 1e8);
    for (long j = 0; j < P; ++j)
      exact(f[keys + static_cast<std::size_t>(j)], q[j], within == 0 ? 0.0 : -1e15, within == 0 ? 1000.0 : 1e15);
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
  check_exact(std::string(text.c_str()), t);  // what the parser saw: the text up to its first NUL
  asperity_cor_free(&t);
  return 0;
}
