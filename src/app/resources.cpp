// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/app/resources.hpp"

#include "asperity/config.hpp"
#include "asperity/experiments/ensemble.hpp"
#include "asperity/experiments/streaming.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "asperity/app/plan.hpp"
#include "asperity/app/plot.hpp"
#include "app/runs/kinds.hpp"

namespace asperity {

namespace {

// Measured peak RSS costs (validate-geometry --no-plots, GCC 12 Release, x86-64; /usr/bin/time
// -f %M). Each kind of run estimates its own (src/app/runs/<kind>.cpp); here: what they share.
constexpr double kPerFigurePixelScale2 = 3.6e6;  // a PNG figure's raster per S^2 (measured below, estimate())

std::string gb(double bytes) { return runs::gb(bytes); }

// Figures: a PNG is drawn as a raster of S^2 times the pixels (--plot-format png@S). Measured
// peak RSS (validate-geometry -q --asperities 1000 --drops 2000, GCC 12 Release): 32 MB at
// S = 1, 83 MB at 4, 255 MB at 8, i.e. ~3.6 MB x S^2, of which S = 1 is in the kinds' bases. The
// estimate ignored it (issue 33 item 8: png@8 estimated 13.6 MB, measured 262 MB).
double figure_bytes(const Scene& s, std::ostringstream& d) {
  if (!s.plots) return 0;
  PlotFormats f{false, false, false};
  try {
    f = parse_plot_formats(s.plot_format);
  } catch (const std::exception&) {  // refused elsewhere, naming the option
  }
  if (!(f.png && f.scale > 1)) return 0;
  d << "; figures png@" << f.scale << ": " << kPerFigurePixelScale2 / 1e6 << " MB x (S^2 - 1)";
  return kPerFigurePixelScale2 * (f.scale * f.scale - 1.0);
}

}  // namespace

double bytes_per_asperity(Backend b) {
  switch (b) {
    case Backend::brute: return 24;   // a scan: the centres only
    case Backend::kdtree: return 39;  // nanoflann
    case Backend::cgal: return 143;
    case Backend::fcl: return 508;
    case Backend::grid: return 73;
  }
  return 508;
}

MemoryEstimate estimate_memory(const Plan& p) {
  std::ostringstream d;
  MemoryEstimate m;
  m.bytes = runs::kind(p.kind).estimate(p, d);
  m.bytes += figure_bytes(p.given, d);
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

double cor_table_bytes(const CorTableSpec& spec) {
  // One speed's drops at a time, + the eps-rank order of the omega bands (8 B per drop); the
  // quantiles of every row (8 B each) and their CSV text (~24 characters each).
  const double rows = double(spec.speeds.size()) * double(std::max<std::size_t>(1, spec.spins.size()));
  const double quantiles = rows * double(spec.probabilities) * double(1 + spec.omega_bands);
  return runs::kBaseSphere + (runs::kPerDropImpact + 8.0) * double(spec.drops) + quantiles * (8 + 24);
}

double sphere_bytes(std::uint64_t asperities, Backend b) { return double(asperities) * bytes_per_asperity(b); }

void check_bytes(double bytes, const std::string& what, const std::string& lower) {
  const double limit = memory_limit_bytes();
  if (limit > 0 && bytes > limit)
    throw MemoryRefused("this needs about " + gb(bytes) + " of memory (" + what + "), more than the " + gb(limit) +
                        " this process may use: lower " + lower);
}

void check_memory(const Plan& p) {
  const double limit = memory_limit_bytes();
  if (!(limit > 0)) return;  // unknown: let the allocation decide
  const MemoryEstimate m = estimate_memory(p);
  if (m.bytes > limit)
    throw MemoryRefused("this run needs about " + gb(m.bytes) + " of memory (" + m.detail + "), more than the " +
                                gb(limit) + " this process may use: lower " + runs::kind(p.kind).lower(p.given));
}

}  // namespace asperity
