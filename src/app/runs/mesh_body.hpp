// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What the two mesh kinds (mesh.cpp: single impacts, mesh_bounce.cpp: bounce sequences) share: the
// rough bodies built on body.mesh, the mesh read once and checked, the PLY export of the first
// body, and their memory.
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "asperity/app/plan.hpp"
#include "asperity/core/mesh.hpp"
#include "app/runs/kinds.hpp"

namespace asperity::runs {

/// The rough mesh bodies of a scene: the same for impacts, bounces and the PLY export.
struct SceneBodies {
  std::filesystem::path file;
  double scale = 1;
  std::vector<double> smooth;
  std::uint64_t asperities = 0;  ///< N per body
  RadiusDistribution radii;
  double density = 0;
  std::uint64_t bodies = 0;      ///< K
  std::uint64_t seed = 0;
};
SceneBodies scene_bodies(const Scene& s);

/// A mesh body's mesh x body.scale, read once, with its derived quantities checked against the
/// supported ranges (plan(), plan.hpp). Throws std::invalid_argument naming the key.
std::shared_ptr<const TriangleMesh> read_checked_mesh(const Scene& s);

/// The first body (same seed and index as the run's body 0) as PLY into `dir`, when
/// outputs.export_ply asks; its name is appended to `files` first (removed if anything later
/// fails). Returns the stage for the report.
PlanStage export_first_body(const Scene& s, const TriangleMesh& mesh, const std::filesystem::path& dir,
                            std::vector<std::string>& files);

/// Measured: the process with its libraries (mesh, CGAL support tree code), and per asperity of a
/// mesh body (centre, radius, support tree, the heap kept between bodies).
inline constexpr double kBaseMesh = 14.3e6;
inline constexpr double kPerAsperityMesh = 141;

/// A mesh body's own costs besides its asperities: reading the file (the peak while it is read)
/// against the kept mesh + the rest of the run (`run` bytes) and the export; the larger one.
double mesh_phases(const Scene& s, double run, std::ostringstream& d);

/// What a user can lower besides the counts: the faces of the mesh, the export's style.
std::string mesh_lower(const Scene& s);

}  // namespace asperity::runs
