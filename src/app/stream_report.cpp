// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/stream_report.hpp"

#include <boost/math/distributions/binomial.hpp>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <limits>
#include <iostream>
#include <locale>
#include <optional>
#include <numbers>
#include <sstream>

#include "app/checkpoint.hpp"
#include "app/io/interrupt.hpp"
#include "asperity/app/plot.hpp"
#include "asperity/app/scene_file.hpp"
#include "asperity/laws/binned.hpp"
#include "asperity/laws/block_ks.hpp"
#include "asperity/laws/theory.hpp"

namespace asperity {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string fmt(double v, int prec = 3) {
  std::ostringstream os;
  os << std::setprecision(prec) << v;
  return os.str();
}

// Mean with the se of a ratio estimator over blocks; quantiles from the fine histogram, interpolated
// linearly in u within a bin (se not estimated: NaN).
Summary summarize_binned(const BinnedStats& b, std::span<const double> probs) {
  Summary s;
  const Moments m = b.moments();
  s.n = m.n;
  s.mean.value = m.mean;
  s.std.value = std::sqrt(m.variance());
  s.std.se = kNaN;
  double ss = 0;
  std::size_t used = 0;
  for (const auto& g : b.block_moments)
    if (g.n) ss += std::pow(double(g.n) * (g.mean - m.mean), 2), ++used;
  s.mean.se = used > 1 ? std::sqrt(double(used) / double(used - 1) * ss) / double(m.n) : kNaN;
  s.batches = used;
  s.probs.assign(probs.begin(), probs.end());
  const double B = double(b.fine_bins());
  for (double p : probs) {
    const double target = p * double(m.n);
    double cum = 0;
    std::size_t j = 0;
    while (j + 1 < b.fine.size() && cum + double(b.fine[j]) < target) cum += double(b.fine[j++]);
    const double frac = b.fine[j] ? (target - cum) / double(b.fine[j]) : 0.5;
    s.quantiles.push_back({b.ref.quantile((double(j) + std::clamp(frac, 0.0, 1.0)) / B), kNaN});
  }
  return s;
}

struct StreamLaws {
  std::string quantity;
  std::vector<Law> laws;
};

std::vector<StreamLaws> stream_laws(const EnsembleConfig& e) {
  const auto n = e.sphere.asperities;
  const double R = e.sphere.radius;
  const Law rx = exact_sphere_rx(n, R);
  return {{"r_xy", {eq14_rxy(n, R), exact_sphere_rxy(n, R)}}, {"r_x", {eq18_rx(n, R), rx}}, {"r_y", {eq18_rx(n, R), rx}}};
}

// A report row by named fields (the common part first, laws/verdict.hpp LawTest).
TestReport test_row(const std::string& quantity, const std::string& law, const std::string& statistic, double D, double p,
                    std::uint64_t n, double predicted_mean, bool iid, bool decisive, Verdict verdict, std::string note) {
  TestReport r;
  r.quantity = quantity, r.law = law, r.decisive = decisive, r.verdict = verdict, r.note = std::move(note);
  r.statistic = statistic, r.D = D, r.p = p, r.n = n, r.predicted_mean = predicted_mean, r.iid = iid;
  return r;
}

TestReport row(const std::string& q, const Law& law, const BinnedTest& t, bool iid, bool decisive, double alpha) {
  TestReport r = test_row(q, law.name, t.statistic, t.statistic == "LR-block" ? kNaN : t.value, t.p, t.n, law.mean, iid,
                          decisive, std::isnan(t.p) ? Verdict::skipped : verdict_at(t.p, alpha), t.note);
  if (t.statistic == "LR-block") r.note = "z = " + fmt(t.value, 4) + "; " + r.note;
  if (!decisive) r.note += "; information only: the drops of one sphere are not iid";
  return r;
}

void design_and_note(GeometryReport& r, const Scene& scene, const ContactStream& s) {
  const auto& e = scene.ensemble;
  const bool expl = e.mode == Mode::explicit_spheres;
  auto& d = r.design;
  d.kind = expl ? "explicit" : "sampled";
  d.spheres = s.spheres, d.rotations_per_sphere = s.rotations;
  d.backend = expl ? std::string(to_string(e.backend)) : std::string("none");
  const DesignScales sc = design_scales(e.mode, e.sphere.asperities, s.spheres, r.samples);
  d.statistical_scale = sc.statistical, d.quenched_scale = sc.quenched;
  d.model_error_scale = model_error_scale(e.sphere.asperities, e.sphere.radius);
  std::ostringstream note;
  if (expl)
    note << "explicit geometry: " << s.spheres << " sphere(s) of " << e.sphere.asperities << " asperities x "
         << s.rotations << " Haar-random rotations each; every contact found by a " << to_string(e.backend)
         << " spatial query. ";
  else
    note << "sampled from the exact finite-N law of the lowest asperity -- no geometry; drops are iid. ";
  note << "Statistics: " << r.statistics << "; no drop is kept (memory independent of the drops). Decisive tests: KS of all drops on 2^" << kStreamCoarseLog2
       << " cells with a sphere-block bootstrap p, and for r_xy the likelihood ratio of Eq. 14 against the exact "
          "finite-N law with its se from the spread between "
       << s.state.stats[0].blocks << " blocks of whole " << (expl ? "spheres" : "drops") << ".";
  r.ensemble_note = note.str();
}

}  // namespace

std::string streaming_label(const EnsembleConfig& c) {
  return "streaming histogram, 2^" + std::to_string(c.bins_log2) +
         " bins of u = F_ref(x) per quantity (F_ref: Eq. 14 for r_xy, Eq. 18 for r_x, r_y) and 2^" +
         std::to_string(kStreamCoarseLog2) + " cells per block of spheres";
}

GeometryReport analyse_stream(const Scene& scene, const ContactStream& s) {
  GeometryReport r;
  r.scene = scene;
  const auto& e = scene.ensemble;
  const auto& sp = e.sphere;
  const bool expl = e.mode == Mode::explicit_spheres;
  r.samples = s.state.stats[0].n();
  r.statistics = streaming_label(e);
  r.core_contacts = s.state.core_contacts;
  r.core_probability = core_contact_probability(sp.asperities, sp.radius, sp.asperity_radius);
  r.core_probability_paper = core_contact_probability_paper(sp.asperities, sp.radius, sp.asperity_radius);
  r.gap_min = r.gap_median = kNaN;  // not streamed
  r.index_bytes = s.index_bytes;
  r.cross_check = s.cross_check;
  if (expl) r.quenched_scale = quenched_deviation_scale(sp.asperities);
  design_and_note(r, scene, s);
  const bool decisive_design = !expl || s.spheres >= kMinDecisiveSpheres;
  const std::vector<double> probs{0.01, 0.05, 0.25, 0.5, 0.75, 0.95, 0.99};
  const auto sets = stream_laws(e);
  for (std::size_t qi = 0; qi < sets.size(); ++qi) {
    const BinnedStats& b = s.state.stats[qi];
    const auto& set = sets[qi];
    r.quantities.push_back({set.quantity, summarize_binned(b, probs)});
    std::vector<Cdf> cdfs;
    for (const auto& l : set.laws) cdfs.push_back(l.cdf);
    // A rejected law's p resolved to alpha/50: Holm compares the smallest p with alpha/m (m <= 20 here,
    // most of them with analytic p-values; the bootstrap's floor 1/(B + 1) must not hide a rejection).
    const std::vector<double> resolve(cdfs.size(), scene.alpha / 10);
    const auto boot = block_ks_tests(to_block_bins(b), cdfs, scene.alpha, e.seed, qi, 199, 9999, resolve);
    for (std::size_t li = 0; li < set.laws.size(); ++li) {
      const Law& law = set.laws[li];
      r.tests.push_back(test_row(set.quantity, law.name, "KS-sphere-bootstrap", boot[li].D, boot[li].p, r.samples, law.mean,
                                 false, decisive_design, decisive_design ? boot[li].verdict : Verdict::not_decisive,
                                 "B = " + std::to_string(boot[li].replicates) + " block bootstrap replicates over " +
                                     std::to_string(b.blocks) + " blocks; 2^" + std::to_string(kStreamCoarseLog2) +
                                     " cells of u, resolution 2^-" + std::to_string(kStreamCoarseLog2)));
      r.tests.push_back(row(set.quantity, law, binned_ks(b, law.cdf), !expl, !expl, scene.alpha));
      r.tests.push_back(row(set.quantity, law, binned_chi2(b, law.cdf), !expl, !expl, scene.alpha));
    }
    if (set.quantity == "r_xy" && b.blocks >= 2) {
      const LrTest lr = binned_lr(b, set.laws[0].cdf, set.laws[1].cdf);
      const std::string kl = "; L = " + fmt(lr.L, 4) + " +- " + fmt(lr.se, 2) + " per drop, KL(eq14||exact) = " +
                             fmt(lr.kl01, 4) + ", KL(exact||eq14) = " + fmt(lr.kl10, 4);
      r.tests.push_back(row(set.quantity, set.laws[0], lr.law0, false, decisive_design, scene.alpha));
      r.tests.back().note += kl;
      r.tests.push_back(row(set.quantity, set.laws[1], lr.law1, false, decisive_design, scene.alpha));
      r.tests.back().note += kl;
    }
  }
  TestReport core = test_row("core_contacts", "exact-sphere", "binomial", kNaN, 1, r.samples,
                             r.core_probability * double(r.samples), !expl, !expl, Verdict::accept, "");
  boost::math::binomial_distribution<double> bin(double(r.samples), r.core_probability);
  const double k = double(r.core_contacts);
  core.p = std::min(1.0, 2.0 * std::min(boost::math::cdf(bin, k),
                                        k > 0 ? boost::math::cdf(boost::math::complement(bin, k - 1)) : 1.0));
  core.verdict = verdict_at(core.p, scene.alpha);
  core.note = "central sphere touched first";
  if (expl) core.note += "; iid binomial p-value, the spread between spheres is not accounted for: information only";
  r.tests.push_back(core);
  r.timings_s = {{"generate", s.seconds_generate}, {"index", s.seconds_index}, {"query", s.seconds_query}};
  return r;
}

BandFigure finite_n_figure(const Scene& scene, const ContactStream& s) {
  const auto& sp = scene.ensemble.sphere;
  const Law eq14 = eq14_rxy(sp.asperities, sp.radius), exact = exact_sphere_rxy(sp.asperities, sp.radius);
  const CdfBand band = pooled_cdf(s.state.stats[0]);
  BandFigure f;
  f.title = "finite-N correction of Eq. (14): N = " + std::to_string(sp.asperities);
  f.xlabel = "r_{xy} [µm]";
  f.ylabel = "F(r_{xy}) - F_{Eq. 14}(r_{xy})";
  f.x_scale = 1e6;
  const bool expl = scene.ensemble.mode == Mode::explicit_spheres;
  f.data_label = (expl ? "explicit geometry: " + std::to_string(s.spheres) + " spheres x " + std::to_string(s.rotations) +
                             " rotations"
                       : std::string("sampled from the exact law, no geometry")) +
                 ", ±1 se between blocks (n = " + std::to_string(s.state.stats[0].n()) + ")";
  // Every 16th coarse edge in the bulk (the tails carry nothing at this scale).
  for (std::size_t j = 15; j < band.x.size(); j += 16) {
    if (band.x[j] > 4 * s.state.stats[0].ref.sigma) break;
    f.x.push_back(band.x[j]);
    f.y.push_back(band.cdf[j] - eq14.cdf(band.x[j]));
    f.se.push_back(band.se[j]);
  }
  const double hi = 4 * s.state.stats[0].ref.sigma;
  f.curves.push_back(sampled_curve([&](double x) { return exact.cdf(x) - eq14.cdf(x); },
                                   "predicted: exact finite-N law - Eq. (14)", 0, hi, 300));
  f.curves.push_back(sampled_curve([](double) { return 0.0; }, "Eq. (14)", 0, hi, 2));
  return f;
}

namespace {

// What a share sends besides its histograms: the block moments (each block is one process's) and
// the counters, a few kB.
std::string share_summary(const StreamState& st) {
  std::string out;
  auto put = [&](const auto& v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); };
  put(st.core_contacts), put(st.check_queries), put(st.check_agreed), put(st.index_bytes);
  for (const auto& b : st.stats)
    for (const Moments& m : b.block_moments) put(m);
  return out;
}

// Adds a share's summary to `into` as merge_shares would (its histograms are summed separately).
void merge_summary(StreamState& into, const std::string& bytes, int rank) {
  std::size_t at = 0;
  auto get = [&](auto& v) {
    if (bytes.size() - at < sizeof v) throw std::runtime_error("the share of rank " + std::to_string(rank) + " is truncated");
    std::memcpy(&v, bytes.data() + at, sizeof v);
    at += sizeof v;
  };
  std::uint64_t core = 0, queries = 0, agreed = 0, index = 0;
  get(core), get(queries), get(agreed), get(index);
  into.core_contacts += core, into.check_queries += queries, into.check_agreed += agreed;
  into.index_bytes = std::max(into.index_bytes, index);
  for (auto& b : into.stats)
    for (Moments& m : b.block_moments) {
      Moments o;
      get(o);
      m.merge(o);
    }
  if (at != bytes.size()) throw std::runtime_error("the share of rank " + std::to_string(rank) + " has trailing bytes");
}

// Rank 0 receives every share and merges it into its own: the histograms are summed (integers),
// the block moments merged (disjoint blocks: the same bits as one process), the counters added.
// Timings stay rank 0's own.
void gather_shares(ContactStream& cs, Collective& group) {
  StreamState& st = cs.state;
  const std::vector<std::string> parts = group.gather(share_summary(st));
  for (auto& b : st.stats) {
    group.sum(b.fine);
    group.sum(b.coarse);
  }
  if (group.rank() != 0) return;
  // The summed histograms are already in st; merge_summary adds only moments and counters.
  for (std::size_t r = 1; r < parts.size(); ++r) merge_summary(st, parts[r], int(r));
  cs.complete = true;
  cs.index_bytes = static_cast<std::size_t>(st.index_bytes);
  cs.cross_check.queries = st.check_queries, cs.cross_check.agreed = st.check_agreed;
}

// The stream of the planned ensemble, or of this process's share (p.control.share), with
// checkpoints in the scene's out (not the staging directory: a checkpoint outlives an interrupted
// run): every p.control.checkpoint_seconds, and when a signal arrives (validate-geometry: the signal waits for the end
// of a wave, the checkpoint is written, then the signal ends the process as usual, exit 128 +
// signal). With a group, every process learns whether all completed (a process that completed
// while another stopped writes its finished share too, so that the resume skips it), and the
// shares are gathered at rank 0, which returns the merged stream.
ContactStream stream_with_checkpoints(const Plan& p, const Progress& progress,
                                      const StreamHooks& given, const StreamState* resume, Collective* group) {
  const Scene& s = p.given;
  const RunControl& c = p.control;
  StreamHooks h = given;
  using Clock = std::chrono::steady_clock;
  auto last = Clock::now();
  if (!h.stop) h.stop = [] { return interrupt_pending() != 0; };
  if (!h.checkpoint_due && c.checkpoint_seconds > 0)
    h.checkpoint_due = [&] { return std::chrono::duration<double>(Clock::now() - last).count() >= c.checkpoint_seconds; };
  if (!h.checkpoint)
    h.checkpoint = [&](const StreamState& st) {
      write_checkpoint(s.out, p, st);
      last = Clock::now();
    };
  std::optional<InterruptDeferral> defer;
  if (interrupt_cleanup_installed()) defer.emplace();
  // 0 complete, 1 stopped (checkpoint written), 2 failed: the worst of all processes decides.
  int status = 0;
  std::string error;
  ContactStream cs;
  try {
    StreamState resumed;
    if (!resume && c.resume) resumed = read_checkpoint(s.out, p), resume = &resumed;
    cs = run_contact_stream(p.scene.ensemble, progress, h, resume, c.share);
    status = cs.complete ? 0 : 1;
  } catch (const std::exception& ex) {
    if (!group) throw;
    status = 2, error = ex.what();
  }
  if (group) status = group->max(status);
  if (status == 2) {
    if (error.empty()) throw StreamEnded("another process of this run failed (its message is above)");
    throw std::runtime_error(error);
  }
  if (status == 1) {
    if (cs.complete) h.checkpoint(cs.state);
    const std::string where = (s.out / checkpoint_state_name(c.share)).string();
    if (c.share.rank == 0)
      std::cerr << "\nvalidate-geometry: stopped after " << cs.state.stats[0].n() << " of " << share_drops(p.scene.ensemble, c.share)
                << " drops" << (c.share.ranks > 1 ? " of rank 0's share" : "") << "; checkpoint in " << where
                << ": continue with " << (c.share.ranks > 1 ? "mpirun -np " + std::to_string(c.share.ranks) + " " : "")
                << "validate-geometry --resume " << s.out.string() << "\n";
    defer.reset();  // a pending signal ends the process here
    throw StreamEnded("the streaming run stopped before its last drop; checkpoint in " + where);
  }
  if (group) gather_shares(cs, *group);
  return cs;
}
}  // namespace

GeometryReport run_stream_scene(const Plan& p, const Progress& progress, const std::filesystem::path& dir,
                                const StreamHooks& hooks, const StreamState* resume, Collective* group) {
  const Scene& run = p.scene;
  Plan plan;  // the stages, with their times
  plan.stages = p.stages;
  const ContactStream cs = stream_with_checkpoints(p, progress, hooks, resume, group);
  auto t0 = std::chrono::steady_clock::now();
  auto since = [](auto t) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count(); };
  GeometryReport r = analyse_stream(run, cs);
  r.timings_s.emplace_back("analysis", since(t0));
  plan.stage("analysis").seconds = r.timings_s.back().second;
  plan.stage("analysis").reason = "contact laws of r_xy, r_x, r_y on the streamed histograms (" + streaming_label(run.ensemble) + ")";
  if (plan.runs("plots")) {
    plan.stage("plots").reason = "outputs.plots: streaming keeps no drops, so one figure: finite_n.png and .csv (measured F - F_Eq14 "
                                 "of r_xy with its band between blocks, against the exact finite-N law)";
    // validate-geometry refuses a run that asks for figures it cannot draw; a library caller
    // without PLplot gets the report without the figure.
    if (const PlotFormats formats = parse_plot_formats(run.plot_format); plotting_problem(formats).empty()) {
      t0 = std::chrono::steady_clock::now();
      r.plots = write_figure(dir.empty() ? run.out : dir, "finite_n", band_figure(finite_n_figure(run, cs)), formats);
      r.timings_s.emplace_back("plots", since(t0));
      plan.stage("plots").seconds = r.timings_s.back().second;
    }
  }
  plan.stage("generate").seconds = cs.seconds_generate;
  plan.stage("index").seconds = cs.seconds_index;
  plan.stage("query").seconds = cs.seconds_query;
  r.plan = std::move(plan.stages);
  r.scene_toml = to_toml(p.given);
  return r;
}

void run_stream_share(const Plan& p, Collective& group) { stream_with_checkpoints(p, {}, {}, nullptr, &group); }

}  // namespace asperity
