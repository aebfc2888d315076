// SPDX-License-Identifier: GPL-3.0-or-later
// Unequal asperity radii on a sphere (levels or lognormal): contacts only, r_x against the exact
// level law and the Gaussians of lambda and lambda_eff (run_radii_experiment, body_experiments.hpp).
#include "asperity/app/experiment_reports.hpp"
#include "asperity/app/plot.hpp"
#include "asperity/experiments/body_experiments.hpp"
#include "app/runs/kinds.hpp"

namespace asperity::runs {

namespace {

bool recognise(const Scene& s) { return !s.bounce.enabled && !s.mesh && s.radii; }

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

// An unequal-radii sphere screened for lambda_eff (one at a time): centres and radii (32 B), its
// support tree, the screening's unit directions, support radii, competitor counts and status,
// and the per-asperity competitor lists of the cap test. Measured: 256 MB at N = 2.5e5, 503 MB at
// 5e5 (--threads 1; 487 MB with 2 threads): the slope.
constexpr double kPerAsperityScreened = 985;

double estimate(const Plan& p, std::ostringstream& d) {
  const auto& e = p.given.ensemble;
  d << e.drops << " drops x " << kPerDropFresh << " B + one screened sphere of " << e.sphere.asperities
    << " asperities x " << kPerAsperityScreened << " B";
  return kBaseSphere + kPerDropFresh * double(e.drops) + double(e.sphere.asperities) * kPerAsperityScreened;
}

std::string lower(const Scene&) { return "asperities.count (--asperities) or ensemble.drops (--drops)"; }

std::vector<PlanStage> stages_of(const Scene& s, const RadiiReport& r) {
  const bool lognormal = s.radii->radii.kind == RadiusDistribution::Kind::lognormal;
  return {stage("screening", true,
                "lambda_eff: " + std::to_string(s.radii->screen_bodies) + " explicit spheres screened" +
                    (lognormal ? ", rotated for r_x (no exact sampler for lognormal radii)" : ""),
                r.seconds_screen),
          stage("query", !lognormal,
                lognormal ? "lognormal radii: r_x comes from rotations of the screened spheres"
                          : "fresh drops: exact sampler of the lowest asperities (level radii)",
                r.seconds_fresh),
          stage("analysis", true, "r_x against the exact level law and Gaussians with lambda, lambda_eff",
                r.seconds_analysis),
          plots_stage(s, r.seconds_plots)};
}

SceneOutput run(const Plan& p, const RunIO& io) {
  const Scene& s = p.scene;
  RadiiReport r = run_radii_experiment(radii_experiment(s), io.progress);
  if (s.plots) {
    const auto t0 = Clock::now();
    r.plots = write_figures(io.dir, r.figures, parse_plot_formats(s.plot_format));
    r.seconds_plots = since(t0);
  }
  SceneOutput o;
  o.files = r.plots;
  o.rejected = r.rejected();
  o.skipped = skipped_of(r.tests);
  o.table = format_table(r);
  o.json = with_header(to_json(r), header_of(s, stages_of(s, r)));
  return o;
}

}  // namespace

const Kind kRadii{RunKind::radii, "radii", recognise, nullptr, estimate, lower, run};

}  // namespace asperity::runs
