/* SPDX-License-Identifier: MIT */
/* Copyright (c) 2026 the asperity developers. MIT (LICENSE's text), like include/asperity/cor_table.h:
 * this coupling is compiled against LAMMPS (GPL-2.0-only) and must stay compatible with it. */
// What the LAMMPS coupling draws, and how: one eps per contact from an asperity restitution table
// (include/asperity/cor_table.h), with a counter-based uniform keyed by the contact, turned into the
// linear spring-dashpot's damping by the header's conversion (docs/dem-coupling.md).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include <Random123/philox.h>

#include "asperity/cor_table.h"

namespace asperity_dem {

/// Which kind of contact a draw belongs to: the fourth counter word, so that a particle-particle
/// contact and a particle-wall contact never share a uniform.
enum class ContactKind : std::uint64_t { pair = 0, wall = 1 };

/// The uniform in [0, 1) of one contact: Philox4x64-10 block (a, b, start step, kind) under the key
/// (seed, "asp-dem"). A pure function of the contact: the same on every rank and thread that sees it,
/// whatever the rank or thread count, and whatever order contacts are met in. For a pair, a < b are
/// the two particle ids; for a wall, a is the particle id and b the wall's number.
inline double contact_uniform(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::int64_t start_step,
                              ContactKind kind) {
  r123::Philox4x64 gen;
  const r123::Philox4x64::ctr_type ctr = {{a, b, static_cast<std::uint64_t>(start_step), static_cast<std::uint64_t>(kind)}};
  const r123::Philox4x64::key_type key = {{seed, 0x6173702d64656dULL /* "asp-dem" */}};
  const r123::Philox4x64::ctr_type r = gen(ctr, key);
  return static_cast<double>(r[0] >> 11) * 0x1.0p-53;
}

/// The settings shared by pair_style asperity/hooke and fix asperity/wall/hooke: the source of eps
/// (a table, or one constant eps for comparisons), the stream's seed, a damping factor for tests
/// (1 = the header's conversion), and an optional per-contact log.
class Draw {
 public:
  Draw() = default;
  Draw(const Draw&) = delete;
  Draw& operator=(const Draw&) = delete;
  ~Draw() {
    if (have_table_) asperity_cor_free(&table_);
    if (log_) std::fclose(log_);
  }

  /// Reads one keyword at args[i] (and its value); returns the args consumed (0: not ours), or -1
  /// with `why` set.
  int keyword(int n, char** args, int i, std::string& why);
  /// After the keywords: loads the table, opens the log (rank > 0 writes "<log>.<rank>"). Returns
  /// false with `why`.
  bool finish(int rank, std::string& why);

  /// eps of a contact that begins now, at normal approach speed vn [m/s] (clamped to the table's
  /// speeds by the header), and the uniform that drew it.
  double eps(double vn, double u) const {
    return have_table_ ? asperity_cor_sample(&table_, vn, u) : constant_;
  }
  /// The linear spring-dashpot's gamma for eps (clamped to [0, 1]: a passive dashpot cannot return
  /// more than it received), times the test factor.
  double gamma(double eps, double k, double m_eff) const {
    const double e = eps < 0.0 ? 0.0 : (eps > 1.0 ? 1.0 : eps);
    return damping_scale_ * asperity_cor_linear_gamma(e, k, m_eff);
  }
  std::uint64_t seed() const { return seed_; }
  /// One line per contact, written when it begins (nothing without `log`).
  void log(std::int64_t step, ContactKind kind, std::uint64_t a, std::uint64_t b, double vn, double u, double eps,
           double gamma) const {
    if (log_)
      std::fprintf(log_, "%lld %s %llu %llu %.17g %.17g %.17g %.17g\n", static_cast<long long>(step),
                   kind == ContactKind::pair ? "pair" : "wall", static_cast<unsigned long long>(a),
                   static_cast<unsigned long long>(b), vn, u, eps, gamma);
  }
  bool flush_log() const { return !log_ || std::fflush(log_) == 0; }

 private:
  asperity_cor_table table_{};
  bool have_table_ = false;
  std::string table_path_, log_path_;
  double constant_ = -1.0;
  double damping_scale_ = 1.0;
  std::uint64_t seed_ = 0;
  bool have_seed_ = false;
  std::FILE* log_ = nullptr;
};

}  // namespace asperity_dem
