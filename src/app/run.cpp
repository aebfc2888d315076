// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/app/run.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <cmath>
#include <chrono>
#include <filesystem>
#include <optional>
#include <ostream>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "asperity/experiments/body_bounce.hpp"
#include "asperity/experiments/body_experiments.hpp"
#include "asperity/experiments/bounce.hpp"
#include "asperity/app/cor_table.hpp"
#include "asperity/app/experiment_reports.hpp"
#include "asperity/app/mesh_io.hpp"
#include "asperity/app/output_staging.hpp"
#include "asperity/app/plot.hpp"
#include "asperity/app/resources.hpp"
#include "checked_text.hpp"
#include "asperity/app/scene_file.hpp"
#include "asperity/app/stream_report.hpp"
#include "asperity/app/checkpoint.hpp"
#include "asperity/core/thread_count.hpp"

namespace asperity {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Asperity radii of a scene: its distribution, or the paper's one radius.
RadiusDistribution scene_radii(const Scene& s) {
  return s.radii ? s.radii->radii : RadiusDistribution::fixed(s.ensemble.sphere.asperity_radius);
}

// A Scene holds the sphere runs' own config types (EnsembleConfig, BounceExperiment); the runs of
// body_experiments.hpp and body_bounce.hpp take theirs from one conversion function each, below.
// The rough mesh bodies are the same for all of them (impacts, bounces, the PLY export): a field
// of the bodies is read from the Scene here only.
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

SceneBodies scene_bodies(const Scene& s) {
  const auto& e = s.ensemble;
  return {s.mesh->file, s.mesh->scale, s.mesh->smooth, e.sphere.asperities, scene_radii(s), e.impact.density,
          e.spheres, e.seed};
}

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

RadiiExperiment radii_experiment(const Scene& s) {
  const auto& e = s.ensemble;
  RadiiExperiment r;
  r.asperities = e.sphere.asperities;
  r.radius = e.sphere.radius;
  r.radii = s.radii->radii;
  r.drops = e.drops;
  r.screen_bodies = s.radii->screen_bodies;
  r.screen_directions = s.radii->screen_directions;
  r.seed = e.seed;
  r.alpha = s.alpha;
  r.plots = s.plots;
  return r;
}

std::vector<std::string> skipped_of(const std::vector<LawCheck>& tests) {
  std::vector<std::string> out;
  for (const auto& t : tests)
    if (unresolved(t)) out.push_back(t.quantity + " " + t.law + ": " + t.note);
  return out;
}

// The header of a run of `s` from its plan; timings_s lists the stages that ran.
ReportHeader header_of(const Scene& s, std::vector<PlanStage> plan) {
  ReportHeader h;
  h.scene = s.name;
  h.scene_toml = to_toml(s);
  for (const auto& st : plan)
    if (st.run) h.timings_s.emplace_back(st.name, st.seconds);
  h.plan = std::move(plan);
  return h;
}

PlanStage stage(std::string name, bool run, std::string reason, double seconds = 0) {
  return {std::move(name), run, std::move(reason), run ? seconds : 0.0};
}

PlanStage plots_stage(const Scene& s, double seconds) {
  return stage("plots", s.plots, s.plots ? "outputs.plots" : "plots = false / --no-plots", seconds);
}

PlanStage export_stage(const Scene& s, double seconds) {
  const bool on = !s.mesh->export_ply.empty();
  return stage("export", on, on ? "outputs.export_ply: the first body as PLY" : "no outputs.export_ply", seconds);
}

// The first body of a mesh scene (same seed and index as the run's body 0) as PLY.
void export_first_body(const Scene& s, const TriangleMesh& mesh, const std::filesystem::path& dir) {
  const SceneBodies sb = scene_bodies(s);
  const RoughBody b = make_rough_mesh_body(mesh, sb.asperities, sb.radii, sb.density, sb.seed, 0,
                                           smooth_surface(sb.smooth), sb.file.stem().string());
  write_ply(dir / s.mesh->export_ply, b, s.mesh->export_points ? PlyStyle::points : PlyStyle::spheres, 1.0, &mesh,
            -mass_properties(mesh, sb.density).centroid);
}

SceneOutput run_radii(const Plan& p, const Progress& progress, const std::filesystem::path& dir) {
  const Scene& s = p.scene;
  RadiiReport r = run_radii_experiment(radii_experiment(s), progress);
  if (s.plots) {
    const auto t0 = Clock::now();
    r.plots = write_figures(dir, r.figures, parse_plot_formats(s.plot_format));
    r.seconds_plots = since(t0);
  }
  const bool lognormal = s.radii->radii.kind == RadiusDistribution::Kind::lognormal;
  SceneOutput o;
  o.files = r.plots;
  o.rejected = r.rejected();
  o.skipped = skipped_of(r.tests);
  o.table = format_table(r);
  const ReportHeader h = header_of(
      s, {stage("screening", true,
                "lambda_eff: " + std::to_string(s.radii->screen_bodies) + " explicit spheres screened" +
                (lognormal ? ", rotated for r_x (no exact sampler for lognormal radii)" : ""),
                r.seconds_screen),
          stage("query", !lognormal,
                lognormal ? "lognormal radii: r_x comes from rotations of the screened spheres"
                : "fresh drops: exact sampler of the lowest asperities (level radii)",
                r.seconds_fresh),
          stage("analysis", true, "r_x against the exact level law and Gaussians with lambda, lambda_eff",
                r.seconds_analysis),
          plots_stage(s, r.seconds_plots)});
  o.json = with_header(to_json(r), h);
  return o;
}

SceneOutput run_mesh(const Plan& p, const Progress& progress, const std::filesystem::path& dir) {
  const Scene& s = p.scene;
  const MeshImpactExperiment m = mesh_experiment(s);
  const TriangleMesh& mesh = *p.mesh;  // read once, by plan()
  SceneOutput o;
  double seconds_export = 0;
  if (!s.mesh->export_ply.empty()) {
    const auto t0 = Clock::now();
    o.files.push_back(s.mesh->export_ply);  // listed first: removed if anything below fails
    export_first_body(s, mesh, dir);
    seconds_export = since(t0);
  }
  MeshImpactReport r = run_mesh_impacts(m, mesh, progress);
  if (s.plots) {
    const auto t0 = Clock::now();
    r.plots = write_figures(dir, r.figures, parse_plot_formats(s.plot_format));
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
          plots_stage(s, r.seconds_plots),
          export_stage(s, seconds_export)});
  o.json = with_header(to_json(r), h);
  return o;
}

SceneOutput run_bounce(const Plan& p, const Progress& progress, std::ostream* log, const std::filesystem::path& dir) {
  const Scene& s = p.scene;
  const auto& e = s.ensemble;
  SceneOutput o;
  auto t0 = Clock::now();
  auto bounce = s.bounce;
  bounce.alpha = s.alpha;  // the verdicts of the Eq. 2 bootstrap use the scene's level
  bounce.tangential = e.impact.tangential;
  const auto reports = run_bounce_experiment(e.sphere, bounce, e.seed, e.threads, log, progress);
  const double seconds_bounce = since(t0);
  t0 = Clock::now();
  const auto comparisons = compare_bounce_variants(reports);
  std::ostringstream table;
  TangentialLaw law = bounce.tangential;
  if (law.model == TangentialLaw::Model::kinematic) law.eps_t = bounce.eps_t;
  table << "tangential law of the explicit variants: " << law.describe() << "\n";
  table << format_bounce_table(reports);
  for (const auto& c : comparisons)
    table << "KS " << to_string(c.a) << " vs " << to_string(c.b) << ", " << c.by << " [" << c.lo << ", " << c.hi
          << "]: D = " << c.ks.D << ", p = " << c.ks.p << "\n";
  const double seconds_analysis = since(t0);
  t0 = Clock::now();
  std::vector<std::string> plots;
  if (s.plots) plots = write_bounce_plots(dir, reports, parse_plot_formats(s.plot_format));
  o.files = plots;
  const double seconds_plots = since(t0);
  o.table = detail::checked_text(std::move(table), "report.txt");
  const ReportHeader h =
      header_of(s, {stage("bounce", true, "bounce sequences per variant, fits and bootstrap goodness of fit", seconds_bounce),
                    stage("analysis", true, "two-sample KS between variants", seconds_analysis),
                    plots_stage(s, seconds_plots)});
  o.json = with_header(bounce_to_json(s.name, e.sphere, bounce, e.seed, reports, plots, comparisons), h);
  return o;
}

SceneOutput run_mesh_bounce(const Plan& p, const Progress& progress, const std::filesystem::path& dir) {
  const Scene& s = p.scene;
  const MeshBounceExperiment m = mesh_bounce_experiment(s);
  const TriangleMesh* mesh = p.mesh.get();  // read once, by plan()
  SceneOutput o;
  double seconds_export = 0;
  if (!s.mesh->export_ply.empty()) {
    const auto t0 = Clock::now();
    o.files.push_back(s.mesh->export_ply);
    export_first_body(s, *mesh, dir);
    seconds_export = since(t0);
  }
  MeshBounceReport r = run_mesh_bounces(m, mesh, progress);
  if (s.plots) {
    const auto t0 = Clock::now();
    r.plots = write_mesh_bounce_plots(dir, r, parse_plot_formats(s.plot_format));
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
          plots_stage(s, r.seconds_plots),
          export_stage(s, seconds_export)});
  o.json = with_header(to_json(r), h);
  return o;
}

// outputs.cor_table: the restitution table and its JSON header beside the report, named in the
// report (with the ensemble that produced it) and in the table's last lines.
void write_scene_cor_table(const Scene& s, const Progress& progress, const std::filesystem::path& dir, SceneOutput& o,
                           ReportHeader& h) {
  const auto t0 = Clock::now();
  const CorTableSpec spec = cor_table_spec(s, *s.cor_table);
  const CorTable t = make_cor_table(spec, progress);
  write_cor_table(dir / s.cor_table->file, t);
  const std::string header = cor_table_header_name(s.cor_table->file);
  o.files.push_back(s.cor_table->file);
  o.files.push_back(header);
  const double seconds = since(t0);
  h.timings_s.emplace_back("cor_table", seconds);
  const nlohmann::json j = {{"file", s.cor_table->file}, {"header", header},     {"ensemble", kCorTableEnsemble},
                            {"speeds", spec.speeds},    {"probabilities", spec.probabilities}, {"drops_per_speed", spec.drops},
                            {"format", t.format()},      {"spins", spec.spins},  {"omega_bands", spec.omega_bands}};
  h.sections.emplace_back("cor_table", j.dump());
  std::ostringstream line;
  line << "\nrestitution table: " << s.cor_table->file << " (+ " << header << "), " << spec.speeds.size() << " speeds x "
       << spec.drops << " drops, " << spec.probabilities << " probabilities; " << kCorTableEnsemble << "\n";
  o.table += line.str();
}

SceneOutput run_sphere(const Plan& p, const Progress& progress, const std::filesystem::path& dir, Collective* group,
                       ContactSamples* keep) {
  const Scene& s = p.given;
  const GeometryReport r = run_scene(p, progress, dir, group, keep);
  SceneOutput o;
  o.files = r.plots;
  o.rejected = r.rejected();
  for (const auto& t : r.tests)
    if (unresolved(t)) o.skipped.push_back(t.quantity + " " + t.law + " (" + std::string(to_string(t.verdict)) + "): " + t.note);
  o.table = format_table(r);
  ReportHeader h;
  h.scene = r.scene.name;
  h.scene_toml = r.scene_toml;
  h.plan = r.plan;
  h.timings_s = r.timings_s;
  if (s.cor_table) write_scene_cor_table(s, progress, dir.empty() ? s.out : dir, o, h);
  o.json = with_header(to_json(r), h);
  return o;
}

}  // namespace

GeometryReport run_scene(const Plan& p, const Progress& progress, const std::filesystem::path& dir, Collective* group,
                         ContactSamples* keep) {
  if (p.streams) return run_stream_scene(p, progress, dir, {}, nullptr, group);
  Plan plan;  // the stages, with their times
  plan.stages = p.stages;
  const Scene& run = p.scene;
  ContactSamples samples = run_contact_ensemble(run.ensemble, progress);
  auto t0 = Clock::now();
  GeometryReport r = analyse(run, samples);
  r.timings_s.emplace_back("analysis", since(t0));
  plan.stage("analysis").seconds = r.timings_s.back().second;
  if (plan.runs("plots")) {
    t0 = Clock::now();
    r.plots = write_plots(dir.empty() ? run.out : dir, run, samples);
    r.timings_s.emplace_back("plots", since(t0));
    plan.stage("plots").seconds = r.timings_s.back().second;
  }
  plan.stage("generate").seconds = samples.seconds_generate;
  plan.stage("index").seconds = samples.seconds_index;
  plan.stage("query").seconds = samples.seconds_query;
  if (plan.runs("cross_check")) plan.stage("cross_check").seconds = samples.cross_check.seconds;
  plan.stage("impact").seconds = samples.seconds_impact;
  r.plan = std::move(plan.stages);
  r.scene_toml = to_toml(p.given);
  if (keep) *keep = std::move(samples);
  return r;
}

GeometryReport run_scene(const Scene& s, const Progress& progress, const std::filesystem::path& dir) {
  return run_scene(plan(s), progress, dir);
}

SceneOutput run_plan(const Plan& p, const Progress& progress, std::ostream* log, const std::filesystem::path& dir,
                     Collective* group, ContactSamples* keep) {
  const ThreadCountScope thread_scope(p.scene.ensemble.threads);  // for this call only (core/thread_count.hpp)
  // Without a directory from the caller the run stages its own files in out and renames them
  // into place at the end: a failure leaves out as it was (output_staging.hpp).
  std::optional<OutputStaging> own;
  if (dir.empty()) own.emplace(p.scene.out);
  const std::filesystem::path& into = dir.empty() ? own->dir() : dir;
  SceneOutput o;
  switch (p.kind) {
    case RunKind::sphere: o = run_sphere(p, progress, into, group, keep); break;
    case RunKind::radii: o = run_radii(p, progress, into); break;
    case RunKind::mesh: o = run_mesh(p, progress, into); break;
    case RunKind::bounce: o = run_bounce(p, progress, log, into); break;
    case RunKind::mesh_bounce: o = run_mesh_bounce(p, progress, into); break;
  }
  o.kind = p.kind;
  if (own) {
    for (const auto& f : o.files) own->add(f);
    own->commit();
  }
  return o;
}

SceneOutput run_scene_output(const Scene& s, const Progress& progress, std::ostream* log, const std::filesystem::path& dir) {
  return run_plan(plan(s), progress, log, dir);
}

}  // namespace asperity
