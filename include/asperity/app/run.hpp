// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// One call runs a scene as validate-geometry does: plan, ensemble, analysis, figures.
#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "asperity/experiments/ensemble.hpp"
#include "asperity/app/plan.hpp"
#include "asperity/app/report.hpp"
#include "asperity/app/scene.hpp"

namespace asperity {

class Collective;  // the processes of a run split across machines (validate-geometry under mpirun)

/// A sphere run (RunKind::sphere) of its plan: only the stages it lists (figures are written into
/// `dir`, default the scene's out, when planned; the report file is not written). The report
/// carries the stages with their times and the scene as given, as TOML.
/// `group` given (rank 0 of a run split across processes; p.control.share its share): a streaming
/// run gathers the other processes' shares before the analysis (run_stream_share runs them).
/// `keep` given: a run that keeps its drops (not p.streams) moves them there after its analysis
/// (asperity.run's arrays: the run's own drops, not a second ensemble).
GeometryReport run_scene(const Plan& p, const Progress& progress = {}, const std::filesystem::path& dir = {},
                         Collective* group = nullptr, ContactSamples* keep = nullptr);
/// run_scene(plan(s)): for callers that hold a sphere scene (tests, benchmarks).
GeometryReport run_scene(const Scene& s, const Progress& progress = {}, const std::filesystem::path& dir = {});

/// What any run produced, ready for the one writer (write_report_files, report.hpp).
struct SceneOutput {
  RunKind kind = RunKind::sphere;
  std::string json;                 ///< report.json text, with the common header (with_header)
  std::string table;                ///< the table for people (printed, and written as report.txt)
  std::vector<std::string> files;   ///< files the run wrote (figures, PLY), by name
  bool rejected = false;            ///< the family of decisive tests rejects a law (Holm; exit status 1)
  /// Decisive tests that could not be evaluated (verdict "skipped"), one line each with the
  /// reason; the run still exits 0 unless a law was rejected (docs/cli.md).
  std::vector<std::string> skipped;
};

/// Runs a plan of any kind and renders its report; writes only figures (and the PLY of a mesh
/// scene's outputs.export_ply), never the report files. Progress of the drops goes to `progress`
/// (sphere, radii, mesh), one line per bounce variant to `log` if given.
/// `dir` given (validate-geometry: an OutputStaging's dir()): the files are written there under
/// their final names and the caller commits them. `dir` empty: they are staged in the scene's out
/// and renamed into place when the run succeeded; on an exception out is left as it was. A run
/// that writes no file (no figures, restitution table or PLY export) touches no directory.
/// `group`, `keep`: as run_scene (only streaming sphere runs are split; others run on rank 0 alone).
SceneOutput run_plan(const Plan& p, const Progress& progress = {}, std::ostream* log = nullptr,
                     const std::filesystem::path& dir = {}, Collective* group = nullptr,
                     ContactSamples* keep = nullptr);

/// run_plan(plan(s)): a scene of any kind, planned once (a run that does not fit in memory is
/// refused before anything is allocated or written, resources.hpp).
SceneOutput run_scene_output(const Scene& s, const Progress& progress = {}, std::ostream* log = nullptr,
                             const std::filesystem::path& dir = {});

}  // namespace asperity
