/* SPDX-License-Identifier: MIT */
/* Copyright (c) 2026 the asperity developers. MIT (LICENSE's text); see asperity_draw.h. */
// LAMMPS styles that draw the restitution coefficient per contact from an asperity table, built
// against the headers Debian's liblammps-dev ships (20220106: pair.h, fix.h, atom.h, ...; not the
// GRANULAR package's headers, so nothing here depends on their class layout):
//   pair_style asperity/hooke   linear spring-dashpot + Cundall-Strack tangential history, like
//                               gran/hooke/history, but with gamma_n per contact;
//   fix asperity/wall/hooke     the same contact against the plane z = zlo;
//   fix asperity/records        per-atom contact records (created by the pair style).
// register_styles() puts their creators into a LAMMPS instance's style maps, as LAMMPS's plugin
// loader does (Debian's LAMMPS has no PLUGIN package). docs/dem-coupling.md has the syntax.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "fix.h"
#include "pair.h"

#include "asperity_draw.h"

namespace asperity_dem {

/// Per-atom storage of `slots` contact records of `width` doubles each, migrated with its atom
/// (Comm::exchange) and grown with the atom arrays. Free records have record[0] == 0.
class FixRecords : public LAMMPS_NS::Fix {
 public:
  FixRecords(LAMMPS_NS::LAMMPS* lmp, int narg, char** arg);
  ~FixRecords() override;
  int setmask() override { return 0; }
  void grow_arrays(int nmax) override;
  void copy_arrays(int i, int j, int delflag) override;
  void set_arrays(int i) override;
  int pack_exchange(int i, double* buf) override;
  int unpack_exchange(int nlocal, double* buf) override;
  int pack_restart(int i, double* buf) override;
  void unpack_restart(int nlocal, int nth) override;
  int size_restart(int nlocal) override;
  int maxsize_restart() override;
  void post_run() override;
  double memory_usage() override;
  /// Whose end-of-run summary this fix prints (the pair style's draw, or the wall's own).
  void set_summary(Draw* draw, const std::string& who, bool pair) { summary_draw_ = draw, summary_who_ = who, summary_pair_ = pair; }

  double* record(int i, int slot) { return rec_[i] + slot * width_; }
  int active(int i) const;
  void grow_slots(int need);
  int slots() const { return slots_; }
  int width() const { return width_; }

 protected:
  FixRecords(LAMMPS_NS::LAMMPS* lmp, int narg, char** arg, int slots, int width);
  void allocate();
  int slots_ = 0, width_ = 0;
  double** rec_ = nullptr;
  Draw* summary_draw_ = nullptr;
  std::string summary_who_;
  bool summary_pair_ = false;
};

/// pair_style asperity/hooke kn kt gammat xmu table FILE [constant EPS|none] seed S [scale_damping X] [log FILE]
class PairHooke : public LAMMPS_NS::Pair {
 public:
  explicit PairHooke(LAMMPS_NS::LAMMPS* lmp);
  ~PairHooke() override;
  void compute(int eflag, int vflag) override;
  void settings(int narg, char** arg) override;
  void coeff(int narg, char** arg) override;
  void init_style() override;
  double init_one(int i, int j) override;

 private:
  // A pair record: partner id (0: free), start step, eps, gamma_n, shear[3], last step touched.
  enum { PARTNER, START, EPS, GAMMA, SHEAR, TOUCHED = SHEAR + 3, WIDTH };
  static constexpr int kSlots0 = 16;  // slots per atom at first; grown (doubled) when an atom needs more
  double* find_or_add(int i, LAMMPS_NS::tagint partner, bool& fresh);
  std::uint16_t slot_of(int i, const double* r) const {
    return static_cast<std::uint16_t>((r - records_->record(i, 0)) / WIDTH);
  }
  void forget_ended();
  double kn_ = 0, kt_ = 0, gammat_ = 0, xmu_ = 0;
  double speed_si_ = 1.0;         // the input's velocity unit in m/s
  std::vector<double> rmax_;      // per type: the largest radius present or to be inserted
  LAMMPS_NS::bigint hints_step_ = -1;
  std::vector<int> hint_first_;          // per ilist position: its first neighbour entry
  std::vector<std::uint16_t> hints_;     // per neighbour entry: slot in i's records, slot in j's
  std::vector<int> touched_;             // per local atom: its distinct records touched in this step
  std::vector<int> source_of_;    // per type pair (i * (ntypes + 1) + j): index into sources_, -1 = the style's
  std::vector<std::unique_ptr<Source>> sources_;
  Draw draw_;
  FixRecords* records_ = nullptr;
  std::string records_id_;
};

/// fix ID group asperity/wall/hooke kn kt gammat xmu zplane zlo|zcylinder radius table FILE [constant EPS|none] seed S
///     [wall N] [scale_damping X] [log FILE]
class FixWall : public FixRecords {
 public:
  FixWall(LAMMPS_NS::LAMMPS* lmp, int narg, char** arg);
  int setmask() override;
  void init() override;
  void setup(int vflag) override;
  void post_force(int vflag) override;

 private:
  // The atom's wall record: in contact (0/1), start step, eps, gamma_n, shear[3].
  enum { ACTIVE, START, EPS, GAMMA, SHEAR, WIDTH = SHEAR + 3 };
  double kn_ = 0, kt_ = 0, gammat_ = 0, xmu_ = 0, zlo_ = 0;
  bool cylinder_ = false;
  double speed_si_ = 1.0;
  std::uint64_t wall_ = 1;
  Draw draw_;
};

/// Makes "asperity/hooke", "asperity/wall/hooke" and "asperity/records" known to `lmp`.
void register_styles(LAMMPS_NS::LAMMPS* lmp);

}  // namespace asperity_dem
