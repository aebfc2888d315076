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

/// How a contact's eps was found: from the table at its approach speed (in), from the table's end
/// row because the speed lies below or above the table's speeds (below/above: clamped), or, for a
/// contact first seen while its particles already separate (v_n <= 0: atoms created overlapping, or a
/// record lost), no impact at all: the fallback eps (the `constant`, else the lowest row's median).
enum class Flag : int { in = 0, below = 1, above = 2, separating = 3 };
inline const char* flag_name(Flag f) {
  static const char* const names[] = {"in", "below", "above", "separating"};
  return names[static_cast<int>(f)];
}

/// Counts of the contacts begun, per flag, on this rank.
struct Counts {
  double n[4] = {0, 0, 0, 0};
  double remote = 0;  // pair contacts whose partner atom is owned by another rank
};

/// Where a type pair's eps comes from when pair_coeff gives it its own: a table, or one constant.
struct Source {
  Source() = default;
  Source(const Source&) = delete;
  Source& operator=(const Source&) = delete;
  ~Source() {
    if (have_table) asperity_cor_free(&table);
  }
  asperity_cor_table table{};
  bool have_table = false;
  double constant = -1.0;
};

/// The settings shared by pair_style asperity/hooke and fix asperity/wall/hooke: the source of eps
/// (a table, or one constant eps for comparisons), the stream's seed, a damping factor for tests
/// (1 = the header's conversion), what to do with speeds outside the table, and an optional
/// per-contact log.
class Draw {
 public:
  Draw() = default;
  Draw(const Draw&) = delete;
  Draw& operator=(const Draw&) = delete;
  ~Draw() { reset(); }
  /// Back to no settings (a pair style whose settings are given again).
  void reset() {
    if (have_table_) asperity_cor_free(&table_);
    if (log_) std::fclose(log_);
    table_ = asperity_cor_table{};
    have_table_ = false, log_ = nullptr;
    table_path_.clear(), log_path_.clear();
    constant_ = -1.0, damping_scale_ = 1.0, seed_ = 0, have_seed_ = false, refuse_outside_ = false;
    counts_ = Counts{};
  }

  /// Reads one keyword at args[i] (and its value); returns the args consumed (0: not ours), or -1
  /// with `why` set.
  int keyword(int n, char** args, int i, std::string& why);
  /// After the keywords: loads the table, opens the log (rank > 0 writes "<log>.<rank>"). Returns
  /// false with `why`.
  bool finish(int rank, std::string& why);

  /// eps of a contact that begins now, at normal approach speed vn [m/s] (clamped to the table's
  /// speeds by the header), and the uniform that drew it; `flag` says how (see Flag). A contact
  /// with vn <= 0 gets the fallback eps.
  double eps(double vn, double u, Flag& flag) const { return eps_from(have_table_ ? &table_ : nullptr, constant_, vn, u, flag); }
  /// The same from a type pair's own source (pair_coeff I J table FILE | constant EPS).
  static double eps_from(const asperity_cor_table* t, double constant, double vn, double u, Flag& flag) {
    if (!(vn > 0.0)) {
      flag = Flag::separating;
      return fallback_from(t, constant);
    }
    if (!t) {
      flag = Flag::in;
      return constant;
    }
    flag = vn < t->speeds[0] ? Flag::below : (vn > t->speeds[t->n_speeds - 1] ? Flag::above : Flag::in);
    return asperity_cor_sample(t, vn, u);
  }
  /// The eps of a contact that is no impact: the `constant`, else the median of the lowest row.
  double fallback() const { return fallback_from(have_table_ ? &table_ : nullptr, constant_); }
  static double fallback_from(const asperity_cor_table* t, double constant) {
    return t ? asperity_cor_sample(t, t->speeds[0], 0.5) : constant;
  }
  /// 'outside error': a speed outside the table is an error, not a clamp.
  bool refuse_outside() const { return refuse_outside_; }
  const asperity_cor_table* table() const { return have_table_ ? &table_ : nullptr; }
  Counts& counts() { return counts_; }
  /// The linear spring-dashpot's gamma for eps (clamped to [0, 1]: a passive dashpot cannot return
  /// more than it received), times the test factor.
  double gamma(double eps, double k, double m_eff) const {
    const double e = eps < 0.0 ? 0.0 : (eps > 1.0 ? 1.0 : eps);
    return damping_scale_ * asperity_cor_linear_gamma(e, k, m_eff);
  }
  std::uint64_t seed() const { return seed_; }
  bool has_seed() const { return have_seed_; }
  /// One line per contact, written when it begins (nothing without `log`).
  void log(std::int64_t step, ContactKind kind, std::uint64_t a, std::uint64_t b, double vn, double u, double eps,
           double gamma, Flag flag) const {
    if (log_)
      std::fprintf(log_, "%lld %s %llu %llu %.17g %.17g %.17g %.17g %s\n", static_cast<long long>(step),
                   kind == ContactKind::pair ? "pair" : "wall", static_cast<unsigned long long>(a),
                   static_cast<unsigned long long>(b), vn, u, eps, gamma, flag_name(flag));
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
  bool refuse_outside_ = false;
  std::FILE* log_ = nullptr;
  Counts counts_;
};

}  // namespace asperity_dem
