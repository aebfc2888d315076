#pragma once
// A scene: everything one run of validate-geometry needs, with named presets that reproduce the
// paper's figures. Every field is validated before any work starts. Scenes are written as TOML
// files (see scene_file.hpp and README "Scenes"); the presets are such files, embedded in the
// library at build time from scenes/*.toml.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "asperity/bounce.hpp"
#include "asperity/ensemble.hpp"

namespace asperity {

struct Scene {
  std::string name = "fig3";  ///< preset name, or "custom"
  EnsembleConfig ensemble;
  /// ensemble.backend was not chosen by the user: the planner picks a scan or an index from the
  /// work per sphere (fixed mode). Results do not depend on the choice (every backend is exact).
  bool backend_auto = true;
  double alpha = 0.01;        ///< significance level of each test
  bool plots = true;          ///< write PNG figures (needs gnuplot)
  bool contact_stats = true;  ///< analyse r_xy, r_x, r_y, r_z and core contacts against their laws
  /// Solve the impulse and analyse eps, Omega'_x when the experiment has impacts
  /// (ensemble.impact.enabled); off: the impact stage is skipped.
  bool restitution_stats = true;
  std::filesystem::path out = "asperity-out";
  std::string report = "report.json";  ///< report file name inside `out`

  friend bool operator==(const Scene&, const Scene&) = default;

  BounceExperiment bounce;    ///< Sec. V bouncing ball (fig6); when enabled, the run is a bounce run
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

/// Throws std::invalid_argument naming the offending field and value.
void validate(const Scene& s);

}  // namespace asperity
