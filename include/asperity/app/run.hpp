// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// One call runs a scene as validate-geometry does: plan, ensemble, analysis, figures.
#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "asperity/experiments/ensemble.hpp"
#include "asperity/app/collective.hpp"
#include "asperity/app/plan.hpp"
#include "asperity/app/report.hpp"
#include "asperity/app/scene.hpp"

namespace asperity {

/// Runs only the stages make_plan(s) lists (figures are written into `dir`, default s.out, when
/// planned; the report file is not written). The report carries the plan with stage times and
/// the scene as TOML (to_toml(s)). Throws std::invalid_argument for an invalid scene.
/// `group` given (rank 0 of a run split across processes; s.share its share): a streaming run
/// gathers the other processes' shares before the analysis (run_stream_share runs them).
GeometryReport run_scene(const Scene& s, const Progress& progress = {}, const std::filesystem::path& dir = {},
                         Collective* group = nullptr);

/// validate(s), then what needs the files a scene refers to: a mesh body's mesh is read and its
/// derived quantities checked against the supported ranges (size, mass and inertia, asperity
/// radius below the body's smallest half-extent, body.smooth against the mesh, the spin's
/// surface speed). Throws std::invalid_argument naming the key. Touches no output.
void check_scene_inputs(const Scene& s);

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

/// Runs a scene of any kind and renders its report (check_run first: a run that does not fit in
/// memory is refused before anything is allocated or written, resources.hpp); writes only figures (and the PLY of a mesh
/// scene's outputs.export_ply), never the report files. Progress of the drops goes to
/// `progress` (sphere, radii, mesh), one line per bounce variant to `log` if given.
/// `dir` given (validate-geometry: an OutputStaging's dir()): the files are written there under
/// their final names and the caller commits them. `dir` empty: they are staged in s.out and
/// renamed into place when the run succeeded; on an exception s.out is left as it was.
/// `group`: as run_scene (only streaming sphere runs are split; others run on rank 0 alone).
SceneOutput run_scene_output(const Scene& s, const Progress& progress = {}, std::ostream* log = nullptr,
                             const std::filesystem::path& dir = {}, Collective* group = nullptr);

}  // namespace asperity
