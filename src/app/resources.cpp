// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/app/resources.hpp"

#include "asperity/config.hpp"
#include "asperity/experiments/ensemble.hpp"
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

#include "asperity/app/mesh_io.hpp"
#include "asperity/app/plan.hpp"
#include "asperity/app/plot.hpp"
#include "asperity/app/run.hpp"

namespace asperity {

namespace {

// Measured peak RSS costs (validate-geometry --no-plots, GCC 12 Release, x86-64; /usr/bin/time
// -f %M on runs of 1e6..4e6 asperities or drops; slope between two sizes):
constexpr double kBaseSphere = 10.6e6;   // the process with its libraries, sphere runs
constexpr double kBaseMesh = 14.3e6;     // mesh runs (mesh, CGAL support tree code): the intercept of the
                                         // 5e5 / 1e6 asperity runs below
constexpr double kPerFigurePixelScale2 = 3.6e6;  // a PNG figure's raster per S^2 (measured below, estimate())
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
// The cross-check of one sphere (ensemble.cpp cross_check_sphere) while the run's index lives: a
// kd-tree over the same centres unless it is the backend, and FCL's tree for small N (measured:
// brute, one sphere of 2e6: 91.1 MB, 40 B per asperity = the centres + the kd-tree).
double one_sphere_check(Backend b, double N) {
  double extra = b == Backend::kdtree ? 0.0 : per_asperity(Backend::kdtree) - per_asperity(Backend::brute);
#if ASPERITY_WITH_FCL
  if (b != Backend::fcl && N <= double(kCrossCheckFclMax)) extra += per_asperity(Backend::fcl) - per_asperity(Backend::brute);
#endif
  return extra;
}
constexpr double kPerDropFresh = 49;      // contact samples per drop
constexpr double kPerDropFixed = 57;      // + the rotation
constexpr double kPerDropImpact = 92;     // + eps, Omega' (fresh or fixed)
// A mesh file read and checked (read_mesh): CGAL's polygon soup, its repair and orientation, the
// Surface_mesh and the self-intersection test's boxes -- all freed before the bodies are built.
// Measured: 96.5 MB at 159,200 faces, 347.6 MB at 638,400 (closed UV ellipsoids, OFF).
constexpr double kPerMeshFaceRead = 524;
// The TriangleMesh kept for the run: 3 doubles per vertex, 3 indices per face, + the facet
// sampler's cumulative areas (8 B per face).
constexpr double kPerMeshVertexKept = 24, kPerMeshFaceKept = 12 + 8;
// The exported body (outputs.export_ply): its centres and radii (32 B per asperity) + the text
// (ply_text_bytes, one allocation), freed before the run's bodies are built.
constexpr double kPerAsperityExport = 32;
// An unequal-radii sphere screened for lambda_eff (one at a time): centres and radii (32 B), its
// support tree, the screening's unit directions, support radii, competitor counts and status,
// and the per-asperity competitor lists of the cap test. Measured: 256 MB at N = 2.5e5, 503 MB at
// 5e5 (--threads 1; 487 MB with 2 threads): the slope.
constexpr double kPerAsperityScreened = 985;
// A mesh body's asperity: centre, radius, support tree, and the heap validate-geometry keeps
// between bodies (mallopt). Measured (ellipsoid.toml without export, 1 body, --threads 1 and 2):
// 84.8 MB at 5e5, 155.3 MB at 1e6 asperities.
constexpr double kPerAsperityMesh = 141;
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

// A mesh body's own costs besides its asperities: reading the file (the peak while it is read)
// against the kept mesh + the rest of the run (`run`) and the export; the larger one.
double mesh_phases(const Scene& s, double run, std::ostringstream& d) {
  const MeshFileSize f = mesh_file_size(s.mesh->file);
  const double read = kPerMeshFaceRead * double(f.faces);
  const double kept = kPerMeshVertexKept * double(f.vertices) + kPerMeshFaceKept * double(f.faces);
  double exported = 0;
  if (!s.mesh->export_ply.empty()) {
    const PlyStyle style = s.mesh->export_points ? PlyStyle::points : PlyStyle::spheres;
    exported = kPerAsperityExport * double(s.ensemble.sphere.asperities) +
               double(ply_text_bytes(s.ensemble.sphere.asperities, style, f.vertices, f.faces));
  }
  d << "; the mesh: " << count(f.faces) << " faces x " << kPerMeshFaceRead << " B while read, " << gb(kept) << " kept";
  if (exported > 0) d << "; the PLY export: " << gb(exported);
  return std::max({read, kept + run, kept + exported});
}


}  // namespace

MemoryEstimate estimate_memory(const Plan& p) {
  const Scene& s = p.given;
  const auto& e = s.ensemble;
  const double N = double(e.sphere.asperities), n = double(e.drops);
  MemoryEstimate m;
  std::ostringstream d;
  switch (p.kind) {
    case RunKind::sphere: {
      const auto& pe = p.scene.ensemble;
      double per_drop = pe.mode == Mode::sampled ? kPerDropFresh : kPerDropFixed;
      if (pe.impact.enabled) per_drop = kPerDropImpact;
      m.bytes = kBaseSphere + per_drop * n;
      if (p.streams) {
        // Streaming keeps no drop: 3 quantities x (a fine histogram per thread + the merged one +
        // the per-block cells) x 8 B (experiments/streaming.hpp).
        const double fine = std::ldexp(1.0, int(pe.bins_log2)), cells = double(kStreamBlocks << kStreamCoarseLog2);
        // + the fine bins' edges of each distinct reference law (streaming.cpp Binners: r_x and r_y
        // share theirs, r_xy has its own), 8 B per edge.
        const double edges = 2 * 8 * (fine + 1);
        m.bytes = kBaseSphere + 3 * 8 * (fine * (threads_of(s) + 1) + cells) + edges;
        d << "streaming histograms (2^" << pe.bins_log2 << " bins x " << threads_of(s) + 1 << " + " << cells
          << " cells, x 3 quantities x 8 B, + 2 x 2^" << pe.bins_log2 << " bin edges x 8 B; no drop kept)";
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
        // One sphere: the checked sphere's centres are the run's; the trees are extra.
        const double check = pe.spheres <= 1 ? one_sphere_check(pe.backend, N)
                             : pe.backend == Backend::kdtree ? 0.0 : per_asperity(Backend::kdtree);
        m.bytes += concurrent * N * b + N * check;
        d << " + " << fmt(concurrent) << " sphere(s) at once (--threads " << threads_of(s) << ") x " << count(e.sphere.asperities)
          << " asperities x " << b << " B (" << to_string(pe.backend) << ")";
      }
      if (s.cor_table) {  // after the run, its samples freed
        const double table = cor_table_bytes(cor_table_spec(s, *s.cor_table));
        if (table > m.bytes) d << "; outputs.cor_table: " << count(s.cor_table->drops) << " drops per speed x " << kPerDropImpact << " B";
        m.bytes = std::max(m.bytes, table);
      }
      break;
    }
    case RunKind::radii: {
      m.bytes = kBaseSphere + kPerDropFresh * n + N * kPerAsperityScreened;
      d << count(e.drops) << " drops x " << kPerDropFresh << " B + one screened sphere of " << count(e.sphere.asperities) << " asperities x "
        << kPerAsperityScreened << " B";
      break;
    }
    case RunKind::mesh: {
      d << count(e.drops) << " drops x " << kPerDropMesh << " B + one body at a time of " << count(e.sphere.asperities) << " asperities x "
        << kPerAsperityMesh << " B";
      m.bytes = kBaseMesh + mesh_phases(s, kPerDropMesh * n + kPerAsperityMesh * N, d);
      break;
    }
    case RunKind::mesh_bounce: {
      const double K = double(e.spheres);
      const double impacts = kImpactsPerDecade * std::log10(s.bounce.speed / s.bounce.stop_speed);
      const double seq = double(s.bounce.sequences);
      d << count(e.spheres) << " bodies kept x " << count(e.sphere.asperities) << " asperities x " << kPerAsperityMesh << " B + " << count(s.bounce.sequences)
        << " sequences x ~" << fmt(impacts) << " impacts x " << kPerImpactBounce << " B";
      const double run = K * N * kPerAsperityMesh + seq * impacts * kPerImpactBounce;
      m.bytes = kBaseMesh + (s.mesh->file.empty() ? run : mesh_phases(s, run, d));
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
  // Figures: a PNG is drawn as a raster of S^2 times the pixels (--plot-format png@S). Measured
  // peak RSS (validate-geometry -q --asperities 1000 --drops 2000, GCC 12 Release): 32 MB at
  // S = 1, 83 MB at 4, 255 MB at 8, i.e. ~3.6 MB x S^2, of which S = 1 is in the bases above. The
  // estimate ignored it (issue 33 item 8: png@8 estimated 13.6 MB, measured 262 MB).
  if (s.plots) {
    PlotFormats f{false, false, false};
    try {
      f = parse_plot_formats(s.plot_format);
    } catch (const std::exception&) {  // refused elsewhere, naming the option
    }
    if (f.png && f.scale > 1) {
      const double figure = kPerFigurePixelScale2 * (f.scale * f.scale - 1.0);
      m.bytes += figure;
      d << "; figures png@" << f.scale << ": " << kPerFigurePixelScale2 / 1e6 << " MB x (S^2 - 1)";
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
  // What the kernel can hand out now without swapping: on a shared machine physical RAM is not
  // available to one process (a 24 GB sphere on a 25 GB machine with 10 GB in use is OOM-killed,
  // which in Python kills the interpreter).
  if (std::ifstream f("/proc/meminfo"); f)
    for (std::string key; f >> key;) {
      double kb = 0;
      if (!(f >> kb)) break;
      if (key == "MemAvailable:") lower(kb * 1024.0);
      f.ignore(64, '\n');
    }
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

namespace {

// What a user can lower, by the kind of run: the scene keys with their options.
std::string lower_hint(const Scene& s) {
  const std::string N = "asperities.count (--asperities)", drops = "ensemble.drops (--drops)",
                    K = "ensemble.spheres (--spheres)", seq = "experiment.sequences (--sequences)";
  std::string mesh;
  if (s.mesh) {
    mesh = ", the faces of body.mesh";
    if (!s.mesh->export_ply.empty() && !s.mesh->export_points) mesh += " or use outputs.export_style = \"points\"";
  }
  switch (run_kind(s)) {
    case RunKind::sphere: return N + ", " + drops + ", " + K + " or ensemble.threads (--threads)";
    case RunKind::radii: return N + " or " + drops;
    case RunKind::mesh: return N + ", " + drops + ", " + K + mesh;
    case RunKind::bounce: return seq + " or " + N;
    case RunKind::mesh_bounce: return N + ", " + K + ", " + seq + mesh;
  }
  return N;
}

}  // namespace

double cor_table_bytes(const CorTableSpec& spec) {
  // One speed's drops at a time, + the eps-rank order of the omega bands (8 B per drop); the
  // quantiles of every row (8 B each) and their CSV text (~24 characters each).
  const double rows = double(spec.speeds.size()) * double(std::max<std::size_t>(1, spec.spins.size()));
  const double quantiles = rows * double(spec.probabilities) * double(1 + spec.omega_bands);
  return kBaseSphere + (kPerDropImpact + 8.0) * double(spec.drops) + quantiles * (8 + 24);
}

double sphere_bytes(std::uint64_t asperities, Backend b) { return double(asperities) * per_asperity(b); }

void check_bytes(double bytes, const std::string& what, const std::string& lower) {
  const double limit = memory_limit_bytes();
  if (limit > 0 && bytes > limit)
    throw MemoryRefused("this needs about " + gb(bytes) + " of memory (" + what + "), more than the " + gb(limit) +
                        " this process may use: lower " + lower);
}

void check_memory(const Plan& p) {
  const Scene& s = p.given;
  const double limit = memory_limit_bytes();
  if (!(limit > 0)) return;  // unknown: let the allocation decide
  const MemoryEstimate m = estimate_memory(p);
  if (m.bytes > limit)
    throw MemoryRefused("this run needs about " + gb(m.bytes) + " of memory (" + m.detail + "), more than the " +
                                gb(limit) + " this process may use: lower " + lower_hint(s));
}

}  // namespace asperity
