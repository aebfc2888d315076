// SPDX-License-Identifier: GPL-3.0-or-later
// What the mesh kinds share (mesh_body.hpp).
#include "app/runs/mesh_body.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "app/io/mesh_io.hpp"
#include "asperity/app/resources.hpp"
#include "asperity/core/geometry.hpp"
#include "asperity/experiments/body_experiments.hpp"

namespace asperity::runs {

namespace {

// The largest asperity radius a scene can draw (levels: the largest; lognormal: the median).
double top_radius(const Scene& s) {
  if (!s.radii) return s.ensemble.sphere.asperity_radius;
  const auto& d = s.radii->radii;
  switch (d.kind) {
    case RadiusDistribution::Kind::levels: return *std::max_element(d.levels.begin(), d.levels.end());
    case RadiusDistribution::Kind::lognormal: return d.median;
    case RadiusDistribution::Kind::fixed: return d.radius;
  }
  return d.radius;
}

std::string show(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

}  // namespace

// Checked: size, mass and inertia, the asperity radius below the body's smallest half-extent,
// body.smooth against the mesh, the spin's surface speed.
std::shared_ptr<const TriangleMesh> read_checked_mesh(const Scene& s) {
  const auto& m = *s.mesh;
  auto kept = std::make_shared<TriangleMesh>();
  TriangleMesh& mesh = *kept;
  try {
    mesh = read_mesh(m.file, m.scale);
  } catch (const std::exception& ex) {
    throw std::invalid_argument("body.mesh: " + std::string(ex.what()));
  }
  if (mesh.vertices.empty() || mesh.faces.empty())
    throw std::invalid_argument("body.mesh: " + m.file.string() + " has no triangles");
  const double density = s.ensemble.impact.density;
  MassProperties mp;
  try {
    mp = mass_properties(mesh, density);
  } catch (const std::exception& ex) {
    throw std::invalid_argument("body.mesh: " + m.file.string() + " x body.scale = " + show(m.scale) + ": " + ex.what());
  }
  // The body's size: its bounding radius about the centre of mass and its half-extents along
  // the mesh axes (where asperity centres and the smooth surface live).
  double L = 0;
  Vec3 half = Vec3::Zero();
  for (const auto& v : mesh.vertices) {
    L = std::max(L, (v - mp.centroid).norm());
    half = half.cwiseMax(v.cwiseAbs());
  }
  const double thinnest = half.minCoeff();
  const std::string size = "the body (" + m.file.filename().string() + " x body.scale = " + show(m.scale) +
                           ") has a bounding radius of " + show(L) + " m";
  if (!(std::isfinite(L) && L <= kMaxLength))
    throw std::invalid_argument("body.scale: " + size + "; supported: <= " + show(kMaxLength) + " m");
  const Eigen::Vector3d moments = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(mp.inertia).eigenvalues();
  if (!std::isnormal(mp.mass) || !(moments.minCoeff() > 0) || !std::isnormal(moments.minCoeff()) ||
      !std::isfinite(moments.maxCoeff()))
    throw std::invalid_argument("body.scale: " + size + " and material.density = " + show(density) +
                                " kg/m^3 give a mass or moment of inertia outside the range of double");
  const double a = top_radius(s);
  if (!(a < thinnest))
    throw std::invalid_argument("asperities.radius: " + show(a) + " m must be smaller than the body's smallest half-extent " +
                                show(thinnest) + " m (body.mesh x body.scale)");
  if (!m.smooth.empty()) {
    const char* axis = "xyz";
    for (int i = 0; i < 3; ++i) {
      const double ax = m.smooth[static_cast<std::size_t>(i)];
      if (!(ax >= 0.5 * half[i] && ax <= 2.0 * half[i]))
        throw std::invalid_argument("body.smooth: semi-axis " + std::string(1, axis[i]) + " = " + show(ax) +
                                    " m must match the mesh (its half-extent along " + std::string(1, axis[i]) + " is " +
                                    show(half[i]) + " m; supported: 0.5x to 2x)");
    }
    if (m.smooth.size() == 4 && !(m.smooth[3] >= 2 && m.smooth[3] <= kMaxSuperellipsoidExponent))
      throw std::invalid_argument("body.smooth: exponent m = " + show(m.smooth[3]) + " must be in [2, " +
                                  show(kMaxSuperellipsoidExponent) + "]");
  }
  // Spin: one rule for every body, as for the sphere (ensemble.hpp): the surface speed
  // |Omega| x bounding radius within the supported range.
  const Vec3 omega = s.bounce.enabled ? s.bounce.omega : s.ensemble.impact.omega;
  const std::string key = "experiment.Omega (--omega-x/--omega-y)";
  const double surface = omega.stableNorm() * L;
  const double max_surface = s.bounce.enabled ? kMaxBounceSpeed : kMaxSpeed;  // a bounce: Eq. 9's range (bounce.hpp)
  if (!(surface <= max_surface))
    throw std::invalid_argument(key + ": |Omega| = " + show(omega.stableNorm()) + " rad/s x " + show(L) +
                                " m (the body's bounding radius) gives a surface speed of " + show(surface) +
                                " m/s; must be <= " + show(max_surface) + " m/s (supported range)");
  if (!s.bounce.enabled && !(surface < s.ensemble.impact.speed))
    throw std::invalid_argument(key + ": |Omega| = " + show(omega.stableNorm()) + " rad/s x " + show(L) +
                                " m (the body's bounding radius; body.scale = " + show(m.scale) +
                                ") gives a surface speed of " + show(surface) + " m/s, not below the approach speed " +
                                show(s.ensemble.impact.speed) +
                                " m/s: parts of the body would recede from the plate (supported: |Omega| L < |V.z|)");
  return kept;
}

SceneBodies scene_bodies(const Scene& s) {
  const auto& e = s.ensemble;
  const RadiusDistribution radii = s.radii ? s.radii->radii : RadiusDistribution::fixed(e.sphere.asperity_radius);
  return {s.mesh->file, s.mesh->scale, s.mesh->smooth, e.sphere.asperities, radii, e.impact.density, e.spheres, e.seed};
}

PlanStage export_first_body(const Scene& s, const TriangleMesh& mesh, const std::filesystem::path& dir,
                            std::vector<std::string>& files) {
  if (s.mesh->export_ply.empty()) return stage("export", false, "no outputs.export_ply");
  const auto t0 = Clock::now();
  files.push_back(s.mesh->export_ply);  // listed first: removed if anything later fails
  const SceneBodies sb = scene_bodies(s);
  const RoughBody b = make_rough_mesh_body(mesh, sb.asperities, sb.radii, sb.density, sb.seed, 0,
                                           smooth_surface(sb.smooth), sb.file.stem().string());
  write_ply(dir / s.mesh->export_ply, b, s.mesh->export_points ? PlyStyle::points : PlyStyle::spheres, 1.0, &mesh,
            -mass_properties(mesh, sb.density).centroid);
  return stage("export", true, "outputs.export_ply: the first body as PLY", since(t0));
}

namespace {

// A mesh file read and checked (read_mesh): CGAL's polygon soup, its repair and orientation, the
// Surface_mesh and the self-intersection test's boxes -- all freed before the bodies are built.
// Measured: 96.5 MB at 159,200 faces, 347.6 MB at 638,400 (closed UV ellipsoids, OFF).
constexpr double kPerMeshFaceRead = 524;
// The TriangleMesh kept for the run: 3 doubles per vertex, 3 indices per face, + the facet
// sampler's cumulative areas (8 B per face).
constexpr double kPerMeshVertexKept = 24, kPerMeshFaceKept = 12 + 8;
// The exported body (outputs.export_ply): its centres and radii (32 B per asperity) + the text
// (ply_text_bytes, one allocation), freed before the run's bodies are built.
constexpr double kPerAsperityExport = 32;

}  // namespace

double mesh_phases(const Scene& s, double run, std::ostringstream& d) {
  const MeshFileSize f = mesh_file_size(s.mesh->file);
  const double read = kPerMeshFaceRead * double(f.faces);
  const double kept = kPerMeshVertexKept * double(f.vertices) + kPerMeshFaceKept * double(f.faces);
  double exported = 0;
  if (!s.mesh->export_ply.empty()) {
    const PlyStyle style = s.mesh->export_points ? PlyStyle::points : PlyStyle::spheres;
    exported = kPerAsperityExport * double(s.ensemble.sphere.asperities) +
               double(ply_text_bytes(s.ensemble.sphere.asperities, style, f.vertices, f.faces));
  }
  d << "; the mesh: " << f.faces << " faces x " << kPerMeshFaceRead << " B while read, " << gb(kept) << " kept";
  if (exported > 0) d << "; the PLY export: " << gb(exported);
  return std::max({read, kept + run, kept + exported});
}

std::string mesh_lower(const Scene& s) {
  std::string mesh = ", the faces of body.mesh";
  if (!s.mesh->export_ply.empty() && !s.mesh->export_points) mesh += " or use outputs.export_style = \"points\"";
  return mesh;
}

}  // namespace asperity::runs
