// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The planner: from a scene's requested outputs, the stages a run needs -- and nothing else.
// Every stage is listed, run or skipped, with the reason; report.json carries the list (`plan`)
// with the wall time of each stage that ran.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "asperity/app/scene.hpp"

namespace asperity {

struct PlanStage {
  std::string name;    ///< "generate", "index", "query", "cross_check", "impact", "analysis", "plots"
  bool run = false;
  std::string reason;  ///< why it runs, or why it is skipped
  double seconds = 0;  ///< wall time [s] once run (0 if skipped)
};

struct Plan {
  /// The scene as it will run: ensemble.backend resolved (backend "auto"), ensemble.impact.enabled
  /// only if the impact stage runs. Everything else as given.
  Scene scene;
  std::vector<PlanStage> stages;

  bool runs(std::string_view stage) const;
  /// Throws std::out_of_range for an unknown name.
  PlanStage& stage(std::string_view name);
};

/// Backend "auto" in fixed mode: with fewer rotations per sphere than this, a brute scan of each
/// sphere (no index) is cheaper than building the grid. Break-even ~ grid build / (brute query -
/// grid query) = 45 ns N / 1.3 ns N ~ 35 rotations from bench/RESULTS.md, measured directly by
/// bench_scenes (bench/RESULTS.md "Planner").
inline constexpr std::uint64_t kScanBelowRotations = 32;

/// The stages `s` needs. Pure: runs nothing. Expects a validated scene.
Plan make_plan(const Scene& s);

}  // namespace asperity
