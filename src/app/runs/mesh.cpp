// SPDX-License-Identifier: GPL-3.0-or-later
// A rough body built on a triangle mesh: single impacts of K explicit bodies x rotations, against
// the sphere laws of the equal-volume sphere (run_mesh_impacts, body_experiments.hpp).
#include "asperity/app/experiment_reports.hpp"
#include "asperity/app/plot.hpp"
#include "asperity/experiments/body_experiments.hpp"
#include "app/runs/mesh_body.hpp"

namespace asperity::runs {

namespace {

bool recognise(const Scene& s) { return !s.bounce.enabled && s.mesh; }

MeshImpactExperiment mesh_experiment(const Scene& s) {
  const auto& e = s.ensemble;
  const SceneBodies b = scene_bodies(s);
  MeshImpactExperiment m;
  m.mesh = b.file, m.scale = b.scale, m.smooth_ellipsoid = b.smooth;
  m.asperities = b.asperities, m.radii = b.radii, m.density = b.density, m.bodies = b.bodies, m.seed = b.seed;
  if (s.radii) m.screen_bodies = s.radii->screen_bodies, m.screen_directions = s.radii->screen_directions;
  m.drops = e.drops;
  m.speed = e.impact.speed;
  m.omega = e.impact.omega;
  m.beta = e.impact.beta;
  m.eps_t = e.impact.eps_t;
  m.tangential = e.impact.tangential;
  m.alpha = s.alpha;
  m.plots = s.plots;
  return m;
}

constexpr double kPerDropMesh = 68;  // measured, as kPerAsperityMesh (mesh_body.hpp)

double estimate(const Plan& p, std::ostringstream& d) {
  const Scene& s = p.given;
  const auto& e = s.ensemble;
  d << e.drops << " drops x " << kPerDropMesh << " B + one body at a time of " << e.sphere.asperities
    << " asperities x " << kPerAsperityMesh << " B";
  return kBaseMesh + mesh_phases(s, kPerDropMesh * double(e.drops) + kPerAsperityMesh * double(e.sphere.asperities), d);
}

std::string lower(const Scene& s) {
  return "asperities.count (--asperities), ensemble.drops (--drops), ensemble.spheres (--spheres)" + mesh_lower(s);
}

SceneOutput run(const Plan& p, const RunIO& io) {
  const Scene& s = p.scene;
  const MeshImpactExperiment m = mesh_experiment(s);
  const TriangleMesh& mesh = *p.mesh;  // read once, by plan()
  SceneOutput o;
  const PlanStage exported = export_first_body(s, mesh, io.dir, o.files);
  MeshImpactReport r = run_mesh_impacts(m, mesh, io.progress);
  if (s.plots) {
    const auto t0 = Clock::now();
    r.plots = write_figures(io.dir, r.figures, parse_plot_formats(s.plot_format));
    r.seconds_plots = since(t0);
  }
  o.files.insert(o.files.end(), r.plots.begin(), r.plots.end());
  o.rejected = r.rejected();
  o.skipped = skipped_of(r.tests);
  o.table = format_table(r);
  const ReportHeader h = header_of(
      s, {stage("generate", true, "mesh, mass properties and the comparison sphere", r.seconds_mesh),
          stage("query", true,
                std::to_string(m.bodies) + " explicit bodies x rotations: support tree, lowest asperity, impact",
                r.seconds_drops),
          stage("analysis", true, "summaries; the sphere laws of the equal-volume sphere (measurements)",
                r.seconds_analysis),
          plots_stage(s, r.seconds_plots), exported});
  o.json = with_header(to_json(r), h);
  return o;
}

}  // namespace

const Kind kMesh{RunKind::mesh, "mesh", recognise, nullptr, estimate, lower, run};

}  // namespace asperity::runs
