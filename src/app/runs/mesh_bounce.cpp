// SPDX-License-Identifier: GPL-3.0-or-later
// Bounce sequences of a rough mesh body: impacts (3x3 solve), free rotation and conservative
// advancement to each landing (run_mesh_bounces, body_bounce.hpp).
#include <cmath>

#include "asperity/app/experiment_reports.hpp"
#include "asperity/experiments/body_bounce.hpp"
#include "app/runs/mesh_body.hpp"

namespace asperity::runs {

namespace {

bool recognise(const Scene& s) { return s.bounce.enabled && s.mesh; }

MeshBounceExperiment mesh_bounce_experiment(const Scene& s) {
  const SceneBodies b = scene_bodies(s);
  MeshBounceExperiment m;
  m.mesh = b.file, m.scale = b.scale, m.smooth = b.smooth;
  m.asperities = b.asperities, m.radii = b.radii, m.density = b.density, m.bodies = b.bodies, m.seed = b.seed;
  m.threads = s.ensemble.threads;
  m.options.bounce = s.bounce;
  m.options.tangential = s.ensemble.impact.tangential;
  m.plots = s.plots;
  return m;
}

constexpr double kPerImpactBounce = 64;  // one impact of a sequence, kept for the analysis (measured)

double estimate(const Plan& p, std::ostringstream& d) {
  const Scene& s = p.given;
  const auto& e = s.ensemble;
  const double K = double(e.spheres), N = double(e.sphere.asperities);
  const double impacts = bounce_impacts(s.bounce);
  const double seq = double(s.bounce.sequences);
  d << e.spheres << " bodies kept x " << e.sphere.asperities << " asperities x " << kPerAsperityMesh << " B + "
    << s.bounce.sequences << " sequences x ~" << fmt3(impacts) << " impacts x " << kPerImpactBounce << " B";
  const double run = K * N * kPerAsperityMesh + seq * impacts * kPerImpactBounce;
  return kBaseMesh + (s.mesh->file.empty() ? run : mesh_phases(s, run, d));
}

std::string lower(const Scene& s) {
  return "asperities.count (--asperities), ensemble.spheres (--spheres), experiment.sequences (--sequences)" +
         mesh_lower(s);
}

SceneOutput run(const Plan& p, const RunIO& io) {
  const Scene& s = p.scene;
  const MeshBounceExperiment m = mesh_bounce_experiment(s);
  const TriangleMesh* mesh = p.mesh.get();  // read once, by plan()
  SceneOutput o;
  const PlanStage exported = export_first_body(s, *mesh, io.dir, o.files);
  MeshBounceReport r = run_mesh_bounces(m, mesh, io.progress);
  if (s.plots) {
    const auto t0 = Clock::now();
    r.plots = write_mesh_bounce_plots(io.dir, r, parse_plot_formats(s.plot_format));
    r.seconds_plots = since(t0);
  }
  o.files.insert(o.files.end(), r.plots.begin(), r.plots.end());
  o.table = format_table(r);
  const ReportHeader h = header_of(
      s, {stage("generate", true, std::to_string(m.bodies) + " rough bodies from the mesh", r.seconds_build),
          stage("index", true, "one exact support tree per body, shared by the threads", r.seconds_index),
          stage("bounce", true,
                "sequences: impacts (3x3 solve), free rotation and conservative advancement to each landing",
                r.seconds_run),
          stage("analysis", true, "speed windows, impact numbers, Eq. 2 fits (descriptive), energy checks",
                r.seconds_analysis),
          plots_stage(s, r.seconds_plots), exported});
  o.json = with_header(to_json(r), h);
  return o;
}

}  // namespace

const Kind kMeshBounce{RunKind::mesh_bounce, "mesh-bounce", recognise, nullptr, estimate, lower, run};

}  // namespace asperity::runs
