/* SPDX-License-Identifier: MIT */
/* Copyright (c) 2026 the asperity developers. MIT (LICENSE's text); see asperity_draw.h. */
// The LAMMPS styles of asperity_lammps.h. The contact force is the linear spring-dashpot with
// Cundall-Strack tangential history (Cundall & Strack, Geotechnique 29, 47 (1979); the form of
// LAMMPS's gran/hooke/history, written here from the model, not copied), except that the normal
// damping is the absolute gamma_n (force -gamma_n d(delta)/dt) of the contact's own drawn eps.
#include "asperity_lammps.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <algorithm>
#include <map>
#include <memory>
#include <vector>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"
#include "utils.h"

using namespace LAMMPS_NS;

namespace asperity_dem {

// The std::string overloads of Error::all/one (the fmt ones are out of reach: fmt_stub/fmt/format.h).
[[noreturn]] static void fail(LAMMPS* lmp, const std::string& why) { lmp->error->all(FLERR, why); }
[[noreturn]] static void fail_one(LAMMPS* lmp, const std::string& why) { lmp->error->one(FLERR, why); }

// ---- Draw: keywords, table, log ----

int Draw::keyword(int n, char** args, int i, std::string& why) {
  std::string k = args[i];
  if (k == "cortable") k = "table";  // the same keyword under a name that is no LAMMPS pair style (pair_style hybrid)
  if (k != "table" && k != "constant" && k != "seed" && k != "scale_damping" && k != "log" && k != "outside") return 0;
  if (i + 1 >= n) {
    why = "keyword '" + k + "' needs a value";
    return -1;
  }
  const char* v = args[i + 1];
  char* end = nullptr;
  errno = 0;
  if (k == "constant" && std::strcmp(v, "none") == 0) {
    constant_ = -1.0;  // no constant: the table decides (lets an input script pass both)
  } else if (k == "table") {
    table_path_ = v;
  } else if (k == "outside") {
    if (std::strcmp(v, "clamp") != 0 && std::strcmp(v, "error") != 0) {
      why = std::string("outside '") + v + "': clamp or error";
      return -1;
    }
    refuse_outside_ = std::strcmp(v, "error") == 0;
  } else if (k == "log") {
    log_path_ = std::strcmp(v, "none") == 0 ? "" : v;
  } else if (k == "seed") {
    const unsigned long long s = std::strtoull(v, &end, 10);
    if (*v == '-' || !*v || *end || errno) {
      why = std::string("seed '") + v + "': not an unsigned decimal integer below 2^64";
      return -1;
    }
    seed_ = s, have_seed_ = true;
  } else {
    const double x = std::strtod(v, &end);
    if (!*v || *end || errno || !std::isfinite(x)) {
      why = k + " '" + v + "': not a finite number";
      return -1;
    }
    if (k == "constant") {
      if (!(x >= 0.0 && x <= 1.0)) {
        why = std::string("constant '") + v + "': eps must lie in [0, 1]";
        return -1;
      }
      constant_ = x;
    } else {
      if (!(x > 0.0)) {
        why = std::string("scale_damping '") + v + "': must be > 0";
        return -1;
      }
      damping_scale_ = x;
    }
  }
  return 2;
}

bool Draw::finish(int rank, std::string& why) {
  if (constant_ >= 0.0) table_path_.clear();  // 'constant EPS' wins over 'table FILE'
  if (table_path_.empty() && constant_ < 0.0) {
    why = "give 'table FILE' (eps drawn per contact) or 'constant EPS' (one eps for every contact); under pair_style "
          "hybrid write 'cortable FILE': hybrid starts LAMMPS's pair style 'table' at the word table";
    return false;
  }
  if (!table_path_.empty() && !have_seed_) {
    why = "'table' needs 'seed S' (the key of the per-contact stream)";
    return false;
  }
  if (!table_path_.empty()) {
    char err[512];
    if (asperity_cor_load(&table_, table_path_.c_str(), err, sizeof err) != 0) {
      why = std::string("table: ") + err;
      return false;
    }
    have_table_ = true;
  }
  if (!log_path_.empty()) {
    const std::string path = rank == 0 ? log_path_ : log_path_ + "." + std::to_string(rank);
    // A new file only: an existing log (or a link planted in its place) is never overwritten.
    const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0 || (log_ = fdopen(fd, "w")) == nullptr) {
      if (fd >= 0) close(fd);
      why = "log '" + path + "': cannot create it (" + std::strerror(errno) + "; it must not exist yet)";
      return false;
    }
    std::fprintf(log_, "# step kind id_a id_b approach_speed_m_s u eps gamma_n flag\n");
  }
  return true;
}

// ---- The contact force ----

namespace {

struct Contact {
  double del[3];  // x_i - x_j (pair) or x_i - wall point (wall)
  double r;       // |del|
  double overlap; // rad_i + rad_j - r > 0
  double vr[3];   // v_i - v_j
  double wr[3];   // (rad_i omega_i + rad_j omega_j) / r
  double meff;
};

struct Params {
  double kn, gamma, kt, gammat, xmu, dt;
  bool shear_update;
};

// Normal: kn overlap - gamma_n d(delta)/dt along del; tangential: spring kt on the shear history plus
// the dashpot meff gammat, capped by Coulomb xmu |F_n| (the history rescaled to the cap).
// Returns the normal approach speed; writes the force on i (f) and its tangential part (fs).
inline __attribute__((always_inline)) void hooke(const Contact& c, const Params& p, double* shear, double* f, double* fs) {
  const double rinv = 1.0 / c.r, rsqinv = rinv * rinv;
  const double vnnr = c.vr[0] * c.del[0] + c.vr[1] * c.del[1] + c.vr[2] * c.del[2];
  double vtr[3];
  for (int d = 0; d < 3; ++d) vtr[d] = c.vr[d] - c.del[d] * vnnr * rsqinv;
  vtr[0] -= c.del[2] * c.wr[1] - c.del[1] * c.wr[2];
  vtr[1] -= c.del[0] * c.wr[2] - c.del[2] * c.wr[0];
  vtr[2] -= c.del[1] * c.wr[0] - c.del[0] * c.wr[1];
  const double ccel = p.kn * c.overlap * rinv - p.gamma * vnnr * rsqinv;  // not clipped at 0 (header)
  if (p.shear_update) {
    for (int d = 0; d < 3; ++d) shear[d] += vtr[d] * p.dt;
    // keep the history in the tangent plane as the contact normal turns
    const double rsht = (shear[0] * c.del[0] + shear[1] * c.del[1] + shear[2] * c.del[2]) * rsqinv;
    for (int d = 0; d < 3; ++d) shear[d] -= rsht * c.del[d];
  }
  const double shrmag = std::sqrt(shear[0] * shear[0] + shear[1] * shear[1] + shear[2] * shear[2]);
  for (int d = 0; d < 3; ++d) fs[d] = -(p.kt * shear[d] + c.meff * p.gammat * vtr[d]);
  const double fsmag = std::sqrt(fs[0] * fs[0] + fs[1] * fs[1] + fs[2] * fs[2]);
  const double fn = p.xmu * std::fabs(ccel * c.r);
  if (fsmag > fn) {
    const double s = fn / fsmag;
    for (int d = 0; d < 3; ++d) {
      if (shrmag != 0.0 && p.kt > 0.0)
        shear[d] = s * (shear[d] + c.meff * p.gammat * vtr[d] / p.kt) - c.meff * p.gammat * vtr[d] / p.kt;
      fs[d] *= s;
    }
  }
  for (int d = 0; d < 3; ++d) f[d] = c.del[d] * ccel + fs[d];
}

// kn kt gammat xmu: the four leading numbers of both styles.
void read_contact_numbers(LAMMPS* lmp, char** arg, double* kn, double* kt, double* gammat, double* xmu) {
  *kn = utils::numeric(FLERR, arg[0], false, lmp);
  *kt = utils::numeric(FLERR, arg[1], false, lmp);
  *gammat = utils::numeric(FLERR, arg[2], false, lmp);
  *xmu = utils::numeric(FLERR, arg[3], false, lmp);
  if (!(*kn > 0.0) || !(*kt >= 0.0) || !(*gammat >= 0.0) || !(*xmu >= 0.0))
    fail(lmp, std::string("asperity: kn must be > 0, kt, gammat, xmu >= 0 (got ") + arg[0] + " " +
                                         arg[1] + " " + arg[2] + " " + arg[3] + ")");
}

void require_sphere(LAMMPS* lmp, const char* who) {
  Atom* atom = lmp->atom;
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
    fail(lmp, std::string(who) + " needs atom_style sphere (radius, rmass, omega, torque)");
  if (!atom->tag_enable) fail(lmp, std::string(who) + " needs atom IDs (they key the per-contact stream)");
}

// The table's speeds are m/s: the factor from the input's velocity unit to m/s, for the unit styles
// whose force, mass, length and time are consistent without a conversion constant (force->ftm2v == 1,
// so that gamma = f(eps) sqrt(m k) is in the input's force/velocity unit). Other styles are refused.
double speed_unit_si(LAMMPS* lmp, const char* who) {
  const std::string u = lmp->update->unit_style;
  double f = 0.0;
  if (u == "si") f = 1.0;
  else if (u == "cgs") f = 0.01;               // cm/s
  else if (u == "micro" || u == "nano") f = 1.0;  // micrometer/microsecond, nanometer/nanosecond
  if (f == 0.0 || lmp->force->ftm2v != 1.0)
    fail(lmp, std::string(who) + ": 'units " + u +
                  "' is not supported: the table's speeds are m/s; use units si, cgs, micro or nano");
  return f;
}

// The end-of-run line: how many contacts began, and how their eps was found (all ranks call it).
void summary(LAMMPS* lmp, const std::string& who, Draw& draw, bool pair) {
  Counts& c = draw.counts();
  double local[5] = {c.n[0], c.n[1], c.n[2], c.n[3], c.remote}, all[5];
  MPI_Allreduce(local, all, 5, MPI_DOUBLE, MPI_SUM, lmp->world);
  c = Counts{};
  const double begun = all[0] + all[1] + all[2] + all[3];
  if (lmp->comm->me != 0) return;
  char line[640];
  const asperity_cor_table* t = draw.table();
  if (!t)
    std::snprintf(line, sizeof line, "%s: %.0f contacts begun in this run, eps %.6g (constant) for each%s", who.c_str(), begun,
                  draw.fallback(), pair ? "" : "\n");
  else
  std::snprintf(line, sizeof line,
                "%s: %.0f contacts begun in this run: %.0f within the table's speeds, %.0f below them (drawn from "
                "the %g m/s row), %.0f above them (drawn from the %g m/s row), %.0f first seen separating (no impact: "
                "eps %.6g)%s",
                who.c_str(), begun, all[0], all[1], t ? t->speeds[0] : 0.0, all[2], t ? t->speeds[t->n_speeds - 1] : 0.0,
                all[3], draw.fallback(), pair ? "" : "\n");
  std::string msg = line;
  if (pair) msg += "; " + std::to_string(static_cast<long long>(all[4])) + " with the partner on another rank\n";
  utils::logmesg(lmp, msg);
}

}  // namespace

// ---- FixRecords ----

FixRecords::FixRecords(LAMMPS* lmp, int narg, char** arg) : Fix(lmp, narg, arg) {
  // fix ID group asperity/records SLOTS WIDTH (created by pair_style asperity/hooke)
  if (narg != 5) fail(lmp, "fix asperity/records: expected SLOTS WIDTH");
  slots_ = utils::inumeric(FLERR, arg[3], false, lmp);
  width_ = utils::inumeric(FLERR, arg[4], false, lmp);
  if (slots_ < 1 || width_ < 1) fail(lmp, "fix asperity/records: SLOTS and WIDTH must be >= 1");
  allocate();
}

FixRecords::FixRecords(LAMMPS* lmp, int narg, char** arg, int slots, int width)
    : Fix(lmp, narg, arg), slots_(slots), width_(width) {
  allocate();
}

void FixRecords::allocate() {
  maxexchange = slots_ * width_ + 1;
  maxexchange_dynamic = 1;  // the slots grow when an atom needs more (grow_slots): comm asks again
  restart_peratom = 1;   // the records go into restart files (pack_restart) and come back (unpack_restart)
  create_attribute = 1;  // atoms created during a run (fix pour, fix deposit) start with no contact
  grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  for (int i = 0; i < atom->nlocal; ++i) set_arrays(i);
}

FixRecords::~FixRecords() {
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(rec_);
}

// The active records of atom i: those at the front whose first value is nonzero (free records are 0).
int FixRecords::active(int i) const {
  int n = 0;
  while (n < slots_ && rec_[i][n * width_] != 0.0) ++n;
  return n;
}

// More slots for every atom of this rank (at least `need`, at least twice as many): the records
// stay, the new slots are free. Pointers into the records are invalid afterwards.
void FixRecords::grow_slots(int need) {
  const int slots = std::max(need, 2 * slots_);
  double** grown = nullptr;
  memory->create(grown, std::max(atom->nmax, 1), slots * width_, "asperity/records:rec");
  for (int i = 0; i < atom->nmax; ++i) {
    std::memcpy(grown[i], rec_[i], sizeof(double) * slots_ * width_);
    std::memset(grown[i] + slots_ * width_, 0, sizeof(double) * (slots - slots_) * width_);
  }
  memory->destroy(rec_);
  rec_ = grown;
  slots_ = slots;
  maxexchange = slots_ * width_ + 1;
}

// Migration (Comm::exchange) and restart files carry the active records only, after their count, so
// ranks whose slots have grown differently exchange atoms and read each other's restart files.
int FixRecords::pack_exchange(int i, double* buf) {
  const int n = active(i);
  buf[0] = n;
  std::memcpy(buf + 1, rec_[i], sizeof(double) * n * width_);
  return 1 + n * width_;
}

int FixRecords::unpack_exchange(int nlocal, double* buf) {
  const int n = static_cast<int>(buf[0]);
  if (n > slots_) grow_slots(n);
  std::memset(rec_[nlocal], 0, sizeof(double) * slots_ * width_);
  std::memcpy(rec_[nlocal], buf + 1, sizeof(double) * n * width_);
  return 1 + n * width_;
}

// Restart files: per atom, the block's length (LAMMPS's layout for per-atom fix data: unpack_restart
// skips the earlier fixes' blocks by their leading lengths), the count n of active records, and
// their n * width values. A restart read back with the same fix ID and style (the pair style's
// records fix is created with its fixed ID at the first run after read_restart; the wall fix takes
// the ID the input gives it again) gets its records back in Modify::add_fix.
int FixRecords::pack_restart(int i, double* buf) {
  const int n = active(i);
  buf[0] = 2 + n * width_;
  buf[1] = n;
  std::memcpy(buf + 2, rec_[i], sizeof(double) * n * width_);
  return 2 + n * width_;
}

void FixRecords::unpack_restart(int nlocal, int nth) {
  double** extra = atom->extra;
  int m = 0;
  for (int k = 0; k < nth; ++k) m += static_cast<int>(extra[nlocal][m]);
  const int len = static_cast<int>(extra[nlocal][m]), n = static_cast<int>(extra[nlocal][m + 1]);
  if (n < 0 || len != 2 + n * width_)
    fail_one(lmp, std::string("fix ") + id + ": the restart file's records do not have " + std::to_string(width_) +
                      " values each (written by another version of the style?)");
  if (n > slots_) grow_slots(n);
  std::memset(rec_[nlocal], 0, sizeof(double) * slots_ * width_);
  std::memcpy(rec_[nlocal], &extra[nlocal][m + 2], sizeof(double) * n * width_);
}

int FixRecords::size_restart(int i) { return 2 + active(i) * width_; }
int FixRecords::maxsize_restart() { return 2 + slots_ * width_; }

void FixRecords::post_run() {
  if (summary_draw_) summary(lmp, summary_who_, *summary_draw_, summary_pair_);
}

void FixRecords::grow_arrays(int nmax) { memory->grow(rec_, nmax, slots_ * width_, "asperity/records:rec"); }

void FixRecords::copy_arrays(int i, int j, int /*delflag*/) {
  std::memcpy(rec_[j], rec_[i], sizeof(double) * slots_ * width_);
}

void FixRecords::set_arrays(int i) { std::memset(rec_[i], 0, sizeof(double) * slots_ * width_); }

double FixRecords::memory_usage() { return static_cast<double>(atom->nmax) * slots_ * width_ * sizeof(double); }

// ---- PairHooke ----

PairHooke::PairHooke(LAMMPS* lmp) : Pair(lmp) {
  single_enable = 0;
  restartinfo = 0;  // give pair_style and pair_coeff again after read_restart; the contact records are in the file
  no_virial_fdotr_compute = 1;
  finitecutflag = 1;
  records_id_ = "ASPERITY_PAIR_RECORDS";
}

PairHooke::~PairHooke() {
  if (records_ && modify->find_fix(records_id_) >= 0) modify->delete_fix(records_id_);
  if (allocated) {
    memory->destroy(setflag);
    memory->destroy(cutsq);
  }
}

void PairHooke::settings(int narg, char** arg) {
  if (narg < 4) fail(lmp, "pair_style asperity/hooke kn kt gammat xmu table FILE [constant EPS|none] seed S ...");
  read_contact_numbers(lmp, arg, &kn_, &kt_, &gammat_, &xmu_);
  draw_.reset();  // settings given again for the same style: start from none
  std::string why;
  for (int i = 4; i < narg;) {
    const int used = draw_.keyword(narg, arg, i, why);
    if (used < 0) fail(lmp, "pair_style asperity/hooke: " + why);
    if (used == 0) fail(lmp, std::string("pair_style asperity/hooke: unknown keyword '") + arg[i] + "'");
    i += used;
  }
  if (!draw_.finish(comm->me, why)) fail(lmp, "pair_style asperity/hooke: " + why);
}

// pair_coeff I J                     the style's table (or constant)
// pair_coeff I J table FILE          this type pair draws from its own table (cortable: the same)
// pair_coeff I J constant EPS        this type pair has one eps
void PairHooke::coeff(int narg, char** arg) {
  if (narg != 2 && narg != 4)
    fail(lmp, "pair_coeff I J [table FILE | cortable FILE | constant EPS] for asperity/hooke");
  const int n = atom->ntypes;
  if (!allocated) {
    memory->create(setflag, n + 1, n + 1, "pair:setflag");
    memory->create(cutsq, n + 1, n + 1, "pair:cutsq");
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) setflag[i][j] = 0;
    source_of_.assign(static_cast<std::size_t>((n + 1) * (n + 1)), -1);
    allocated = 1;
  }
  int ilo, ihi, jlo, jhi;
  utils::bounds(FLERR, arg[0], 1, n, ilo, ihi, error);
  utils::bounds(FLERR, arg[1], 1, n, jlo, jhi, error);
  int source = -1;  // the style's own
  if (narg == 4) {
    const std::string k = arg[2];
    auto src = std::make_unique<Source>();
    if (k == "table" || k == "cortable") {
      char err[512];
      if (asperity_cor_load(&src->table, arg[3], err, sizeof err) != 0)
        fail(lmp, std::string("pair_coeff ") + arg[0] + " " + arg[1] + " asperity/hooke: table: " + err);
      src->have_table = true;
      if (!draw_.has_seed()) fail(lmp, "pair_coeff ... table needs 'seed S' in pair_style asperity/hooke");
    } else if (k == "constant") {
      char* end = nullptr;
      const double x = std::strtod(arg[3], &end);
      if (!*arg[3] || *end || !(x >= 0.0 && x <= 1.0))
        fail(lmp, std::string("pair_coeff asperity/hooke: constant '") + arg[3] + "': eps must lie in [0, 1]");
      src->constant = x;
    } else {
      fail(lmp, "pair_coeff asperity/hooke: unknown keyword '" + k + "' (table, cortable or constant)");
    }
    sources_.push_back(std::move(src));
    source = static_cast<int>(sources_.size()) - 1;
  }
  int count = 0;
  for (int i = ilo; i <= ihi; ++i)
    for (int j = std::max(jlo, i); j <= jhi; ++j) {
      setflag[i][j] = 1, ++count;
      source_of_[static_cast<std::size_t>(i * (n + 1) + j)] = source;
      source_of_[static_cast<std::size_t>(j * (n + 1) + i)] = source;
    }
  if (count == 0) fail(lmp, "pair_coeff for asperity/hooke: no type pair in " + std::string(arg[0]) + " " + arg[1]);
}

void PairHooke::init_style() {
  require_sphere(lmp, "pair_style asperity/hooke");
  if (!comm->ghost_velocity) fail(lmp, "pair_style asperity/hooke needs 'comm_modify vel yes'");
  // Every rank keeps both sides' records of a pair it sees and integrates them itself: newton off.
  if (force->newton_pair) fail(lmp, "pair_style asperity/hooke needs 'newton off'");
  if (modify->find_fix(records_id_) < 0)
    modify->add_fix(records_id_ + " all asperity/records " + std::to_string(kSlots0) + " " + std::to_string(WIDTH));
  records_ = static_cast<FixRecords*>(modify->fix[modify->find_fix(records_id_)]);
  records_->set_summary(&draw_, "pair_style asperity/hooke", true);
  speed_si_ = speed_unit_si(lmp, "pair_style asperity/hooke");
  // The largest radius per type, of the atoms present and of those that fix pour and fix deposit will
  // insert (their extract("radius", type), as gran/hooke/history does): the cutoff of a type pair is
  // the sum of the two, so that poured atoms meet their contacts before they overlap.
  const int nt = atom->ntypes;
  std::vector<double> mine(nt + 1, 0.0);
  for (int f = 0; f < modify->nfix; ++f) {
    const std::string style = modify->fix[f]->style;
    if (style != "pour" && style != "deposit") continue;
    for (int t = 1; t <= nt; ++t) {
      int type = t;  // extract() may change it
      const void* r = modify->fix[f]->extract("radius", type);
      if (r) mine[t] = std::fmax(mine[t], *static_cast<const double*>(r));
    }
  }
  for (int i = 0; i < atom->nlocal; ++i) mine[atom->type[i]] = std::fmax(mine[atom->type[i]], atom->radius[i]);
  rmax_.assign(nt + 1, 0.0);
  MPI_Allreduce(mine.data(), rmax_.data(), nt + 1, MPI_DOUBLE, MPI_MAX, world);
  if (!(*std::max_element(rmax_.begin(), rmax_.end()) > 0.0))
    fail(lmp, "pair_style asperity/hooke: no atom with a radius > 0, and no fix pour or fix deposit to insert one");
  neighbor->request(this, instance_me);
}

double PairHooke::init_one(int i, int j) {
  const double cut = rmax_[i] + rmax_[j];
  // a type pair with no atom of either type yet: the largest cutoff (LAMMPS needs one > 0)
  return cut > 0.0 ? cut : 2.0 * *std::max_element(rmax_.begin(), rmax_.end());
}

// An atom's active records are kept at the front of its slots (forget_ended compacts them), so a
// search stops at the first free slot: one or two comparisons for a particle with one contact.
double* PairHooke::find_or_add(int i, tagint partner, bool& fresh) {
  const double key = static_cast<double>(partner);
  const int slots = records_->slots();
  for (int s = 0; s < slots; ++s) {
    double* r = records_->record(i, s);
    if (r[PARTNER] == key) {
      fresh = false;
      return r;
    }
    if (r[PARTNER] == 0.0) {
      std::memset(r, 0, sizeof(double) * WIDTH);
      r[PARTNER] = key;
      fresh = true;
      return r;
    }
  }
  // every slot of i is in use: more slots for all atoms (no fixed cap; pointers into records move)
  if (slots >= 65535) fail_one(lmp, "pair_style asperity/hooke: atom " + std::to_string(atom->tag[i]) + " has 65535 contacts");
  records_->grow_slots(slots + 1);
  double* r = records_->record(i, slots);
  r[PARTNER] = key;
  fresh = true;
  return r;
}

// Drops the records of contacts not touched in this step (they ended), keeping the active ones at the
// front. Fast path: touched_[i] counts the distinct records of i touched in this step; when the slot
// after them is free, they are all of i's records (active records are contiguous from slot 0), and
// nothing ended.
void PairHooke::forget_ended() {
  const double now = static_cast<double>(update->ntimestep);
  const int slots = records_->slots();
  for (int i = 0; i < atom->nlocal; ++i) {
    const int k = touched_[i];
    if (k < slots && records_->record(i, k)[PARTNER] == 0.0) continue;  // all touched (or none active)
    int n = 0;
    while (n < slots && records_->record(i, n)[PARTNER] != 0.0) ++n;
    for (int s = 0; s < n;) {
      double* r = records_->record(i, s);
      if (r[TOUCHED] == now) {
        ++s;
        continue;
      }
      double* last = records_->record(i, --n);  // the contact ended: the last active record takes its slot
      if (last != r) std::memcpy(r, last, sizeof(double) * WIDTH);
      std::memset(last, 0, sizeof(double) * WIDTH);
    }
  }
}

void PairHooke::compute(int eflag, int vflag) {
  ev_init(eflag, vflag);
  double **x = atom->x, **v = atom->v, **f = atom->f, **omega = atom->omega, **torque = atom->torque;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const tagint* tag = atom->tag;
  const int* type = atom->type;
  const int nlocal = atom->nlocal;
  const bigint step = update->ntimestep;
  Params p{kn_, 0.0, kt_, gammat_, xmu_, update->dt, update->setupflag == 0};
  // Slot hints, one pair per neighbour-list entry (the slot of the contact in i's and in j's records the
  // last time it was found), rebuilt with the list; a hint is used only after its record's partner id
  // has been checked, so a stale one (records compacted by forget_ended) costs one search, no error.
  if (update->setupflag || neighbor->lastcall != hints_step_ || hint_first_.size() != static_cast<std::size_t>(list->inum) + 1) {
    hints_step_ = neighbor->lastcall;
    hint_first_.assign(static_cast<std::size_t>(list->inum) + 1, 0);
    for (int ii = 0; ii < list->inum; ++ii) hint_first_[ii + 1] = hint_first_[ii] + list->numneigh[list->ilist[ii]];
    hints_.assign(2 * static_cast<std::size_t>(hint_first_.back()), 0);
  }
  const double now = static_cast<double>(step);
  touched_.assign(static_cast<std::size_t>(nlocal), 0);
  for (int ii = 0; ii < list->inum; ++ii) {
    const int i = list->ilist[ii];
    const int* jlist = list->firstneigh[i];
    std::uint16_t* hint = hints_.data() + 2 * static_cast<std::size_t>(hint_first_[ii]);
    for (int jj = 0; jj < list->numneigh[i]; ++jj, hint += 2) {
      const int j = jlist[jj] & NEIGHMASK;
      Contact c;
      for (int d = 0; d < 3; ++d) c.del[d] = x[i][d] - x[j][d];
      const double rsq = c.del[0] * c.del[0] + c.del[1] * c.del[1] + c.del[2] * c.del[2];
      const double radsum = radius[i] + radius[j];
      if (rsq >= radsum * radsum) continue;  // not touching: its records are dropped below
      c.r = std::sqrt(rsq);
      const double rinv = 1.0 / c.r;
      c.overlap = radsum - c.r;
      for (int d = 0; d < 3; ++d) {
        c.vr[d] = v[i][d] - v[j][d];
        c.wr[d] = (radius[i] * omega[i][d] + radius[j] * omega[j][d]) * rinv;
      }
      c.meff = rmass[i] * rmass[j] / (rmass[i] + rmass[j]);
      bool fresh_i = false, fresh_j = false;
      // (a hint is always < the slots: it comes from slot_of, and the slots only grow)
      double* ri = records_->record(i, hint[0]);
      if (ri[PARTNER] != static_cast<double>(tag[j])) {
        ri = find_or_add(i, tag[j], fresh_i);
        hint[0] = slot_of(i, ri);
      }
      double* rj = nullptr;
      if (j < nlocal) {
        rj = records_->record(j, hint[1]);
        if (rj[PARTNER] != static_cast<double>(tag[i])) {
          rj = find_or_add(j, tag[i], fresh_j);
          hint[1] = slot_of(j, rj);
          ri = records_->record(i, hint[0]);  // j's search may have grown the slots (and moved i's records)
        }
      }
      if (fresh_i) {
        // First touch: the approach speed now selects the table's row; one draw for the contact.
        const double vn = -speed_si_ * (c.vr[0] * c.del[0] + c.vr[1] * c.del[1] + c.vr[2] * c.del[2]) / c.r;
        const std::uint64_t a = static_cast<std::uint64_t>(tag[i] < tag[j] ? tag[i] : tag[j]);
        const std::uint64_t b = static_cast<std::uint64_t>(tag[i] < tag[j] ? tag[j] : tag[i]);
        const double u = contact_uniform(draw_.seed(), a, b, step, ContactKind::pair);
        Flag flag;
        ri[START] = static_cast<double>(step);
        const int src = source_of_[static_cast<std::size_t>(type[i] * (atom->ntypes + 1) + type[j])];
        if (src < 0) {
          ri[EPS] = draw_.eps(vn, u, flag);
        } else {
          const Source& so = *sources_[static_cast<std::size_t>(src)];
          ri[EPS] = Draw::eps_from(so.have_table ? &so.table : nullptr, so.constant, vn, u, flag);
        }
        ri[GAMMA] = draw_.gamma(ri[EPS], kn_, c.meff);
        if (j < nlocal || tag[i] < tag[j]) {  // once per contact, on one rank
          draw_.log(step, ContactKind::pair, a, b, vn, u, ri[EPS], ri[GAMMA], flag);
          draw_.counts().n[static_cast<int>(flag)] += 1;
          if (j >= nlocal) draw_.counts().remote += 1;
          if (draw_.refuse_outside() && (flag == Flag::below || flag == Flag::above))
            fail_one(lmp, "pair_style asperity/hooke: atoms " + std::to_string(a) + " and " + std::to_string(b) +
                              " meet at " + std::to_string(vn) + " m/s, outside the table's speeds (outside error)");
        }
      }
      p.gamma = ri[GAMMA];
      double fij[3], fs[3];
      hooke(c, p, ri + SHEAR, fij, fs);
      touched_[i] += ri[TOUCHED] != now;
      ri[TOUCHED] = now;
      const double tor[3] = {(c.del[1] * fs[2] - c.del[2] * fs[1]) * rinv, (c.del[2] * fs[0] - c.del[0] * fs[2]) * rinv,
                             (c.del[0] * fs[1] - c.del[1] * fs[0]) * rinv};
      for (int d = 0; d < 3; ++d) {
        f[i][d] += fij[d];
        torque[i][d] -= radius[i] * tor[d];
      }
      if (rj) {
        // j's record mirrors i's: same contact, same eps and gamma, the shear history seen from j.
        if (fresh_j) rj[START] = ri[START], rj[EPS] = ri[EPS], rj[GAMMA] = ri[GAMMA];
        for (int d = 0; d < 3; ++d) {
          rj[SHEAR + d] = -ri[SHEAR + d];
          f[j][d] -= fij[d];
          torque[j][d] -= radius[j] * tor[d];
        }
        touched_[j] += rj[TOUCHED] != now;
        rj[TOUCHED] = now;
      }
      if (evflag) ev_tally_xyz(i, j, nlocal, 0, 0.0, 0.0, fij[0], fij[1], fij[2], c.del[0], c.del[1], c.del[2]);
    }
  }
  forget_ended();
  if (!draw_.flush_log()) fail_one(lmp, "pair_style asperity/hooke: cannot write the log");
}

// ---- FixWall ----

FixWall::FixWall(LAMMPS* lmp, int narg, char** arg) : FixRecords(lmp, 3, arg, 1, WIDTH) {
  // fix ID group asperity/wall/hooke kn kt gammat xmu zplane zlo table FILE [constant EPS|none] seed S [wall N] ...
  if (narg < 9 || (std::strcmp(arg[7], "zplane") != 0 && std::strcmp(arg[7], "zcylinder") != 0))
    fail(lmp, "fix asperity/wall/hooke kn kt gammat xmu zplane ZLO|zcylinder RADIUS table FILE [constant EPS|none] seed S "
                      "[wall N] [scale_damping X] [log FILE]");
  read_contact_numbers(lmp, arg + 3, &kn_, &kt_, &gammat_, &xmu_);
  cylinder_ = std::strcmp(arg[7], "zcylinder") == 0;
  zlo_ = utils::numeric(FLERR, arg[8], false, lmp);  // zplane: the plane z = zlo; zcylinder: the radius about the z axis
  if (cylinder_ && !(zlo_ > 0.0)) fail(lmp, std::string("fix asperity/wall/hooke: zcylinder radius '") + arg[8] + "' must be > 0");
  std::string why;
  for (int i = 9; i < narg;) {
    if (std::strcmp(arg[i], "wall") == 0) {
      if (i + 1 >= narg) fail(lmp, "fix asperity/wall/hooke: 'wall' needs a number");
      wall_ = static_cast<std::uint64_t>(utils::bnumeric(FLERR, arg[i + 1], false, lmp));
      i += 2;
      continue;
    }
    const int used = draw_.keyword(narg, arg, i, why);
    if (used < 0) fail(lmp, "fix asperity/wall/hooke: " + why);
    if (used == 0) fail(lmp, std::string("fix asperity/wall/hooke: unknown keyword '") + arg[i] + "'");
    i += used;
  }
  if (!draw_.finish(comm->me, why)) fail(lmp, "fix asperity/wall/hooke: " + why);
  set_summary(&draw_, std::string("fix ") + id + " asperity/wall/hooke", false);
}

int FixWall::setmask() { return LAMMPS_NS::FixConst::POST_FORCE; }

void FixWall::init() {
  require_sphere(lmp, "fix asperity/wall/hooke");
  speed_si_ = speed_unit_si(lmp, "fix asperity/wall/hooke");
}

void FixWall::setup(int vflag) { post_force(vflag); }

void FixWall::post_force(int) {
  double **x = atom->x, **v = atom->v, **f = atom->f, **omega = atom->omega, **torque = atom->torque;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int* mask = atom->mask;
  const tagint* tag = atom->tag;
  const bigint step = update->ntimestep;
  Params p{kn_, 0.0, kt_, gammat_, xmu_, update->dt, update->setupflag == 0};
  for (int i = 0; i < atom->nlocal; ++i) {
    double* rec = record(i, 0);
    // the distance from the wall, and del = x_i - the wall's nearest point: the plane below the
    // particle, or the cylinder about the z axis around it (the particle inside)
    Contact c;
    double dist;
    if (cylinder_) {
      const double rxy = std::sqrt(x[i][0] * x[i][0] + x[i][1] * x[i][1]);
      dist = zlo_ - rxy;
      const double s = rxy > 0.0 ? -dist / rxy : 0.0;
      c.del[0] = s * x[i][0], c.del[1] = s * x[i][1], c.del[2] = 0.0;
    } else {
      dist = x[i][2] - zlo_;
      c.del[0] = c.del[1] = 0.0, c.del[2] = dist;
    }
    if (!(mask[i] & groupbit) || dist >= radius[i] || dist <= 0.0) {
      std::memset(rec, 0, sizeof(double) * WIDTH);  // not touching (or through the wall): no contact
      continue;
    }
    c.r = dist;
    c.overlap = radius[i] - dist;
    for (int d = 0; d < 3; ++d) c.vr[d] = v[i][d], c.wr[d] = radius[i] * omega[i][d] / dist;
    c.meff = rmass[i];  // the wall's mass is infinite
    if (rec[ACTIVE] == 0.0) {
      const double vn = -speed_si_ * (v[i][0] * c.del[0] + v[i][1] * c.del[1] + v[i][2] * c.del[2]) / dist;
      const double u = contact_uniform(draw_.seed(), static_cast<std::uint64_t>(tag[i]), wall_, step, ContactKind::wall);
      Flag flag;
      rec[ACTIVE] = 1.0;
      rec[START] = static_cast<double>(step);
      rec[EPS] = draw_.eps(vn, u, flag);
      rec[GAMMA] = draw_.gamma(rec[EPS], kn_, c.meff);
      draw_.log(step, ContactKind::wall, static_cast<std::uint64_t>(tag[i]), wall_, vn, u, rec[EPS], rec[GAMMA], flag);
      draw_.counts().n[static_cast<int>(flag)] += 1;
      if (draw_.refuse_outside() && (flag == Flag::below || flag == Flag::above))
        fail_one(lmp, "fix asperity/wall/hooke: atom " + std::to_string(tag[i]) + " meets the wall at " +
                          std::to_string(vn) + " m/s, outside the table's speeds (outside error)");
    }
    p.gamma = rec[GAMMA];
    double fw[3], fs[3];
    hooke(c, p, rec + SHEAR, fw, fs);
    for (int d = 0; d < 3; ++d) f[i][d] += fw[d];
    torque[i][0] -= radius[i] * (c.del[1] * fs[2] - c.del[2] * fs[1]) / c.r;
    torque[i][1] -= radius[i] * (c.del[2] * fs[0] - c.del[0] * fs[2]) / c.r;
    torque[i][2] -= radius[i] * (c.del[0] * fs[1] - c.del[1] * fs[0]) / c.r;
  }
  if (!draw_.flush_log()) fail_one(lmp, "fix asperity/wall/hooke: cannot write the log");
}

// ---- Registration ----

namespace {
Pair* make_pair(LAMMPS* lmp) { return new PairHooke(lmp); }
Fix* make_records(LAMMPS* lmp, int narg, char** arg) { return new FixRecords(lmp, narg, arg); }
Fix* make_wall(LAMMPS* lmp, int narg, char** arg) { return new FixWall(lmp, narg, arg); }
}  // namespace

void register_styles(LAMMPS* lmp) {
  (*lmp->force->pair_map)["asperity/hooke"] = &make_pair;
  (*lmp->modify->fix_map)["asperity/records"] = &make_records;
  (*lmp->modify->fix_map)["asperity/wall/hooke"] = &make_wall;
}

}  // namespace asperity_dem
