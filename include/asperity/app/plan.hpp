// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The planner: the one place that decides how a scene runs. plan(scene, control) is called once
// per run (validate-geometry, asperity.run, run_scene_output): it checks the scene's cross-key
// rules (validate), resolves every "auto" (spheres, backend), decides the stages and whether the
// run streams, reads each file the scene names once (a mesh body's mesh, kept in the plan),
// checks the memory and the checkpoint files. Nothing else decides any of these: every later
// step reads the Plan, never the scene as written. report.json carries the stages (`plan`) with
// the wall time of each stage that ran.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "asperity/app/scene.hpp"
#include "asperity/core/mesh.hpp"
#include "asperity/experiments/streaming.hpp"

namespace asperity {

/// How a run is driven, not what it computes (never part of a scene or its TOML): changing any of
/// these changes no result.
struct RunControl {
  /// Continue the interrupted streaming run whose checkpoint is in scene.out (app/checkpoint.hpp).
  bool resume = false;
  /// This process's share of a run split across processes (validate-geometry under mpirun;
  /// streaming runs only, experiments/streaming.hpp). plan() resets it to one process for a run
  /// that does not stream (such a run is rank 0's alone).
  StreamShare share;
  /// Streaming runs: a checkpoint every this many seconds (0: only on SIGINT/SIGTERM) in scene.out.
  double checkpoint_seconds = 300;
};

/// The kinds of run a scene can be (docs/scenes.md).
enum class RunKind {
  sphere,  ///< the paper's sphere: contacts and single impacts (run_scene)
  radii,   ///< unequal asperity radii on a sphere (run_radii_experiment)
  mesh,    ///< a rough mesh body, single impacts (run_mesh_impacts)
  bounce,  ///< Sec. V bouncing ball (run_bounce_experiment)
  mesh_bounce  ///< bounce sequences of a rough mesh body (run_mesh_bounces, body_bounce.hpp)
};
RunKind run_kind(const Scene& s);
std::string_view to_string(RunKind k);

struct PlanStage {
  std::string name;    ///< "generate", "index", "query", "cross_check", "impact", "analysis", "plots"
  bool run = false;
  std::string reason;  ///< why it runs, or why it is skipped
  double seconds = 0;  ///< wall time [s] once run (0 if skipped)
};

struct Plan {
  /// The scene as given: its TOML is the report's (scene_toml) and the checkpoint's.
  Scene given;
  /// The scene as it will run: ensemble.backend and ensemble.spheres resolved ("auto"),
  /// ensemble.impact.enabled only if the impact stage runs. Everything else as given.
  Scene scene;
  RunControl control;
  RunKind kind = RunKind::sphere;
  /// The run keeps histograms instead of drops (experiments/streaming.hpp): the one answer to
  /// "does this run stream" (checkpoints, --resume, the split across processes).
  bool streams = false;
  /// A mesh body's mesh x body.scale, read once (null for sphere bodies).
  std::shared_ptr<const TriangleMesh> mesh;
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

/// The plan of a run of `s` driven by `control`; touches no output. Throws std::invalid_argument
/// naming the key (MemoryRefused, resources.hpp, for a run that does not fit in memory) for a
/// scene that breaks a cross-key rule, a file it names that cannot be read or does not fit, a
/// checkpoint that is missing, foreign or in the way, or run control that does not apply
/// (--resume of a run that does not stream).
Plan plan(Scene s, RunControl control = {});

/// How many plans this process has made (a diagnostic counter for the tests that check each run
/// is planned once; it changes nothing).
std::uint64_t plans_made();

}  // namespace asperity
