// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The kinds of run, one row each (the shape of LAMMPS's style registry, for a closed set): what a
// kind is called, how a scene is recognised as one, which stages it plans before it runs, what
// memory it needs and what a user can lower, and how it runs. Everything one kind knows lives in
// its own file, src/app/runs/<kind>.cpp; a new kind is one file and one row (kinds.cpp).
// Internal to the library: not installed.
#include <chrono>
#include <filesystem>
#include <iosfwd>
#include <sstream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "app/collective.hpp"
#include "asperity/app/plan.hpp"
#include "asperity/app/report.hpp"
#include "asperity/app/run.hpp"
#include "asperity/experiments/body_experiments.hpp"

namespace asperity::runs {

/// Where a run reports progress and writes its files (the arguments of run_plan, run.hpp).
struct RunIO {
  const Progress& progress;
  std::ostream* log = nullptr;          ///< one line per bounce variant
  std::filesystem::path dir;            ///< where figures and other files are written
  Collective* group = nullptr;          ///< streaming sphere runs split across processes
  ContactSamples* keep = nullptr;       ///< sphere runs that keep their drops (asperity.run's arrays)
};

struct Kind {
  RunKind kind;
  std::string_view name;  ///< as report.json and the messages say it
  /// Whether a scene is this kind (rows are asked in table order; the first that says yes wins).
  bool (*recognise)(const Scene&);
  /// The stages decided before the run (null: the kind lists its stages as it runs).
  void (*plan)(Plan&);
  /// The kind's own peak memory [bytes] (figures are added by estimate_memory), with what it is
  /// made of written to `detail`.
  double (*estimate)(const Plan&, std::ostringstream& detail);
  /// The scene keys (with their options) a user can lower when the run does not fit.
  std::string (*lower)(const Scene&);
  /// Runs the plan and renders its report (never the report files: the caller writes them).
  SceneOutput (*run)(const Plan&, const RunIO&);
};

/// Every kind, in the order they are recognised.
std::span<const Kind* const> kinds();
/// The row of kind `k`.
const Kind& kind(RunKind k);

// Shared by the kinds' files.
using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
/// A stage of the report's plan; its time only when it ran.
PlanStage stage(std::string name, bool run, std::string reason, double seconds = 0);
PlanStage plots_stage(const Scene& s, double seconds);
/// The report header of a run of `s` from the stages it ran.
ReportHeader header_of(const Scene& s, std::vector<PlanStage> stages);
/// Decisive tests that could not be evaluated, one line each with the reason.
std::vector<std::string> skipped_of(const std::vector<LawCheck>& tests);
/// `v` with 3 significant digits, for the memory details; `bytes` as "1.23 GB".
std::string fmt3(double v);
std::string gb(double bytes);
/// The threads a run uses (ensemble.threads; 0: OpenMP's default).
int threads_of(const Scene& s);
// Measured peak RSS costs shared by several kinds (validate-geometry --no-plots, GCC 12 Release,
// x86-64; /usr/bin/time -f %M on runs of 1e6..4e6 asperities or drops; slope between two sizes):
inline constexpr double kBaseSphere = 10.6e6;  ///< the process with its libraries, sphere runs
inline constexpr double kPerDropFresh = 49;    ///< contact samples per drop
inline constexpr double kPerDropImpact = 92;   ///< + eps, Omega' (fresh or fixed)

/// Impacts of one bounce sequence from b.speed down to b.stop_speed (bounce.cpp, the runs' one):
/// Eq. 9 to leading order, 1 - eps = c u^(1/5), gives k(u) = 5 / c (u_stop^(-1/5) - u_1^(-1/5)),
/// capped at b.max_impacts (a stop speed far below 1e-10 m/s is never reached sooner).
double bounce_impacts(const BounceExperiment& b);

// The rows (one file each).
extern const Kind kSphere, kRadii, kMesh, kBounce, kMeshBounce;

}  // namespace asperity::runs
