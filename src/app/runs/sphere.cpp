// SPDX-License-Identifier: GPL-3.0-or-later
// The paper's sphere: contacts and single impacts of equal asperities, sampled from the exact
// finite-N law or found in explicit spheres (the run of run_scene, run.hpp); a restitution table
// beside the report when outputs.cor_table asks for one.
#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "asperity/app/cor_table.hpp"
#include "asperity/app/plot.hpp"
#include "asperity/app/resources.hpp"
#include "asperity/app/scene_file.hpp"
#include "app/stream_report.hpp"
#include "asperity/config.hpp"
#include "asperity/experiments/streaming.hpp"
#include "app/runs/kinds.hpp"

namespace asperity {

namespace runs {

namespace {

bool recognise(const Scene& s) { return !s.bounce.enabled && !s.mesh && !s.radii; }

// The stages of a sphere run, with ensemble.spheres, ensemble.backend and ensemble.impact.enabled
// resolved in p.scene.
void plan_generate_and_index(Plan& p) {
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
}

void plan_query_and_check(Plan& p) {
  const auto& e = p.scene.ensemble;
  const bool fixed = e.mode == Mode::explicit_spheres;
  p.stages.push_back({"query", true,
                      "lowest asperity of each of " + std::to_string(e.drops) + " drops" +
                          (fixed ? std::string(" by spatial query") : std::string(" (exact sampler, no geometry)"))});
  if (fixed)
    p.stages.push_back({"cross_check", true,
                        "a deterministic subsample of the queries answered again by brute force and the kd-tree (and FCL "
                        "where built and N is small)"});
  else
    p.stages.push_back({"cross_check", false, "sampled: no spatial queries to check"});
}

void plan_analysis(Plan& p) {
  const Scene& s = p.given;
  auto& e = p.scene.ensemble;
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

void plan_sphere(Plan& p) {
  plan_generate_and_index(p);
  plan_query_and_check(p);
  plan_analysis(p);
}

// Measured per drop of explicit spheres: contact samples + the rotation (fig3-fixed at 2.5e5, 5e5,
// 1e6, 2e6 drops: 40-46 B per drop between sizes; 57 before, which put fig3-fixed at 1.21x).
constexpr double kPerDropFixed = 46;

// The cross-check of one sphere (ensemble.cpp cross_check_sphere) while the run's index lives: a
// kd-tree over the same centres unless it is the backend, and FCL's tree for small N (measured:
// brute, one sphere of 2e6: 91.1 MB, 40 B per asperity = the centres + the kd-tree).
double one_sphere_check(Backend b, double N) {
  const double brute = bytes_per_asperity(Backend::brute);
  double extra = b == Backend::kdtree ? 0.0 : bytes_per_asperity(Backend::kdtree) - brute;
#if ASPERITY_WITH_FCL
  if (b != Backend::fcl && N <= double(kCrossCheckFclMax)) extra += bytes_per_asperity(Backend::fcl) - brute;
#else
  (void)N;
#endif
  return extra;
}

// Streaming keeps no drop: 3 quantities x (a fine histogram per thread + the merged one + the
// per-block cells) x 8 B (experiments/streaming.hpp), + the fine bins' edges of each distinct
// reference law (streaming.cpp Binners: r_x and r_y share theirs, r_xy has its own), 8 B per edge.
double streaming_bytes(const Plan& p, std::ostringstream& d) {
  const auto& pe = p.scene.ensemble;
  const int threads = threads_of(p.given);
  const double fine = std::ldexp(1.0, int(pe.bins_log2)), cells = double(kStreamBlocks << kStreamCoarseLog2);
  const double edges = 2 * 8 * (fine + 1);
  d << "streaming histograms (2^" << pe.bins_log2 << " bins x " << threads + 1 << " + " << cells
    << " cells, x 3 quantities x 8 B, + 2 x 2^" << pe.bins_log2 << " bin edges x 8 B; no drop kept)";
  return kBaseSphere + 3 * 8 * (fine * (threads + 1) + cells) + edges;
}

// One sphere: its rotations in parallel; K > 1 spheres: one sphere per busy thread (ensemble.cpp),
// K from the plan (the error budget when spheres = "auto"), + the kd-tree of the cross-check (one
// checked sphere at a time, measured when spheres run in parallel) unless it is the backend. One
// sphere: the checked sphere's centres are the run's; the trees are extra.
double explicit_spheres_bytes(const Plan& p, std::ostringstream& d) {
  const auto& pe = p.scene.ensemble;
  const double N = double(pe.sphere.asperities);
  const int threads = threads_of(p.given);
  const double concurrent = pe.spheres <= 1 ? 1.0 : double(std::min<std::uint64_t>(std::uint64_t(threads), pe.spheres));
  const double b = bytes_per_asperity(pe.backend);
  // K > 1: the checked sphere's kd-tree (with its own centres) and, for small N, FCL's tree
  // (cross_check_backends; measured: example.toml at N = 20000 peaks 9.4 MB above N = 20001).
  double check = pe.spheres <= 1 ? one_sphere_check(pe.backend, N)
                 : pe.backend == Backend::kdtree ? 0.0 : bytes_per_asperity(Backend::kdtree);
#if ASPERITY_WITH_FCL
  if (pe.spheres > 1 && pe.backend != Backend::fcl && N <= double(kCrossCheckFclMax))
    check += bytes_per_asperity(Backend::fcl) - bytes_per_asperity(Backend::brute);
#endif
  d << " + " << fmt3(concurrent) << " sphere(s) at once (--threads " << threads << ") x " << pe.sphere.asperities
    << " asperities x " << b << " B (" << to_string(pe.backend) << ")";
  return concurrent * N * b + N * check;
}

double estimate(const Plan& p, std::ostringstream& d) {
  const Scene& s = p.given;
  const auto& pe = p.scene.ensemble;
  double per_drop = pe.mode == Mode::sampled ? kPerDropFresh : kPerDropFixed;
  if (pe.impact.enabled) per_drop = kPerDropImpact;
  double bytes = kBaseSphere + per_drop * double(s.ensemble.drops);
  if (p.streams) bytes = streaming_bytes(p, d);
  else d << s.ensemble.drops << " drops x " << per_drop << " B";
  if (pe.mode == Mode::explicit_spheres) bytes += explicit_spheres_bytes(p, d);
  if (s.cor_table) {  // after the run, its samples freed
    const double table = cor_table_bytes(cor_table_spec(s, *s.cor_table));
    if (table > bytes) d << "; outputs.cor_table: " << s.cor_table->drops << " drops per speed x " << kPerDropImpact << " B";
    bytes = std::max(bytes, table);
  }
  return bytes;
}

std::string lower(const Scene&) {
  return "asperities.count (--asperities), ensemble.drops (--drops), ensemble.spheres (--spheres) or ensemble.threads "
         "(--threads)";
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

SceneOutput run(const Plan& p, const RunIO& io) {
  const Scene& s = p.given;
  const GeometryReport r = run_scene(p, io.progress, io.dir, io.group, io.keep);
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
  if (s.cor_table) write_scene_cor_table(s, io.progress, io.dir.empty() ? s.out : io.dir, o, h);
  o.json = with_header(to_json(r), h);
  return o;
}

}  // namespace

const Kind kSphere{RunKind::sphere, "sphere", recognise, plan_sphere, estimate, lower, run};

}  // namespace runs

GeometryReport run_scene(const Plan& p, const Progress& progress, const std::filesystem::path& dir, Collective* group,
                         ContactSamples* keep) {
  if (p.streams) return run_stream_scene(p, progress, dir, {}, nullptr, group);
  Plan plan;  // the stages, with their times
  plan.stages = p.stages;
  const Scene& run = p.scene;
  ContactSamples samples = run_contact_ensemble(run.ensemble, progress);
  auto t0 = runs::Clock::now();
  GeometryReport r = analyse(run, samples);
  r.timings_s.emplace_back("analysis", runs::since(t0));
  plan.stage("analysis").seconds = r.timings_s.back().second;
  if (plan.runs("plots")) {
    t0 = runs::Clock::now();
    r.plots = write_plots(dir.empty() ? run.out : dir, run, samples);
    r.timings_s.emplace_back("plots", runs::since(t0));
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

}  // namespace asperity
