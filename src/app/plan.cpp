// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/app/plan.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "asperity/app/checkpoint.hpp"
#include "asperity/app/mesh_io.hpp"
#include "asperity/app/resources.hpp"
#include "asperity/core/geometry.hpp"

namespace asperity {

namespace {

std::atomic<std::uint64_t> g_plans{0};  // plans_made(): a diagnostic count, read by tests only

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

// A mesh body's mesh, read once, and its derived quantities checked against the supported ranges:
// size, mass and inertia, the asperity radius below the body's smallest half-extent, body.smooth
// against the mesh, the spin's surface speed.
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

}  // namespace

RunKind run_kind(const Scene& s) {
  if (s.bounce.enabled) return s.mesh ? RunKind::mesh_bounce : RunKind::bounce;
  if (s.mesh) return RunKind::mesh;
  if (s.radii) return RunKind::radii;
  return RunKind::sphere;
}

std::string_view to_string(RunKind k) {
  switch (k) {
    case RunKind::sphere: return "sphere";
    case RunKind::radii: return "radii";
    case RunKind::mesh: return "mesh";
    case RunKind::bounce: return "bounce";
    case RunKind::mesh_bounce: return "mesh-bounce";
  }
  return "?";
}

bool Plan::runs(std::string_view name) const {
  for (const auto& s : stages)
    if (s.name == name) return s.run;
  return false;
}

PlanStage& Plan::stage(std::string_view name) {
  for (auto& s : stages)
    if (s.name == name) return s;
  throw std::out_of_range("no stage '" + std::string(name) + "' in the plan");
}

namespace {

// The stages of a sphere run, with ensemble.spheres, ensemble.backend and ensemble.impact.enabled
// resolved in p.scene (the other kinds list their own stages as they run, run.cpp).
void plan_sphere(Plan& p) {
  const Scene& s = p.given;
  auto& e = p.scene.ensemble;
  const bool fixed = e.mode == Mode::explicit_spheres;
  if (fixed && s.spheres_auto) e.spheres = auto_spheres(e.sphere.asperities, e.drops);
  const std::uint64_t rotations = fixed ? e.drops / e.spheres : 1;
  if (fixed && s.backend_auto) e.backend = rotations < kScanBelowRotations ? Backend::brute : Backend::grid;

  const std::string n = std::to_string(e.sphere.asperities);
  if (fixed)
    p.stages.push_back({"generate", true,
                        std::to_string(e.spheres) + " explicit sphere(s) of " + n + " asperities" +
                            (s.spheres_auto ? " (spheres auto: error budget M <= N/(10 c^2) rotations per sphere, K >= " +
                                                  std::to_string(kAutoMinSpheres) + ")"
                                            : std::string())});
  else
    p.stages.push_back({"generate", false,
                        "sampled: each drop draws its lowest asperities from the exact finite-N law; no sphere is built"});

  if (!fixed) {
    p.stages.push_back({"index", false, "sampled: no sphere, no index"});
  } else if (e.backend == Backend::brute) {
    p.stages.push_back(
        {"index", false,
         s.backend_auto ? "backend auto: " + std::to_string(rotations) + " rotation(s) per sphere < " +
                              std::to_string(kScanBelowRotations) + ", a brute scan costs less than building the grid"
                        : std::string("backend brute: every query scans the sphere")});
  } else {
    p.stages.push_back({"index", true,
                        std::string(to_string(e.backend)) + " index per sphere" +
                            (s.backend_auto ? ", backend auto: " + std::to_string(rotations) + " rotations per sphere >= " +
                                                  std::to_string(kScanBelowRotations)
                                            : std::string())});
  }
  p.stages.push_back({"query", true,
                      "lowest asperity of each of " + std::to_string(e.drops) + " drops" +
                          (fixed ? std::string(" by spatial query") : std::string(" (exact sampler, no geometry)"))});
  if (fixed)
    p.stages.push_back({"cross_check", true,
                        "a deterministic subsample of the queries answered again by brute force and the kd-tree (and FCL "
                        "where built and N is small)"});
  else
    p.stages.push_back({"cross_check", false, "sampled: no spatial queries to check"});

  const bool impact = e.impact.enabled && s.restitution_stats;
  if (impact)
    p.stages.push_back({"impact", true, "outputs.restitution: the impulse of every drop"});
  else
    p.stages.push_back({"impact", false,
                        e.impact.enabled ? "outputs.restitution = false" : "experiment.kind = contact: no impacts"});
  e.impact.enabled = impact;

  std::string what;
  if (s.contact_stats) what = "contact laws (r_xy, r_x, r_y, r_z, core contacts)";
  if (impact) what += std::string(what.empty() ? "" : " and ") + "restitution laws (eps, Omega'_x)";
  if (what.empty()) what = "summaries only: no law requested";
  p.stages.push_back({"analysis", true, what});

  if (s.plots)
    p.stages.push_back({"plots", true, "outputs.plots: a figure per analysed quantity"});
  else
    p.stages.push_back({"plots", false, "outputs.plots = false"});
}

}  // namespace

Plan plan(Scene s, RunControl control) {
  g_plans.fetch_add(1, std::memory_order_relaxed);
  validate(s);  // the cross-key rules (scene.hpp); the reader has checked each key
  Plan p;
  p.kind = run_kind(s);
  p.scene = s;
  p.given = std::move(s);
  if (p.kind == RunKind::sphere) plan_sphere(p);
  p.streams = p.kind == RunKind::sphere && uses_streaming(p.scene.ensemble);
  if (!p.streams) control.share = {};  // a run that does not stream is rank 0's alone
  if (control.resume && !p.streams)
    throw std::invalid_argument("--resume: the scene of " + p.given.out.string() +
                                " does not stream (statistics = raw, or not a contact ensemble)");
  p.control = control;
  check_memory(p);  // before the mesh is read: its size comes from its header
  // A checkpoint in the output directory belongs to an interrupted streaming run: never
  // overwritten; a resumed run's is read whole now, before any file is touched.
  if (p.streams) check_checkpoint_files(p);
  if (p.given.mesh) p.mesh = read_checked_mesh(p.given);
  return p;
}

std::uint64_t plans_made() { return g_plans.load(std::memory_order_relaxed); }

}  // namespace asperity
