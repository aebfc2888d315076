// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/app/resources.hpp"

#include "asperity/experiments/streaming.hpp"

#include <sys/resource.h>
#include <unistd.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "asperity/app/plan.hpp"
#include "asperity/app/run.hpp"

namespace asperity {

namespace {

// Measured peak RSS costs (validate-geometry --no-plots, GCC 12 Release, x86-64; /usr/bin/time
// -f %M on runs of 1e6..4e6 asperities or drops; slope between two sizes):
constexpr double kBaseSphere = 10.6e6;   // the process with its libraries, sphere runs
constexpr double kBaseMesh = 19.5e6;     // mesh runs (mesh, CGAL support tree code)
// Per asperity of one explicit sphere, centre included, by contact index.
double per_asperity(Backend b) {
  switch (b) {
    case Backend::brute: return 24;   // a scan: the centres only
    case Backend::kdtree: return 39;  // nanoflann
    case Backend::cgal: return 143;
    case Backend::fcl: return 508;
    case Backend::grid: return 73;
  }
  return 508;
}
constexpr double kPerDropFresh = 49;      // contact samples per drop
constexpr double kPerDropFixed = 57;      // + the rotation
constexpr double kPerDropImpact = 92;     // + eps, Omega' (fresh or fixed)
constexpr double kPerAsperityMesh = 160;  // a mesh body's asperity: centre, radius, support tree, and the
                                          // heap validate-geometry keeps between bodies (mallopt)
constexpr double kPerDropMesh = 68;
constexpr double kPerImpactBounce = 64;   // one impact of a bounce sequence, kept for the analysis
// The paper's procedure (paper, paper-printed33, paper-corrected28) holds ~6x more per impact
// (measured: 178 MB at 8000 sequences x 55.5 impacts, 45 MB at 2000).
constexpr double kPerImpactBouncePaper = 380;
constexpr double kImpactsPerDecade = 55.5;  // fig6: 55.5 impacts from 1 m/s down to 0.1 m/s

int threads_of(const Scene& s) {
  if (s.ensemble.threads > 0) return s.ensemble.threads;
#ifdef _OPENMP
  return std::max(1, omp_get_max_threads());
#else
  return 1;
#endif
}

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(3);
  os << v;
  return os.str();
}

std::string count(std::uint64_t v) { return std::to_string(v); }

std::string gb(double bytes) { return fmt(bytes / 1e9) + " GB"; }

}  // namespace

MemoryEstimate estimate_memory(const Scene& s) {
  const auto& e = s.ensemble;
  const double N = double(e.sphere.asperities), n = double(e.drops);
  MemoryEstimate m;
  std::ostringstream d;
  switch (run_kind(s)) {
    case RunKind::sphere: {
      const Plan plan = make_plan(s);
      const auto& pe = plan.scene.ensemble;
      double per_drop = pe.mode == Mode::sampled ? kPerDropFresh : kPerDropFixed;
      if (pe.impact.enabled) per_drop = kPerDropImpact;
      m.bytes = kBaseSphere + per_drop * n;
      if (uses_streaming(pe)) {
        // Streaming keeps no drop: 3 quantities x (a fine histogram per thread + the merged one +
        // the per-block cells) x 8 B (experiments/streaming.hpp).
        const double fine = std::ldexp(1.0, int(pe.bins_log2)), cells = double(kStreamBlocks << kStreamCoarseLog2);
        m.bytes = kBaseSphere + 3 * 8 * (fine * (threads_of(s) + 1) + cells);
        d << "streaming histograms (2^" << pe.bins_log2 << " bins x " << threads_of(s) + 1 << " + " << cells
          << " cells, x 3 quantities x 8 B; no drop kept)";
      } else {
        d << count(e.drops) << " drops x " << per_drop << " B";
      }
      if (pe.mode == Mode::explicit_spheres) {
        // One sphere: its rotations in parallel; K > 1 spheres: one sphere per busy thread
        // (ensemble.cpp), K from the plan (the error budget when spheres = "auto").
        const double concurrent =
            pe.spheres <= 1 ? 1.0 : double(std::min<std::uint64_t>(std::uint64_t(threads_of(s)), pe.spheres));
        const double b = per_asperity(pe.backend);
        // + the kd-tree of the cross-check (one checked sphere at a time, measured when spheres run
        // in parallel), unless it is the backend.
        const double check = pe.spheres <= 1 || pe.backend == Backend::kdtree ? 0.0 : per_asperity(Backend::kdtree);
        m.bytes += concurrent * N * b + N * check;
        d << " + " << fmt(concurrent) << " sphere(s) at once (--threads " << threads_of(s) << ") x " << count(e.sphere.asperities)
          << " asperities x " << b << " B (" << to_string(pe.backend) << ")";
      }
      if (s.cor_table) {  // after the run, its samples freed: one speed's drops at a time
        // + the eps-rank order of the omega bands (8 B per drop)
        const double table = kBaseSphere + (kPerDropImpact + 8.0) * double(s.cor_table->drops);
        if (table > m.bytes) d << "; outputs.cor_table: " << count(s.cor_table->drops) << " drops per speed x " << kPerDropImpact << " B";
        m.bytes = std::max(m.bytes, table);
      }
      break;
    }
    case RunKind::radii: {
      m.bytes = kBaseSphere + kPerDropFresh * n + N * per_asperity(Backend::grid);
      d << count(e.drops) << " drops x " << kPerDropFresh << " B + one screened sphere of " << count(e.sphere.asperities) << " asperities x "
        << per_asperity(Backend::grid) << " B";
      break;
    }
    case RunKind::mesh: {
      m.bytes = kBaseMesh + kPerDropMesh * n + kPerAsperityMesh * N;
      d << count(e.drops) << " drops x " << kPerDropMesh << " B + one body at a time of " << count(e.sphere.asperities) << " asperities x "
        << kPerAsperityMesh << " B";
      break;
    }
    case RunKind::mesh_bounce: {
      const double K = double(e.spheres);
      const double impacts = kImpactsPerDecade * std::log10(s.bounce.speed / s.bounce.stop_speed);
      const double seq = double(s.bounce.sequences);
      m.bytes = kBaseMesh + K * N * kPerAsperityMesh + seq * impacts * kPerImpactBounce;
      d << count(e.spheres) << " bodies kept x " << count(e.sphere.asperities) << " asperities x " << kPerAsperityMesh << " B + " << count(s.bounce.sequences)
        << " sequences x ~" << fmt(impacts) << " impacts x " << kPerImpactBounce << " B";
      break;
    }
    case RunKind::bounce: {
      // Impacts of every sequence of a variant are kept for its analysis; a second variant adds
      // ~a sixth (measured: one variant 42 MB, two 48 MB at 8000 sequences).
      const double impacts = kImpactsPerDecade * std::log10(s.bounce.speed / s.bounce.stop_speed);
      const double seq = double(s.bounce.sequences);
      const double variants = 1.0 + (double(s.bounce.variants.size()) - 1.0) / 6.0;
      double per_impact = kPerImpactBounce;
      for (BounceVariant v : s.bounce.variants)
        if (to_string(v).starts_with("paper")) per_impact = kPerImpactBouncePaper;
      m.bytes = kBaseSphere + seq * impacts * per_impact * variants;
      d << count(s.bounce.sequences) << " sequences x ~" << fmt(impacts) << " impacts x " << per_impact << " B x " << fmt(variants)
        << " (variants)";
      break;
    }
  }
  m.detail = d.str();
  return m;
}

double memory_limit_bytes() {
  const double pages = double(::sysconf(_SC_PHYS_PAGES)), page = double(::sysconf(_SC_PAGESIZE));
  double limit = pages > 0 && page > 0 ? pages * page : 0;
  auto lower = [&](double v) {
    if (v > 0 && (limit == 0 || v < limit)) limit = v;
  };
  // cgroup v2 (containers, systemd slices): "max" or bytes.
  if (std::ifstream f("/sys/fs/cgroup/memory.max"); f) {
    std::string t;
    f >> t;
    if (!t.empty() && t != "max") lower(std::strtod(t.c_str(), nullptr));
  }
  struct rlimit r {};
  if (::getrlimit(RLIMIT_AS, &r) == 0 && r.rlim_cur != RLIM_INFINITY) lower(double(r.rlim_cur));
  return limit;
}

void check_memory(const Scene& s) {
  const double limit = memory_limit_bytes();
  if (!(limit > 0)) return;  // unknown: let the allocation decide
  const MemoryEstimate m = estimate_memory(s);
  if (m.bytes > limit)
    throw std::invalid_argument("this run needs about " + gb(m.bytes) + " of memory (" + m.detail + "), more than the " +
                                gb(limit) + " this process may use: lower --asperities, --drops, --spheres, --threads or "
                                "--sequences");
}

}  // namespace asperity
