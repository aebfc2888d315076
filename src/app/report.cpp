// SPDX-License-Identifier: GPL-3.0-or-later
#include "checked_text.hpp"
#include "asperity/app/report.hpp"

#include "app/io/atomic_file.hpp"

#include <boost/math/distributions/binomial.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <exception>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

#include "asperity/app/plot.hpp"
#include "asperity/config.hpp"
#include "asperity/core/random.hpp"
#include "asperity/laws/atom.hpp"
#include "asperity/laws/block_ks.hpp"
#include "asperity/laws/family.hpp"
#include "asperity/laws/theory.hpp"
#include "asperity/laws/theory_impact.hpp"

namespace asperity {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
const std::vector<double> kProbs{0.01, 0.05, 0.25, 0.5, 0.75, 0.95, 0.99};
// The grid of the explicit design's binned KS statistic (points at pooled-sample quantiles: the
// binned D is at most ~1/kKsGrid below the full one) and the most blocks its bootstrap resamples
// (groups of whole spheres beyond that: a replicate costs O(blocks x grid)).
constexpr std::size_t kKsGrid = 1024;
constexpr std::size_t kMaxBlocks = 256;
// A rejected law's bootstrap p is resolved to alpha/(5 x 10): Holm's smallest threshold is alpha/m,
// and a run has at most 8 decisive bootstrap and LR tests (r_xy, r_x, r_y, eps, Omega'_x).
constexpr double kFamilyResolve = 10;

std::vector<double> sorted(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// KS of x against a law with an atom of mass m at `atom`, taken by the samples flagged in `at_atom`:
// u_i = F(x_i) elsewhere, u_i = F(atom) - m + V_i m there (V_i uniform from a counter-based
// stream), and the u_i are tested against the uniform law. Without atom samples this is the plain
// KS test. Parallel over samples; the result does not depend on the thread count.
KsResult ks_mixed(const std::vector<double>& x, const std::vector<std::uint8_t>& at_atom, const Law& law, double atom,
                  double mass, std::uint64_t seed) {
  std::vector<double> u(x.size());
  const double below = law.cdf(atom) - mass;
  const std::int64_t n = static_cast<std::int64_t>(x.size());
  // law.cdf may throw far outside a law's regime; an exception must not leave the OpenMP region.
  std::exception_ptr error;
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) try {
    const auto k = static_cast<std::size_t>(i);
    if (!at_atom.empty() && at_atom[k]) {
      Stream st(seed, Purpose::analysis, k);
      u[k] = below + st.uniform0() * mass;
    } else {
      u[k] = law.cdf(x[k]);
    }
  } catch (...) {
#pragma omp critical(asperity_ks_mixed_error)
    if (!error) error = std::current_exception();
  }
  if (error) std::rethrow_exception(error);
  std::sort(u.begin(), u.end());
  return ks_one_sample(u, [](double t) { return std::clamp(t, 0.0, 1.0); });
}

struct LawSet {
  std::string quantity;
  std::vector<Law> laws;
  std::vector<bool> decisive;  // printed laws with known errors are reported, not decisive
  // Corrected impact laws include core contacts as an atom of mass p_core at `atom`; their KS
  // test uses the randomised probability integral transform there (exact for mixed laws).
  std::vector<bool> has_atom = {};
  double atom = 0, atom_mass = 0;
};

ImpactScene impact_scene(const EnsembleConfig& e) {
  ImpactScene x;
  x.asperities = e.sphere.asperities;
  x.radius = e.sphere.radius;
  x.asperity_radius = e.sphere.asperity_radius;
  x.speed = e.impact.speed;
  x.omega_x = e.impact.omega.x();
  x.omega_y = e.impact.omega.y();
  x.beta = e.impact.beta;
  return x;
}

// A law the run should have tested but could not: reported with verdict "skipped".
struct SkippedLaw {
  std::string quantity, law;
  bool decisive = false;
  std::string reason;
};

// The Sec. IV laws by name, as laws_for builds them (decisive: the corrected ones).
std::vector<SkippedLaw> sec4_laws(const std::string& reason) {
  return {{"eps", "eq28-printed", false, reason},        {"eps", "eq28-paper-route", false, reason},
          {"eps", "eq28-corrected", true, reason},       {"omega_x_after", "eq33-printed", false, reason},
          {"omega_x_after", "eq33-corrected", true, reason}};
}

// The laws of the requested outputs only: contact laws if `contact`, impact laws if the
// experiment has impacts (the planner turns impacts off when restitution is not requested).
// `impact_laws`: the Sec. IV laws describe every drop; when some drops did not impact, the eps
// sample is truncated and those laws do not apply. `note` collects laws that were not tested,
// `skipped` lists them.
namespace {

// A law's name as a figure's legend says it (report.json and the table keep the name): the paper's
// equation and what was done to it; a name not listed reads "eqNN-x-y" as "Eq. (NN) x y".
std::string legend_label(const std::string& name) {
  static const std::pair<const char*, const char*> known[] = {
      {"eq14", "Eq. (14), Rayleigh"},
      {"eq18", "Eq. (18), Gaussian"},
      {"exact-sphere", "exact finite-N law on the sphere"},
      {"eq28-printed", "Eq. (28) as printed"},
      {"eq28-paper-route", "Eq. (28) by the paper's route, carried out"},
      {"eq28-corrected", "Eq. (28) corrected"},
      {"eq33-printed", "Eq. (33) as printed"},
      {"eq33-corrected", "Eq. (33) corrected"},
      {"exact-levels", "exact law over the radius levels"},
  };
  for (const auto& [id, text] : known)
    if (name == id) return text;
  std::string out = name;
  for (char& c : out)
    if (c == '-') c = ' ';
  if (out.rfind("eq", 0) == 0 && out.size() > 2 && std::isdigit(static_cast<unsigned char>(out[2]))) {
    const std::size_t end = out.find(' ');
    out = "Eq. (" + out.substr(2, end == std::string::npos ? std::string::npos : end - 2) + ")" +
          (end == std::string::npos ? "" : out.substr(end));
  }
  return out;
}

}  // namespace

std::vector<LawSet> laws_for(const EnsembleConfig& e, bool contact, bool impact_laws, std::string& note,
                             std::vector<SkippedLaw>* skipped = nullptr) {
  const auto& p = e.sphere;
  const double R = p.radius;
  const auto n = p.asperities;
  std::vector<LawSet> sets;
  if (contact) {
    const Law rx = exact_sphere_rx(n, R);  // tabulated once, shared by r_x and r_y
    sets = {{"r_xy", {eq14_rxy(n, R), exact_sphere_rxy(n, R)}, {true, true}, {false, false}},
            {"r_x", {eq18_rx(n, R), rx}, {true, true}, {false, false}},
            {"r_y", {eq18_rx(n, R), rx}, {true, true}, {false, false}}};
  }
  // The Sec. IV laws assume eps_t = 1 and a horizontal spin.
  if (e.impact.enabled && !impact_laws) {
    note = " Sec. IV laws not tested: some drops did not impact (contact point not approaching the plate), so the "
           "eps and Omega'_x samples are truncated.";
    if (skipped) *skipped = sec4_laws("some drops did not impact: the eps and Omega'_x samples are truncated");
  } else if (e.impact.enabled && e.impact.eps_t == 1.0 && e.impact.omega.z() == 0.0) {
    ImpactScene x = impact_scene(e);
    ImpactScene physical = x;
    physical.core_contacts = true;  // explicit geometry lets the bare sphere touch: so must the law
    // Far outside the paper's regime (e.g. spin >> speed) a law's distribution cannot be built
    // (Boost rejects its parameters): report that instead of failing the whole run.
    try {
      const auto par = impact_law_parameters(physical);
      LawSet eps{"eps", {eq28_printed(x), eq28_paper_route(x), eq28_corrected(physical)}, {false, false, true},
                 {false, false, true}, par.eps_n, par.p_core};
      LawSet wx{"omega_x_after", {eq33_printed(x), eq33_corrected(physical)}, {false, true}, {false, true},
                x.omega_x, par.p_core};
      sets.push_back(std::move(eps));
      sets.push_back(std::move(wx));
    } catch (const std::exception& ex) {
      note = std::string(" Sec. IV laws not tested: they cannot be evaluated at these parameters (") + ex.what() + ").";
      if (skipped) *skipped = sec4_laws(std::string("cannot be evaluated at these parameters: ") + ex.what());
    }
  }
  return sets;
}

const std::vector<double>& column(const ContactSamples& s, const std::string& q) {
  if (q == "r_xy") return s.r_xy;
  if (q == "r_x") return s.r_x;
  if (q == "r_y") return s.r_y;
  if (q == "eps") return s.eps;
  if (q == "omega_x_after") return s.omega_x_after;
  return s.r_z;
}

// Display scale and unit of a quantity in the table (JSON is always SI).
double display_scale(const std::string& q) { return q.rfind("r_", 0) == 0 ? 1e6 : 1.0; }
std::string si_unit(const std::string& q) {
  if (q == "eps") return "1";
  if (q == "omega_x_after") return "rad/s";
  return "m";
}

std::string fmt(double v, int prec = 4) {
  if (std::isnan(v)) return "-";
  std::ostringstream os;
  os << std::setprecision(prec) << v;
  return os.str();
}

nlohmann::json plan_json(const std::vector<PlanStage>& plan) {
  using nlohmann::json;
  json out = json::array();
  for (const auto& st : plan)
    out.push_back({{"stage", st.name}, {"run", st.run}, {"reason", st.reason},
                   {"seconds", st.run ? json(st.seconds) : json(nullptr)}});
  return out;
}

nlohmann::json timings_json(const std::vector<std::pair<std::string, double>>& timings) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [k, v] : timings) out[k] = v;
  return out;
}

}  // namespace

FamilyDecision GeometryReport::family() const {
  return family_decision(tests, [](const TestReport& t) { return t.p; }, scene.alpha);
}

bool GeometryReport::rejected() const { return family().rejected; }

std::size_t GeometryReport::skipped() const {
  return static_cast<std::size_t>(std::count_if(tests.begin(), tests.end(), [](const TestReport& t) { return unresolved(t); }));
}

namespace {

// The design of a run, as analyse reads it: K spheres x M rotations (explicit) or n iid drops.
struct DesignView {
  bool expl = false;
  std::size_t n = 0, K = 0, M = 0;
  bool decisive = false;  ///< enough spheres to estimate the spread between them
};

DesignView design_view(const Scene& scene, const ContactSamples& s) {
  DesignView v;
  v.expl = s.mode == Mode::explicit_spheres;
  v.n = s.r_xy.size();
  v.K = v.expl ? scene.ensemble.spheres : v.n;
  v.M = v.expl ? v.n / v.K : 1;
  v.decisive = !v.expl || v.K >= kMinDecisiveSpheres;
  return v;
}

// Counts, core-contact probabilities and the runner-up gap.
void fill_counts(GeometryReport& r, const Scene& scene, const ContactSamples& s) {
  const auto& sp = scene.ensemble.sphere;
  r.samples = s.r_xy.size();
  r.core_contacts = s.core_contacts;
  r.core_probability = core_contact_probability(sp.asperities, sp.radius, sp.asperity_radius);
  r.core_probability_paper = core_contact_probability_paper(sp.asperities, sp.radius, sp.asperity_radius);
  r.index_bytes = s.index_bytes;
  r.cross_check = s.cross_check;
  r.statistics = s.mode == Mode::explicit_spheres
                     ? "raw samples, KS of all drops on a grid of pooled quantiles with a sphere-block bootstrap"
                     : "raw samples, exact KS";
  std::vector<double> g = s.gap;
  const auto q = quantiles_unsorted(g, std::vector<double>{0.0, 0.5});
  r.gap_min = q[0];
  r.gap_median = q[1];
}

// The design and its error budget.
GeometryReport::Design design_of(const Scene& scene, const ContactSamples& s, const DesignView& v) {
  const auto& sp = scene.ensemble.sphere;
  GeometryReport::Design d;
  d.kind = v.expl ? "explicit" : "sampled";
  d.spheres = v.K;
  d.rotations_per_sphere = v.M;
  d.backend = v.expl ? std::string(to_string(scene.ensemble.backend)) : std::string("none");
  const DesignScales sc = design_scales(s.mode, sp.asperities, v.K, v.n);
  d.statistical_scale = sc.statistical;
  d.quenched_scale = sc.quenched;
  d.model_error_scale = model_error_scale(sp.asperities, sp.radius);
  return d;
}

// What the ensemble is and what its tests can decide, in words (report.json ensemble_note).
std::string design_note(const GeometryReport& r, const Scene& scene, const DesignView& v) {
  const auto& sp = scene.ensemble.sphere;
  std::ostringstream note;
  if (v.expl) {
    note << "explicit geometry: " << v.K << " sphere(s) of " << sp.asperities << " asperities x " << v.M
         << " Haar-random rotations each; every contact found by a " << to_string(scene.ensemble.backend)
         << " spatial query. Rotations of one sphere sample that sphere's own (quenched) law, which differs from the "
            "ensemble law by a KS distance ~"
         << fmt(kQuenchedKs / std::sqrt(double(sp.asperities)), 3) << " per sphere; pooled over K spheres ~"
         << fmt(r.design.quenched_scale, 3) << ", against the statistical resolution ~" << fmt(r.design.statistical_scale, 3)
         << ". Standard errors come from the spread between spheres (batch means). ";
    if (v.K == 1)
      note << "One sphere: the drops describe that sphere's own law; no test decides (verdict not-decisive).";
    else if (!v.decisive)
      note << "Fewer than " << kMinDecisiveSpheres
           << " spheres: too few to estimate the spread between spheres; no test decides (verdict not-decisive).";
    else
      note << "Decisive tests: KS distance of all " << v.n
           << " drops on a grid of pooled-sample quantiles, p-value from a sphere-block bootstrap (resampling spheres).";
  } else {
    note << "sampled from the exact finite-N law of the lowest asperity -- no geometry: the two lowest asperities of "
            "each drop are drawn from the order statistics of the polar angle; no sphere is built. Drops are iid.";
  }
  return note.str();
}

// Summaries of every analysed quantity (batched by sphere when every drop has a value), and the
// restitution deficit of impact runs.
void summarise(GeometryReport& r, const Scene& scene, const ContactSamples& s, const DesignView& v) {
  std::vector<std::string> names;
  if (scene.contact_stats) names = {"r_xy", "r_x", "r_y", "r_z"};
  // Impact quantities are batched by sphere only when every drop impacted (no drop missing).
  const bool impact = scene.ensemble.impact.enabled && s.eps.size() >= 2;
  if (impact) names.insert(names.end(), {"eps", "omega_x_after"});
  for (const auto& q : names) {
    const auto& x = column(s, q);
    const bool batched = v.expl && x.size() == v.n && v.M >= 2;
    r.quantities.push_back({q, batched ? summarize_batches(x, v.K, kProbs) : summarize_iid(x, kProbs)});
  }
  if (impact) {
    std::vector<double> deficit(s.eps.size());
    for (std::size_t i = 0; i < deficit.size(); ++i) deficit[i] = s.eps_n[i] - s.eps[i];
    const bool batched = v.expl && deficit.size() == v.n && v.M >= 2;
    const Summary d = batched ? summarize_batches(deficit, v.K, kProbs) : summarize_iid(deficit, kProbs);
    r.eps_deficit = d.mean;
    double en = 0;
    for (double e : s.eps_n) en += e;
    r.eps_n_mean = en / double(s.eps_n.size());
  }
  r.no_impacts = s.no_impacts;
}

const std::string kPrintedNote = "as printed in the paper; reported for comparison, does not count toward the exit status";

// What the law tests of one run share.
struct TestContext {
  const Scene& scene;
  const ContactSamples& s;
  DesignView v;
  std::string statistic;  ///< of the law tests: "KS-sphere-bootstrap" (explicit) or "KS"
};

// A row of tests[] named by what it tests; the caller sets the rest by name.
TestReport test_row(const std::string& quantity, const std::string& law, const std::string& statistic, std::uint64_t n) {
  TestReport t;
  t.quantity = quantity;
  t.law = law;
  t.statistic = statistic;
  t.n = n;
  return t;
}

// A law the run could not test: verdict skipped, D, p and predicted_mean NaN.
TestReport skipped_test(const TestContext& c, const std::string& quantity, const std::string& law, bool decisive_law,
                        std::size_t count, const std::string& reason) {
  TestReport t = test_row(quantity, law, c.statistic, count);
  t.D = t.p = t.predicted_mean = kNaN;
  t.iid = !c.v.expl;
  t.decisive = decisive_law && c.v.decisive;
  t.verdict = Verdict::skipped;
  t.note = "not tested: " + reason;
  return t;
}

// The laws of `set` that can be evaluated (at x[0]), as (index, cdf); the others are skipped, with
// a note in the report.
std::vector<std::pair<std::size_t, Cdf>> evaluable_laws(GeometryReport& r, const TestContext& c, const LawSet& set,
                                                        const std::vector<double>& x) {
  std::vector<std::pair<std::size_t, Cdf>> out;
  for (std::size_t li = 0; li < set.laws.size(); ++li) {
    // Every cdf is evaluated at ~10^3 grid points only; a law that cannot be evaluated is skipped.
    try {
      (void)set.laws[li].cdf(x[0]);
      out.emplace_back(li, set.laws[li].cdf);
    } catch (const std::exception& ex) {
      r.ensemble_note += " Law " + set.laws[li].name + " not tested: it cannot be evaluated at these parameters (" +
                         ex.what() + ").";
      r.tests.push_back(skipped_test(c, set.quantity, set.laws[li].name, set.decisive[li], x.size(),
                                     std::string("cannot be evaluated at these parameters: ") + ex.what()));
    }
  }
  return out;
}

// The row of one law of the explicit design, from its block-bootstrap (or not-decisive) result.
TestReport explicit_test(const TestContext& c, const LawSet& set, std::size_t li, const BlockKsResult& res,
                         const BlockBins& bins, std::size_t count) {
  const Law& law = set.laws[li];
  const bool decisive_law = set.decisive[li];
  TestReport t = test_row(set.quantity, law.name, c.statistic, count);
  t.D = res.D, t.p = res.p, t.predicted_mean = law.mean;
  t.iid = false;
  t.decisive = decisive_law && c.v.decisive && res.verdict != Verdict::not_decisive;
  t.verdict = res.verdict;
  if (res.verdict == Verdict::not_decisive) {
    t.p = kolmogorov_pvalue(res.D, count);
    t.note = c.v.K == 1 ? "one sphere: that sphere's own law against the ensemble law; the p-value assumes iid drops "
                          "(they are not): decides nothing"
                        : "fewer than " + std::to_string(kMinDecisiveSpheres) +
                              " spheres: the p-value assumes iid drops (they are not): decides nothing";
  } else {
    t.note = "B = " + std::to_string(res.replicates) + " sphere-block bootstrap replicates over " +
             std::to_string(bins.blocks) + " blocks";
    if (res.verdict == Verdict::undecided) t.note += "; cannot decide at this B (smallest attainable p is not below alpha)";
    if (!decisive_law) t.note = kPrintedNote + "; " + t.note;
  }
  if (set.has_atom.size() > li && set.has_atom[li])
    t.note += "; includes core contacts as an atom of mass " + fmt(set.atom_mass, 3);
  return t;
}

bool any_atom(const LawSet& set) {
  return std::any_of(set.has_atom.begin(), set.has_atom.end(), [](bool b) { return b; });
}

// The sample of a set. Core contacts sit exactly at the atom of the corrected laws (eps = eps_n,
// Omega'_x = Omega_x up to rounding): snapped there so that the empirical cdf and the law's cdf
// step at the same point.
std::vector<double> snapped_column(const TestContext& c, const LawSet& set) {
  const auto& x0 = column(c.s, set.quantity);
  std::vector<double> x(x0.begin(), x0.end());
  if (any_atom(set) && c.s.eps_core.size() == x.size())
    for (std::size_t i = 0; i < x.size(); ++i)
      if (c.s.eps_core[i]) x[i] = set.atom;
  return x;
}

// A sample without spread, or a law that is an atom, is compared exactly (laws/atom.hpp): the KS
// and bootstrap tests have no null distribution there (every D* = 0 puts any D > 0 at the floor p).
// Overrides the row's statistic, D, p and verdict; `units`: independent units (drops or spheres).
void decide_degenerate(TestReport& t, const LawSet& set, std::size_t li, const std::vector<double>& x,
                       std::size_t units, double alpha) {
  const bool atom = li < set.has_atom.size() && set.has_atom[li];
  std::optional<AtomTest> a;
  try {
    a = exact_atom_test(x, set.laws[li].cdf, units, atom ? std::optional<double>(set.atom) : std::nullopt);
  } catch (const std::exception&) {
    return;  // the law cannot be evaluated there: the ordinary test's row stands
  }
  if (!a) return;
  t.note = a->note + " (" + t.statistic + " not used)";
  t.statistic = "exact-atom";
  t.D = a->D, t.p = a->p;
  t.verdict = verdict_at(a->p, alpha);
}

// Explicit design: the binned KS distance of all drops against each law; p from the sphere-block
// bootstrap when the design can decide. `stream` (the set's index) keeps the replicates apart.
void test_explicit(GeometryReport& r, const TestContext& c, const LawSet& set, std::size_t stream) {
  const std::vector<double> x = snapped_column(c, set);
  // The atom and the point just below it are grid edges: drops at the atom and drops just off it
  // (eps < eps_n) fall in different cells even when every pooled quantile is the atom.
  const std::vector<double> extra =
      any_atom(set) ? std::vector<double>{std::nextafter(set.atom, -kInf), set.atom} : std::vector<double>{};
  const BlockBins bins = bin_by_block(x, x.size() == c.v.n ? c.v.K : 1, kKsGrid, kMaxBlocks, extra);
  // Each law on every grid edge first, alone: a law that cannot be evaluated there is skipped by
  // itself. Tested together, one law's NaN (Eq. 28 as printed where its raw integral crosses zero,
  // e.g. Omega_x = 1 rad/s on fig4's sphere; an info law) would skip the whole set, the decisive
  // eq28-corrected with it (issue 33 item 6).
  std::vector<std::pair<std::size_t, Cdf>> laws;
  for (auto& [li, cdf] : evaluable_laws(r, c, set, x)) {
    try {
      (void)binned_ks_distance(bins, cdf);
      laws.emplace_back(li, std::move(cdf));
    } catch (const std::exception& ex) {
      r.tests.push_back(skipped_test(c, set.quantity, set.laws[li].name, set.decisive[li], x.size(),
                                     std::string("cannot be evaluated at these parameters: ") + ex.what()));
    }
  }
  if (laws.empty()) return;
  std::vector<Cdf> cdfs;
  for (const auto& [li, cdf] : laws) cdfs.push_back(cdf);
  std::vector<BlockKsResult> res;
  try {
    if (c.v.decisive && x.size() == c.v.n) {
      std::vector<double> resolve;  // decisive laws: fine enough for Holm; printed laws as before
      for (const auto& [li, cdf] : laws) resolve.push_back(set.decisive[li] ? c.scene.alpha / kFamilyResolve : c.scene.alpha);
      res = block_ks_tests(bins, cdfs, c.scene.alpha, c.scene.ensemble.seed, stream, 199, 9999, resolve);
    } else {
      for (const auto& f : cdfs) res.push_back({binned_ks_distance(bins, f), kNaN, 0, Verdict::not_decisive});
    }
  } catch (const std::exception& ex) {
    for (const auto& [li, cdf] : laws)
      r.tests.push_back(skipped_test(c, set.quantity, set.laws[li].name, set.decisive[li], x.size(),
                                     std::string("cannot be evaluated at these parameters: ") + ex.what()));
    return;
  }
  for (std::size_t j = 0; j < laws.size(); ++j) {
    r.tests.push_back(explicit_test(c, set, laws[j].first, res[j], bins, x.size()));
    if (res[j].verdict != Verdict::not_decisive)
      decide_degenerate(r.tests.back(), set, laws[j].first, x, c.v.K, c.scene.alpha);
  }
}

// Sampled design: iid drops, the exact one-sample KS test (randomised PIT at a law's atom).
void test_sampled(GeometryReport& r, const TestContext& c, const LawSet& set) {
  const auto& x0 = column(c.s, set.quantity);
  const auto all = sorted(x0);
  const std::vector<double> x = snapped_column(c, set);
  for (std::size_t li = 0; li < set.laws.size(); ++li) {
    const Law& law = set.laws[li];
    const bool decisive_law = set.decisive[li];
    TestReport t = test_row(set.quantity, law.name, "KS", x0.size());
    t.D = 0, t.p = 1, t.predicted_mean = law.mean;
    t.iid = true;
    t.decisive = decisive_law;
    if (!decisive_law) t.note = kPrintedNote;
    const bool atom = li < set.has_atom.size() && set.has_atom[li];
    KsResult ks;
    try {
      ks = atom ? ks_mixed(x0, c.s.eps_core, law, set.atom, set.atom_mass, c.scene.ensemble.seed)
                : ks_one_sample(all, law.cdf);
    } catch (const std::exception& ex) {
      r.ensemble_note += " Law " + law.name + " not tested: it cannot be evaluated at these parameters (" +
                         ex.what() + ").";
      r.tests.push_back(skipped_test(c, set.quantity, law.name, decisive_law, x0.size(),
                                     std::string("cannot be evaluated at these parameters: ") + ex.what()));
      continue;
    }
    if (atom) t.note = "includes core contacts as an atom of mass " + fmt(set.atom_mass, 3) + " (randomised PIT)";
    t.D = ks.D, t.p = ks.p;
    t.verdict = ks.p < c.scene.alpha ? Verdict::reject : Verdict::accept;
    decide_degenerate(t, set, li, x, x.size(), c.scene.alpha);
    r.tests.push_back(t);
  }
}

// Every law of the requested outputs against its sample; laws that could not be tested are listed.
void test_laws(GeometryReport& r, const TestContext& c) {
  std::string law_note;
  const bool impact_laws = c.s.no_impacts == 0 && c.s.eps.size() == c.v.n;
  std::vector<SkippedLaw> skipped;
  const auto law_sets = laws_for(c.scene.ensemble, c.scene.contact_stats, impact_laws, law_note, &skipped);
  r.ensemble_note += law_note;
  for (std::size_t si = 0; si < law_sets.size(); ++si) {
    if (column(c.s, law_sets[si].quantity).empty()) continue;
    if (c.v.expl) test_explicit(r, c, law_sets[si], si);
    else test_sampled(r, c, law_sets[si]);
  }
  for (const auto& l : skipped)
    r.tests.push_back(skipped_test(c, l.quantity, l.law, l.decisive, column(c.s, l.quantity).size(), l.reason));
}

// Core contacts: binomial(drops, P_core) for iid drops; two-sided exact p-value. In the explicit
// design the count of one sphere is overdispersed (its own core probability): information only.
TestReport core_contact_test(const GeometryReport& r, const Scene& scene, const ContactSamples& s, const DesignView& v) {
  const std::size_t n = v.n;
  TestReport t = test_row("core_contacts", "exact-sphere", "binomial", n);
  t.D = kNaN, t.p = 1, t.predicted_mean = r.core_probability * double(n);
  t.iid = !v.expl;
  t.decisive = !v.expl;
  boost::math::binomial_distribution<double> b(double(n), r.core_probability);
  const double k = double(s.core_contacts);
  const double lower = boost::math::cdf(b, k);
  const double upper = k > 0 ? boost::math::cdf(boost::math::complement(b, k - 1)) : 1.0;
  t.p = std::min(1.0, 2.0 * std::min(lower, upper));
  t.verdict = t.p < scene.alpha ? Verdict::reject : Verdict::accept;
  t.note = "central sphere touched first; the paper's estimate exp(-N a/R) = " + fmt(r.core_probability_paper, 3) +
           " per drop, exact (1 - a/2R)^N = " + fmt(r.core_probability, 3);
  if (v.expl) t.note += "; iid binomial p-value, the spread between spheres is not accounted for: information only";
  return t;
}

}  // namespace

GeometryReport analyse(const Scene& scene, const ContactSamples& s) {
  GeometryReport r;
  r.scene = scene;
  const DesignView v = design_view(scene, s);
  fill_counts(r, scene, s);
  r.design = design_of(scene, s, v);
  if (v.expl) r.quenched_scale = quenched_deviation_scale(scene.ensemble.sphere.asperities);
  r.ensemble_note = design_note(r, scene, v);
  summarise(r, scene, s, v);
  test_laws(r, TestContext{scene, s, v, v.expl ? "KS-sphere-bootstrap" : "KS"});
  if (scene.contact_stats) r.tests.push_back(core_contact_test(r, scene, s, v));
  r.timings_s = {{"generate", s.seconds_generate}, {"index", s.seconds_index}, {"query", s.seconds_query}};
  if (scene.ensemble.impact.enabled) r.timings_s.emplace_back("impact", s.seconds_impact);
  if (v.expl) r.timings_s.emplace_back("cross_check", s.cross_check.seconds);
  return r;
}

namespace {
std::string design_label(const std::string& kind, std::uint64_t spheres, std::uint64_t rotations, const std::string& backend) {
  if (kind == "sampled") return "sampled from the exact finite-N law -- no geometry";
  return "explicit geometry: " + std::to_string(spheres) + (spheres == 1 ? " sphere x " : " spheres x ") +
         std::to_string(rotations) + " rotations, " + backend + " query";
}
std::string design_label(const GeometryReport& r) {
  const auto& d = r.design;
  return design_label(d.kind, d.spheres, d.rotations_per_sphere, d.backend);
}

// What the verdict line adds: the family, its level and its smallest adjusted p, and the decisive
// tests below alpha on their own that the family does not reject.
std::string family_line(const std::vector<TestReport>& tests, const FamilyDecision& f) {
  std::ostringstream os;
  os << " by the family of " << f.tests << " decided decisive test" << (f.tests == 1 ? "" : "s")
     << " (Holm, alpha = " << f.alpha << ", smallest adjusted p = " << fmt(f.min_adjusted_p, 3) << ")";
  std::size_t alone = 0;
  for (std::size_t i = 0; i < tests.size(); ++i) alone += rejects(tests[i]) && !f.reject[i];
  if (alone > 0)
    os << "; " << alone << " decisive test" << (alone == 1 ? "" : "s")
       << " below alpha on its own, not rejected by the family";
  return os.str();
}

}  // namespace

std::string format_table(const GeometryReport& r) {
  std::ostringstream os;
  const auto& sp = r.scene.ensemble.sphere;
  os << "validate-geometry: scene " << r.scene.name << ", " << design_label(r) << ", N = " << sp.asperities
     << ", R = " << sp.radius << " m, a = " << sp.asperity_radius << " m, " << r.samples << " drops, seed "
     << r.scene.ensemble.seed << "\n";
  os << "lengths in micrometres, omega in rad/s; KS = one-sample Kolmogorov-Smirnov (iid), KS-sphere-bootstrap = KS of "
        "all drops with a sphere-block bootstrap p, alpha = "
     << r.scene.alpha << " per test; the exit status is the family's: Holm's step-down over the decided decisive tests "
        "(Holm p, family)\n\n";
  os << std::left << std::setw(14) << "quantity" << std::setw(24) << "measured mean +- se" << std::setw(18) << "law"
     << std::setw(12) << "law mean" << std::setw(21) << "test" << std::setw(10) << "KS D" << std::setw(11) << "p"
     << std::setw(11) << "Holm p" << std::setw(8) << "family" << "verdict\n";
  os << std::string(136, '-') << "\n";
  const FamilyDecision family = r.family();
  for (std::size_t i = 0; i < r.tests.size(); ++i) {
    const auto& t = r.tests[i];
    std::string measured = "-";
    const double scale = display_scale(t.quantity);
    if (t.quantity == "core_contacts") {
      measured = std::to_string(r.core_contacts);
    } else {
      const int digits = t.quantity == "eps" ? 8 : 5;
      for (const auto& q : r.quantities)
        if (q.name == t.quantity)
          measured = fmt(q.summary.mean.value * scale, digits) + " +- " + fmt(q.summary.mean.se * scale, 2);
    }
    std::string verdict(to_string(t.verdict));
    if (!t.decisive) verdict += " (info)";
    os << std::left << std::setw(14) << t.quantity << std::setw(24) << measured << std::setw(18) << t.law
       << std::setw(12) << fmt(t.predicted_mean * scale, t.quantity == "eps" ? 8 : 5) << std::setw(21) << t.statistic << std::setw(10) << fmt(t.D, 3)
       << std::setw(11) << fmt(t.p, 3) << std::setw(11) << fmt(family.adjusted_p[i], 3) << std::setw(8)
       << (std::isnan(family.adjusted_p[i]) ? "-" : family.reject[i] ? "reject" : "accept") << verdict << "\n";
  }
  os << "\ncore contacts: " << r.core_contacts << " of " << r.samples << " drops (expected "
     << fmt(r.core_probability * double(r.samples), 4) << "; paper's estimate per drop " << fmt(r.core_probability_paper, 3)
     << ")\n";
  if (r.scene.ensemble.impact.enabled) {
    const auto& x = r.scene.ensemble.impact;
    os << "impact: u = " << x.speed << " m/s, Omega = (" << x.omega.x() << ", " << x.omega.y() << ", " << x.omega.z() << ") rad/s, ";
    if (x.tangential.model == TangentialLaw::Model::kinematic) os << "eps_t = " << x.eps_t;
    else os << "tangential law " << x.tangential.describe();
    os << ", Pade [1/4] beta = " << x.beta << "; mean eps_n = " << fmt(r.eps_n_mean, 8)
       << ", deficit eps_n - <eps> = " << fmt(r.eps_deficit.value, 4) << " +- " << fmt(r.eps_deficit.se, 2)
       << "; drops without impact: " << r.no_impacts << "\n";
  }
  os << "runner-up gap: min " << fmt(r.gap_min * 1e9, 4) << " nm, median " << fmt(r.gap_median * 1e9, 4) << " nm\n";
  {
    const auto& d = r.design;
    os << "design: " << design_label(r);
    if (d.kind == "explicit") {
      os << "; cross-check: " << r.cross_check.queries << " queries re-answered by ";
      for (std::size_t i = 0; i < r.cross_check.backends.size(); ++i) os << (i ? ", " : "") << r.cross_check.backends[i];
      os << ", " << r.cross_check.agreed << " agree";
    }
    if (!r.statistics.empty()) os << "\nstatistics: " << r.statistics;
    os << "\nerror scales (KS distance): statistical " << fmt(d.statistical_scale, 3) << ", quenched "
       << fmt(d.quenched_scale, 3) << ", model error (Eq. 14 vs exact finite-N law) " << fmt(d.model_error_scale, 3) << "\n";
  }
  os << r.ensemble_note << "\n";
  os << "verdict: " << (family.rejected ? "a law was REJECTED" : "no law rejected") << family_line(r.tests, family);
  if (const std::size_t k = r.skipped(); k > 0)
    os << "; " << k << " decisive test" << (k == 1 ? "" : "s")
       << " SKIPPED or UNDECIDED (could not be evaluated or decided, see the notes)";
  os << "\n";
  for (const auto& t : r.tests)  // the rows show the others
    if (unresolved(t))
      os << to_string(t.verdict) << ": " << t.quantity << " " << t.law << " (" << t.scope << "): " << t.note << "\n";
  return detail::checked_text(std::move(os), "report.txt");
}

namespace {

nlohmann::json impact_json(const ImpactExperiment& x) {
  return {{"speed_m_s", x.speed},
          {"omega_rad_s", {x.omega.x(), x.omega.y(), x.omega.z()}},
          {"density_kg_m3", x.density},
          {"beta", x.beta},
          {"eps_t", x.eps_t},
          {"tangential", [&] {
             TangentialLaw law = x.tangential;
             if (law.model == TangentialLaw::Model::kinematic) law.eps_t = x.eps_t;
             return law.describe();
           }()},
          {"restitution_model", "viscoelastic-pade14"},
          {"solver", x.tangential.model == TangentialLaw::Model::kinematic
                         ? "closed form (Sherman-Morrison), tested against the general 3x3 solve"
                         : "impulse process of the tangential law (core/tangential.hpp solve_impact)"}};
}

nlohmann::json design_json(const GeometryReport& r) {
  const auto& d = r.design;
  return {{"kind", d.kind},
          {"label", design_label(r)},
          {"spheres", d.spheres},
          {"rotations_per_sphere", d.rotations_per_sphere},
          {"backend", d.backend},
          {"statistical_scale", d.statistical_scale},
          {"quenched_scale", d.quenched_scale},
          {"model_error_scale", d.model_error_scale}};
}

nlohmann::json quantities_json(const std::vector<QuantityReport>& quantities) {
  using nlohmann::json;
  json q = json::object();
  for (const auto& qr : quantities) {
    const auto& s = qr.summary;
    json qs = json::array();
    for (std::size_t i = 0; i < s.probs.size(); ++i)
      qs.push_back({{"p", s.probs[i]}, {"value", s.quantiles[i].value}, {"se", s.quantiles[i].se}});
    q[qr.name] = {{"unit", si_unit(qr.name)},     {"n", s.n},       {"mean", s.mean.value}, {"mean_se", s.mean.se},
                  {"std", s.std.value}, {"std_se", s.std.se}, {"quantiles", qs},   {"se_batches", s.batches}};
  }
  return q;
}

nlohmann::json tests_json(const std::vector<TestReport>& rows, const FamilyDecision& family) {
  using nlohmann::json;
  json tests = json::array();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& t = rows[i];
    const double adj = family.adjusted_p[i];
    tests.push_back({{"quantity", t.quantity},
                     {"law", t.law},
                     {"scope", t.scope},
                     {"statistic", t.statistic},
                     {"D", std::isnan(t.D) ? json(nullptr) : json(t.D)},
                     {"p", std::isnan(t.p) ? json(nullptr) : json(t.p)},
                     {"n", t.n},
                     {"predicted_mean", t.predicted_mean},
                     {"iid", t.iid},
                     {"decisive", t.decisive},
                     {"verdict", std::string(to_string(t.verdict))},
                     {"note", t.note},
                     {"adjusted_p", std::isnan(adj) ? json(nullptr) : json(adj)},
                     {"family_reject", bool(family.reject[i])}});
  }
  return tests;
}

}  // namespace

std::string family_json(const FamilyDecision& f, const std::vector<std::string>& names) {
  using nlohmann::json;
  json adjusted = json::object();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (!std::isnan(f.adjusted_p[i])) {
      std::string key = names[i];
      for (int k = 2; adjusted.contains(key); ++k) key = names[i] + " #" + std::to_string(k);
      adjusted[key] = f.adjusted_p[i];
    }
  const json j = {{"procedure", "holm"},
                  {"alpha", f.alpha},
                  {"tests", f.tests},
                  {"rejected", f.rejected},
                  {"min_adjusted_p", std::isnan(f.min_adjusted_p) ? json(nullptr) : json(f.min_adjusted_p)},
                  {"adjusted_p", adjusted},
                  {"members", "decisive tests with verdict accept or reject (not-decisive, skipped and undecided "
                              "ones are not in the family); valid under any dependence between them"}};
  return j.dump();
}

namespace {

std::vector<std::string> test_names(const std::vector<TestReport>& rows) {
  std::vector<std::string> names;
  for (const auto& t : rows) names.push_back(t.quantity + " " + t.law + " (" + t.statistic + ")");
  return names;
}

}  // namespace

std::string to_json(const GeometryReport& r) {
  using nlohmann::json;
  const auto& e = r.scene.ensemble;
  json j;
  j["schema_version"] = kReportSchemaVersion;
  j["tool"] = "validate-geometry";
  j["tool_version"] = ASPERITY_VERSION;
  j["scene"] = r.scene.name;
  j["mode"] = std::string(to_string(e.mode));
  j["samples"] = r.samples;
  j["core_contacts"] = r.core_contacts;
  j["core_contact_probability"] = {{"exact", r.core_probability}, {"paper", r.core_probability_paper}};
  j["parameters"] = {{"asperities", e.sphere.asperities},
                     {"radius_m", e.sphere.radius},
                     {"asperity_radius_m", e.sphere.asperity_radius},
                     {"drops", e.drops},
                     {"spheres", e.mode == Mode::explicit_spheres ? e.spheres : e.drops},
                     {"rotations_per_sphere", e.mode == Mode::explicit_spheres ? e.drops / e.spheres : 1},
                     {"seed", e.seed},
                     {"backend", e.mode == Mode::explicit_spheres ? std::string(to_string(e.backend)) : std::string("none")},
                     {"alpha", r.scene.alpha}};
  if (e.impact.enabled) {
    j["impact"] = impact_json(e.impact);
    j["no_impacts"] = r.no_impacts;
    j["eps_n_mean"] = r.eps_n_mean;
    j["eps_deficit"] = {{"value", r.eps_deficit.value}, {"se", r.eps_deficit.se}};
  }
  j["ensemble_note"] = r.ensemble_note;
  if (!r.statistics.empty()) j["statistics"] = r.statistics;
  if (e.mode == Mode::explicit_spheres) j["quenched_deviation_scale"] = r.quenched_scale;
  j["design"] = design_json(r);
  if (r.design.kind == "explicit")
    j["cross_check"] = {{"queries", r.cross_check.queries},
                        {"agreed", r.cross_check.agreed},
                        {"backends", r.cross_check.backends}};
  j["runner_up_gap_m"] = {{"min", r.gap_min}, {"median", r.gap_median}};
  j["quantities"] = quantities_json(r.quantities);
  const FamilyDecision family = r.family();
  j["tests"] = tests_json(r.tests, family);
  j["rejected"] = family.rejected;  // the family's decision (Holm), the exit status
  j["family"] = json::parse(family_json(family, test_names(r.tests)));
  j["skipped"] = r.skipped();
  j["timings_s"] = timings_json(r.timings_s);
  if (r.index_bytes) j["index_bytes_per_asperity"] = double(r.index_bytes) / double(e.sphere.asperities);
  j["plots"] = image_files(r.plots);
  j["plot_data"] = data_files(r.plots);
  if (!r.plan.empty()) j["plan"] = plan_json(r.plan);
  if (!r.scene_toml.empty()) j["scene_file"] = r.scene_toml;
  return j.dump(2) + "\n";
}


std::string with_header(const std::string& body, const ReportHeader& h) {
  using nlohmann::json;
  json j = json::parse(body);
  if (!j.is_object()) throw std::invalid_argument("with_header: the report body must be a JSON object");
  j["schema_version"] = kReportSchemaVersion;
  j["tool"] = h.tool;
  j["tool_version"] = ASPERITY_VERSION;
  j["scene"] = h.scene;
  if (!h.scene_toml.empty()) j["scene_file"] = h.scene_toml;
  if (!h.plan.empty()) j["plan"] = plan_json(h.plan);
  if (!h.timings_s.empty()) j["timings_s"] = timings_json(h.timings_s);
  for (const auto& [name, text] : h.sections) j[name] = json::parse(text);
  return j.dump(2) + "\n";
}

std::vector<std::filesystem::path> write_report_files(const std::filesystem::path& dir, const std::string& report_name,
                                                      const std::string& json, const std::string& table) {
  const std::filesystem::path report = dir / report_name;
  std::filesystem::path txt = report;
  txt.replace_extension(".txt");
  if (txt == report) txt += ".txt";  // a report named "x.txt" keeps its table apart
  write_file_atomic(report, json);
  try {
    write_file_atomic(txt, table);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(report, ec);
    throw;
  }
  return {report, txt};
}

std::vector<std::string> write_plots(const std::filesystem::path& dir, const Scene& scene, const ContactSamples& s) {
  std::vector<NamedFigure> figures;
  std::map<std::string, Curve> curves;
  const auto& sp = scene.ensemble.sphere;
  const double sigma = 1.0 / std::sqrt(2.0 * std::numbers::pi * areal_density(sp.asperities, sp.radius));
  std::ostringstream sub;
  const bool expl = scene.ensemble.mode == Mode::explicit_spheres;
  const std::uint64_t K = expl ? scene.ensemble.spheres : s.r_xy.size();
  sub << "N = " << sp.asperities << ", ρ = " << sp.asperity_radius << " m";
  // The legend of the measured points names the ensemble they come from.
  const std::string data_label =
      expl ? "explicit geometry: " + std::to_string(K) + (K == 1 ? " sphere x " : " spheres x ") +
                 std::to_string(s.r_xy.size() / K) + " rotations, " + std::string(to_string(scene.ensemble.backend)) +
                 " query"
           : std::string("sampled from the exact finite-N law, no geometry");
  std::string law_note;  // the report says why a law is missing
  for (const auto& set : laws_for(scene.ensemble, scene.contact_stats,
                                  s.no_impacts == 0 && s.eps.size() == s.r_xy.size(), law_note)) {
    const auto& x = column(s, set.quantity);
    if (x.empty()) continue;
    HistogramFigure fig;
    double lo, hi;
    if (set.quantity.rfind("r_", 0) == 0) {
      const bool radial = set.quantity == "r_xy";
      hi = std::min(sp.radius, (radial ? 4.5 : 4.0) * sigma);
      lo = radial ? 0.0 : -hi;
      const std::string sym = radial ? "r_{xy}" : (set.quantity == "r_x" ? "r_x" : "r_y");
      fig.title = sym + " of the contact vector: " + sub.str();
      fig.xlabel = sym + " [µm]";
      fig.x_scale = 1e6;
      fig.y_scale = 1e-6;
      fig.ylabel = "probability density [1/µm]";
    } else {
      // Range from the data: the bulk plus the tails the log panel shows.
      std::vector<double> v(x.begin(), x.end());
      const auto q = quantiles_unsorted(v, std::vector<double>{1e-4, 1.0 - 1e-5});
      lo = q[0], hi = q[1];
      const double pad = 0.05 * (hi - lo);
      lo -= pad, hi += pad;
      if (!(hi > lo)) lo -= 1e-12, hi += 1e-12;
      const bool eps = set.quantity == "eps";
      fig.title = (eps ? std::string("ε") : std::string("Ω'_x")) + ": " + sub.str();
      fig.xlabel = eps ? "ε" : "Ω'_x [rad/s]";
      fig.ylabel = eps ? "probability density" : "probability density [s/rad]";
    }
    fig.histogram = make_histogram(x, lo, hi, 60);
    fig.data_label = data_label;
    for (const auto& law : set.laws) {
      const std::string label = legend_label(law.name);
      // r_x and r_y have the same laws on the same range: their curves are computed once (the exact
      // r_x density is a quadrature per point).
      const std::string key = (set.quantity == "r_y" ? std::string("r_x") : set.quantity) + "/" + law.name;
      auto it = curves.find(key);
      if (it == curves.end()) {
        // The exact r_x density is a quadrature per point (~9 ms each on a loaded core); its cdf is
        // tabulated (pchip). The figure draws the cdf's central difference, h = (hi - lo)/4000,
        // which agrees with the density to ~1e-6 relative: invisible in a figure.
        const bool tabulated = set.quantity != "r_xy" && set.quantity.rfind("r_", 0) == 0 && law.name == "exact-sphere";
        const double h = (hi - lo) / 4000;
        const Cdf cdf = law.cdf;
        const std::function<double(double)> f =
            tabulated ? std::function<double(double)>([cdf, h](double t) { return (cdf(t + h) - cdf(t - h)) / (2 * h); })
                      : law.pdf;
        it = curves.emplace(key, sampled_curve(f, label, lo, hi, 200)).first;
      }
      fig.curves.push_back(it->second);
    }
    figures.push_back({set.quantity + ".png", std::move(fig)});
  }
  return write_figures(dir, figures, parse_plot_formats(scene.plot_format));
}

}  // namespace asperity
