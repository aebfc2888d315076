// SPDX-License-Identifier: GPL-3.0-or-later
// bench_scenes: what the planner saves. A plain std::chrono driver printing markdown (the text of
// bench/RESULTS.md "Planner").
//
// Part 1 (savings): whole runs (asperity::run_scene: ensemble + analysis, no figures, no report
// file) of the same scene with different requested outputs or backend choices; median wall time
// over --repeats runs and the median time of each planned stage.
// Part 2 (scan or index): fixed mode, K spheres x M rotations, contact only: the ensemble's wall
// time (run_contact_ensemble: generation + index + queries) with a brute scan and with the grid,
// for several M. The crossing point is what backend "auto" uses (plan.hpp kScanBelowRotations).
//
// --scan-only: part 2 only.
// --quick: seconds-long smoke run on tiny scenes (checks the harness, never a timing).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "asperity/app/plan.hpp"
#include "asperity/app/run.hpp"
#include "asperity/app/scene.hpp"
#include "timing.hpp"

using namespace asperity;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

using asperity::bench::median;

std::string loadavg() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

struct Case {
  std::string label;
  Scene scene;
};

// Runs every case `repeats` times, interleaved (so that a change of machine load hits all cases
// alike); prints one row per case.
void savings(const std::string& title, const std::vector<Case>& cases, int repeats) {
  std::vector<std::vector<double>> wall(cases.size());
  std::vector<std::map<std::string, std::vector<double>>> stages(cases.size());
  std::vector<std::string> ran(cases.size());
  for (int r = 0; r < repeats; ++r)
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const auto t0 = Clock::now();
      const GeometryReport rep = run_scene(cases[i].scene);
      wall[i].push_back(since(t0));
      ran[i].clear();
      for (const auto& st : rep.plan) {
        if (!st.run) continue;
        stages[i][st.name].push_back(st.seconds);
        ran[i] += (ran[i].empty() ? "" : ", ") + st.name;
      }
    }
  std::cout << "\n### " << title << "\n\n| outputs | stages run | generate s | index s | query s | impact s | analysis s | "
                                    "total s (median) | vs first row |\n|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
  const double base = median(wall[0]);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    std::cout << "| " << cases[i].label << " | " << ran[i];
    for (const char* st : {"generate", "index", "query", "impact", "analysis"}) {
      const auto it = stages[i].find(st);
      std::cout << " | " << (it == stages[i].end() ? std::string("—") : fmt(median(it->second)));
    }
    const double m = median(wall[i]);
    std::cout << " | " << fmt(m) << " | " << (i == 0 ? std::string("1") : fmt(base / m) + "x faster") << " |\n";
  }
}

void scan_or_index(std::uint64_t n, std::uint64_t spheres, const std::vector<std::uint64_t>& rotations, int repeats) {
  std::cout << "\n### Scan or index: N = " << n << ", K = " << spheres
            << " spheres, contact only (run_contact_ensemble wall time, median of " << repeats
            << ")\n\n| rotations per sphere M | brute s | grid s | grid / brute | auto picks |\n|---:|---:|---:|---:|:---|\n";
  for (const auto m : rotations) {
    EnsembleConfig c;
    c.sphere.asperities = n;
    c.mode = Mode::explicit_spheres;
    c.spheres = spheres;
    c.drops = std::max<std::uint64_t>(2, spheres * m);
    std::vector<double> tb, tg;
    for (int r = 0; r < repeats; ++r) {
      c.backend = Backend::brute;
      auto t0 = Clock::now();
      const auto a = run_contact_ensemble(c);
      tb.push_back(since(t0));
      c.backend = Backend::grid;
      t0 = Clock::now();
      const auto b = run_contact_ensemble(c);
      tg.push_back(since(t0));
      if (a.r_xy != b.r_xy) {
        std::cerr << "bench_scenes: brute and grid disagree (N = " << n << ", M = " << m << ")\n";
        std::exit(2);
      }
    }
    const double b = median(tb), g = median(tg);
    std::cout << "| " << m << " | " << fmt(b) << " | " << fmt(g) << " | " << fmt(g / b) << " | "
              << (m < kScanBelowRotations ? "brute" : "grid") << " |\n";
  }
}

// Part 1: the same scene with different outputs / backend choices.
void whole_runs(bool quick, int repeats) {
  // fig4 with three choices of outputs.
  Scene fig4 = preset("fig4");
  fig4.plots = false;
  if (quick) fig4.ensemble.drops = 20000;
  Scene contact_only = fig4, restitution_only = fig4;
  contact_only.restitution_stats = false;
  restitution_only.contact_stats = false;
  savings("fig4 (N = 1e5, " + std::to_string(fig4.ensemble.drops) + " fresh drops, V = 1.3 m/s, Omega_x = 0.2 rad/s)",
          {{"contact + restitution (preset)", fig4},
           {"contact only (restitution = false)", contact_only},
           {"restitution only (contact = false)", restitution_only}},
          repeats);

  // Many explicit spheres with one rotation each: building a grid per sphere does not pay.
  Scene fixed = preset("fig3-fixed");
  fixed.plots = false;
  fixed.ensemble.spheres = quick ? 20 : 1000;
  fixed.ensemble.drops = fixed.ensemble.spheres;  // one rotation per sphere
  if (quick) fixed.ensemble.sphere.asperities = 10000;
  Scene fixed_auto = fixed;
  fixed_auto.backend_auto = true;
  savings("fig3-fixed with " + std::to_string(fixed.ensemble.spheres) + " spheres x 1 rotation (N = " +
              std::to_string(fixed.ensemble.sphere.asperities) + ")",
          {{"backend = \"grid\" (preset)", fixed}, {"backend = \"auto\" (scan)", fixed_auto}}, repeats);
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, scan_only = false;
  int repeats = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      quick = true;
    } else if (a == "--scan-only") {
      scan_only = true;
    } else if (a == "--repeats" && i + 1 < argc) {
      repeats = std::atoi(argv[++i]);
      if (repeats < 1) {
        std::cerr << "bench_scenes: --repeats must be >= 1\n";
        return 2;
      }
    } else {
      std::cerr << "usage: bench_scenes [--quick] [--scan-only] [--repeats R]\n";
      return 2;
    }
  }
  if (quick) repeats = 1;
  const auto start = Clock::now();
  const std::time_t now = std::time(nullptr);
  char when[64];
  std::strftime(when, sizeof when, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::cout << "bench_scenes " << (quick ? "--quick " : "") << "started " << when << ", load average " << loadavg()
            << "\n";

  if (!scan_only) whole_runs(quick, repeats);
  if (quick) {
    scan_or_index(2000, 8, {1, 64}, 1);
  } else {
    scan_or_index(10000, 256, {1, 8, 16, 32, 64, 128}, repeats);
    scan_or_index(100000, 64, {1, 8, 16, 32, 64, 128}, repeats);
  }
  std::cout << "\ntotal " << fmt(since(start)) << " s wall, load average after " << loadavg() << "\n";
  return 0;
}
