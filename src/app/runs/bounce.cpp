// SPDX-License-Identifier: GPL-3.0-or-later
// Sec. V bouncing ball: sequences of impacts of the paper's sphere per variant (the paper's
// procedure, random orientation, dynamic), Eq. 2 fits with a bootstrap goodness of fit, and KS
// between variants (run_bounce_experiment, bounce.hpp).
#include <algorithm>
#include <cmath>
#include <ostream>

#include "asperity/app/experiment_reports.hpp"
#include "asperity/experiments/bounce.hpp"
#include "app/checked_text.hpp"
#include "app/runs/kinds.hpp"

namespace asperity::runs {

namespace {

bool recognise(const Scene& s) { return s.bounce.enabled && !s.mesh; }

// One impact kept for the analysis (measured 64 B per impact at 8000 sequences x 55.5 impacts, of
// which ~6 B are the block below's share).
constexpr double kPerImpactBounce = 58;
// run_bounces holds the impacts of a block of up to kBounceBlock sequences (48 B each, bounce.cpp
// Impact) until they are appended: negligible for short sequences, as much again as the kept
// impacts when a sequence runs to max_impacts (measured: fig6, 1000 asperities, 200 dynamic
// sequences, stop_speed = 1e-300: 99,502 impacts each, 1.83 GB; the flat 64 B estimated 0.224 GB).
constexpr double kPerImpactInBlock = 48;
// The paper's procedure (paper, paper-printed33, paper-corrected28) holds ~6x more per impact
// (measured: 178 MB at 8000 sequences x 55.5 impacts, 45 MB at 2000; 380 B per impact with the
// block's share, 360 B without).
constexpr double kPerImpactBouncePaper = 360;
// c = kEq9Slope x beta in 1 - eps = c u^(1/5): fitted to the measured mean of fig6, 55.5 impacts
// from 1 m/s down to 0.1 m/s at beta = 0.0467 (Eq. 9's leading coefficient is 1.153; the spread
// of the contact geometry lowers the mean).
constexpr double kEq9Slope = 1.128;

}  // namespace

double bounce_impacts(const BounceExperiment& b) {
  const double cap = double(b.max_impacts);
  const double c = kEq9Slope * b.beta;
  const double k = 5.0 / c * (std::pow(b.stop_speed, -0.2) - std::pow(b.speed, -0.2));
  return k < cap ? std::max(1.0, k) : cap;  // beta = 0 (no dissipation): inf, the cap
}

namespace {

// Impacts of every sequence of a variant are kept for its analysis; a second variant adds ~a
// sixth (measured: one variant 42 MB, two 48 MB at 8000 sequences).
double estimate(const Plan& p, std::ostringstream& d) {
  const BounceExperiment& b = p.given.bounce;
  const double impacts = bounce_impacts(b);
  const double seq = double(b.sequences);
  const double variants = 1.0 + (double(b.variants.size()) - 1.0) / 6.0;
  double per_impact = kPerImpactBounce;
  for (BounceVariant v : b.variants)
    if (to_string(v).starts_with("paper")) per_impact = kPerImpactBouncePaper;
  const double block = double(std::min<std::uint64_t>(b.sequences, kBounceBlock));
  d << b.sequences << " sequences x ~" << fmt3(impacts) << " impacts x " << per_impact << " B x " << fmt3(variants)
    << " (variants) + a block of " << block << " sequences x " << kPerImpactInBlock << " B per impact";
  return kBaseSphere + seq * impacts * (per_impact * variants) + block * impacts * kPerImpactInBlock;
}

std::string lower(const Scene&) { return "experiment.sequences (--sequences) or asperities.count (--asperities)"; }

// The table: the variants' tangential law, their reports, the KS comparisons between them.
std::string bounce_table(const BounceExperiment& bounce, const std::vector<BounceVariantReport>& reports,
                         const std::vector<BounceComparison>& comparisons) {
  std::ostringstream table;
  TangentialLaw law = bounce.tangential;
  if (law.model == TangentialLaw::Model::kinematic) law.eps_t = bounce.eps_t;
  table << "tangential law of the explicit variants: " << law.describe() << "\n";
  table << format_bounce_table(reports);
  for (const auto& c : comparisons)
    table << "KS " << to_string(c.a) << " vs " << to_string(c.b) << ", " << c.by << " [" << c.lo << ", " << c.hi
          << "]: D = " << c.ks.D << ", p = " << c.ks.p << "\n";
  return detail::checked_text(std::move(table), "report.txt");
}

SceneOutput run(const Plan& p, const RunIO& io) {
  const Scene& s = p.scene;
  const auto& e = s.ensemble;
  SceneOutput o;
  auto t0 = Clock::now();
  auto bounce = s.bounce;
  bounce.alpha = s.alpha;  // the verdicts of the Eq. 2 bootstrap use the scene's level
  bounce.tangential = e.impact.tangential;
  const auto reports = run_bounce_experiment(e.sphere, bounce, e.seed, e.threads, io.log, io.progress);
  const double seconds_bounce = since(t0);
  t0 = Clock::now();
  const auto comparisons = compare_bounce_variants(reports);
  o.table = bounce_table(bounce, reports, comparisons);
  const double seconds_analysis = since(t0);
  t0 = Clock::now();
  if (s.plots) o.files = write_bounce_plots(io.dir, reports, parse_plot_formats(s.plot_format));
  const double seconds_plots = since(t0);
  const ReportHeader h =
      header_of(s, {stage("bounce", true, "bounce sequences per variant, fits and bootstrap goodness of fit", seconds_bounce),
                    stage("analysis", true, "two-sample KS between variants", seconds_analysis),
                    plots_stage(s, seconds_plots)});
  o.json = with_header(bounce_to_json(s.name, e.sphere, bounce, e.seed, reports, o.files, comparisons), h);
  return o;
}

}  // namespace

const Kind kBounce{RunKind::bounce, "bounce", recognise, nullptr, estimate, lower, run};

}  // namespace asperity::runs
