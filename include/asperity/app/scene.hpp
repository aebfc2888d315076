// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A scene: everything one run of validate-geometry needs, with named presets that reproduce the
// paper's figures. Every field is validated before any work starts. Scenes are written as TOML
// files (see scene_file.hpp and docs/scenes.md); the presets are such files, embedded in the
// library at build time from scenes/*.toml.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "asperity/core/body.hpp"
#include "asperity/experiments/bounce.hpp"
#include "asperity/experiments/ensemble.hpp"
#include "asperity/experiments/streaming.hpp"

namespace asperity {

/// A rough body built on a triangle mesh (mesh.hpp) instead of the paper's sphere: a run of
/// run_mesh_impacts (body_experiments.hpp) -- ensemble.spheres explicit bodies x rotations.
struct MeshBodyScene {
  /// As written in the scene; load_scene resolves it (relative to the scene file's directory,
  /// then to the meshes/ directory of the source tree or installation).
  std::filesystem::path file;
  double scale = 1.0;                ///< mesh coordinates -> metres
  /// Empty: asperity centres on the facets; {a, b, c[, m]} [m]: mapped onto that (super)ellipsoid.
  std::vector<double> smooth;
  /// Non-empty: the first body is also written as PLY (asperity spheres) to out / export_ply.
  std::string export_ply;
  bool export_points = false;        ///< PLY of centres only (small) instead of asperity spheres

  friend bool operator==(const MeshBodyScene&, const MeshBodyScene&) = default;
};

/// outputs.cor_table: a restitution table for DEM codes (app/cor_table.hpp) written with the run's
/// other outputs -- `file` (CSV) and its JSON header (same stem, .json). Sphere impact scenes only.
struct CorTableScene {
  std::string file;              ///< plain file name ending in .csv
  std::vector<double> speeds;    ///< empty: 9 speeds from u/10 to 10 u around the scene's speed u
  std::size_t probabilities = 201;
  std::uint64_t drops = 100000;  ///< per speed
  std::vector<double> spins;     ///< incoming Omega_x grid [rad/s]; empty: the scene's Omega
  std::size_t omega_bands = 0;   ///< Omega'_x per eps band (joint draws); 0: none

  friend bool operator==(const CorTableScene&, const CorTableScene&) = default;
};

/// The JSON header's name of a restitution table file ("steel.csv" -> "steel.json").
std::string cor_table_header_name(const std::string& csv);

/// Largest exponent m of a superellipsoid body.smooth = [a, b, c, m] (|x/a|^m must stay finite).
inline constexpr double kMaxSuperellipsoidExponent = 100;

/// Unequal asperity radii on the sphere: a run of run_radii_experiment (body_experiments.hpp).
struct RadiiScene {
  RadiusDistribution radii;                  ///< levels or lognormal
  std::uint64_t screen_bodies = 2;           ///< explicit spheres screened for lambda_eff
  std::uint64_t screen_directions = 200000;  ///< random directions of the screening cross-check, per body

  friend bool operator==(const RadiiScene&, const RadiiScene&) = default;
};

struct Scene {
  std::string name = "fig3";  ///< preset name, or "custom"
  EnsembleConfig ensemble;
  /// ensemble.backend was not chosen by the user: the planner picks a scan or an index from the
  /// work per sphere (fixed mode). Results do not depend on the choice (every backend is exact).
  bool backend_auto = true;
  /// ensemble.spheres was not chosen (explicit design): the planner takes K from the error budget
  /// (auto_spheres, ensemble.hpp). Scene files write it as spheres = "auto".
  bool spheres_auto = true;
  double alpha = 0.01;        ///< significance level of each test and of the family (Holm: the exit status)
  bool plots = true;          ///< write figures with their data as CSV (needs PLplot)
  /// outputs.plot_format (--plot-format): png, svg, pdf, png+svg, png+pdf (app/plot.hpp
  /// parse_plot_formats); the CSV is always written.
  std::string plot_format = "png";
  bool contact_stats = true;  ///< analyse r_xy, r_x, r_y, r_z and core contacts against their laws
  /// Solve the impulse and analyse eps, Omega'_x when the experiment has impacts
  /// (ensemble.impact.enabled); off: the impact stage is skipped.
  bool restitution_stats = true;
  std::filesystem::path out = "asperity-out";
  std::string report = "report.json";  ///< report file name inside `out`
  // How a run is driven (--resume, the share of a split run, the checkpoint interval) is not
  // scene data: RunControl (plan.hpp).

  friend bool operator==(const Scene&, const Scene&) = default;

  BounceExperiment bounce;    ///< Sec. V bouncing ball (fig6); when enabled, the run is a bounce run
  /// body.kind = "mesh": the run is run_mesh_impacts (asperity radii from `radii` if set, else
  /// ensemble.sphere.asperity_radius); ensemble.sphere.radius is unused.
  std::optional<MeshBodyScene> mesh;
  /// Asperity radii "levels"/"lognormal"; on a sphere the run is run_radii_experiment.
  /// nullopt: every asperity has radius ensemble.sphere.asperity_radius (the paper).
  std::optional<RadiiScene> radii;
  /// outputs.cor_table: also write a restitution table (sphere impact scenes); nullopt: none.
  std::optional<CorTableScene> cor_table;
};

/// Names of the built-in presets (the files scenes/NAME.toml, embedded in the library).
std::vector<std::string> preset_names();
/// The TOML text of a preset; throws std::invalid_argument naming the value for an unknown name.
std::string_view preset_text(std::string_view name);
/// The scene of a preset (parse_scene(preset_text(name))); throws std::invalid_argument naming the
/// value for an unknown name.
/// fig3: the paper's Fig. 3 -- N = 1e5, R = 3 mm, a = 6.5e-7 m, fresh spheres, 1e6 drops.
/// fig3-fixed: the same from 100 explicit spheres x 1e4 rotations (grid backend).
/// fig4: Fig. 3's sphere dropped at V.n = 1.3 m/s with Omega_x = 0.2 rad/s: eps and Omega'_x.
/// fig5: Omega = 0, V.n = 1 m/s, a = R x 1e-4: Omega'_x.
/// fig6: Sec. V bouncing ball, N = 1e6, R = 3 mm, a = 5e-7 m, V_z = 1 m/s, Omega = 0, until
///       V_z < 0.1 m/s, 1e5 sequences per variant (paper, random-orientation, dynamic).
Scene preset(std::string_view name);

/// Throws std::invalid_argument naming the offending field and value. Output names (report,
/// export_ply) must be plain file names, distinct from each other, from the report's table
/// (report_table_name) and from the figures and their data (*.png, *.svg, *.pdf, *.csv).
void validate(const Scene& s);

/// The key of an output the scene writes as a file besides its figures ("outputs.cor_table",
/// "outputs.export_ply"), empty when it writes none: the one answer for run_plan (whether it
/// stages files) and asperity.run (which refuses such a scene without out=).
std::string file_output_key(const Scene& s);

/// The table's file name next to the report: its name with .txt ("report.json" -> "report.txt";
/// "x.txt" -> "x.txt.txt").
std::string report_table_name(const std::string& report);

}  // namespace asperity
