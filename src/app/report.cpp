#include "asperity/app/report.hpp"

#include "asperity/app/atomic_file.hpp"

#include <boost/math/distributions/binomial.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
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
#include "asperity/core/random.hpp"
#include "asperity/laws/block_ks.hpp"
#include "asperity/laws/theory.hpp"
#include "asperity/laws/theory_impact.hpp"

namespace asperity {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const std::vector<double> kProbs{0.01, 0.05, 0.25, 0.5, 0.75, 0.95, 0.99};
// The grid of the explicit design's binned KS statistic (points at pooled-sample quantiles: the
// binned D is at most ~1/kKsGrid below the full one) and the most blocks its bootstrap resamples
// (groups of whole spheres beyond that: a replicate costs O(blocks x grid)).
constexpr std::size_t kKsGrid = 1024;
constexpr std::size_t kMaxBlocks = 256;

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

bool GeometryReport::rejected() const {
  return std::any_of(tests.begin(), tests.end(), [](const TestReport& t) { return t.decisive && t.verdict == "reject"; });
}

std::size_t GeometryReport::skipped() const {
  return static_cast<std::size_t>(
      std::count_if(tests.begin(), tests.end(), [](const TestReport& t) {
        return t.decisive && (t.verdict == "skipped" || t.verdict == "undecided");
      }));
}

GeometryReport analyse(const Scene& scene, const ContactSamples& s) {
  GeometryReport r;
  r.scene = scene;
  const auto& sp = scene.ensemble.sphere;
  const bool expl = s.mode == Mode::explicit_spheres;
  const std::size_t n = s.r_xy.size();
  r.samples = n;
  r.core_contacts = s.core_contacts;
  r.core_probability = core_contact_probability(sp.asperities, sp.radius, sp.asperity_radius);
  r.core_probability_paper = core_contact_probability_paper(sp.asperities, sp.radius, sp.asperity_radius);
  r.index_bytes = s.index_bytes;
  r.cross_check = s.cross_check;
  r.statistics = expl ? "raw samples, KS of all drops on a grid of pooled quantiles with a sphere-block bootstrap"
                      : "raw samples, exact KS";
  {
    std::vector<double> g = s.gap;
    const auto q = quantiles_unsorted(g, std::vector<double>{0.0, 0.5});
    r.gap_min = q[0];
    r.gap_median = q[1];
  }
  const std::size_t K = expl ? scene.ensemble.spheres : n, M = expl ? n / K : 1;
  const bool decisive_design = !expl || K >= kMinDecisiveSpheres;
  // The design and its error budget.
  {
    auto& d = r.design;
    d.kind = expl ? "explicit" : "sampled";
    d.spheres = K;
    d.rotations_per_sphere = M;
    d.backend = expl ? std::string(to_string(scene.ensemble.backend)) : std::string("none");
    const DesignScales sc = design_scales(s.mode, sp.asperities, K, n);
    d.statistical_scale = sc.statistical;
    d.quenched_scale = sc.quenched;
    d.model_error_scale = model_error_scale(sp.asperities, sp.radius);
  }
  std::ostringstream note;
  if (expl) {
    r.quenched_scale = quenched_deviation_scale(sp.asperities);
    note << "explicit geometry: " << K << " sphere(s) of " << sp.asperities << " asperities x " << M
         << " Haar-random rotations each; every contact found by a " << to_string(scene.ensemble.backend)
         << " spatial query. Rotations of one sphere sample that sphere's own (quenched) law, which differs from the "
            "ensemble law by a KS distance ~"
         << fmt(kQuenchedKs / std::sqrt(double(sp.asperities)), 3) << " per sphere; pooled over K spheres ~"
         << fmt(r.design.quenched_scale, 3) << ", against the statistical resolution ~" << fmt(r.design.statistical_scale, 3)
         << ". Standard errors come from the spread between spheres (batch means). ";
    if (K == 1)
      note << "One sphere: the drops describe that sphere's own law; no test decides (verdict not-decisive).";
    else if (!decisive_design)
      note << "Fewer than " << kMinDecisiveSpheres
           << " spheres: too few to estimate the spread between spheres; no test decides (verdict not-decisive).";
    else
      note << "Decisive tests: KS distance of all " << n
           << " drops on a grid of pooled-sample quantiles, p-value from a sphere-block bootstrap (resampling spheres).";
  } else {
    note << "sampled from the exact finite-N law of the lowest asperity -- no geometry: the two lowest asperities of "
            "each drop are drawn from the order statistics of the polar angle; no sphere is built. Drops are iid.";
  }
  if (!scene.legacy_mode.empty()) note << " " << legacy_mode_note(scene.legacy_mode);
  r.ensemble_note = note.str();

  std::vector<std::string> names;
  if (scene.contact_stats) names = {"r_xy", "r_x", "r_y", "r_z"};
  // Impact quantities are batched by sphere only when every drop impacted (no drop missing).
  const bool impact = scene.ensemble.impact.enabled && s.eps.size() >= 2;
  if (impact) names.insert(names.end(), {"eps", "omega_x_after"});
  for (const auto& q : names) {
    const auto& x = column(s, q);
    const bool batched = expl && x.size() == n && M >= 2;
    r.quantities.push_back({q, batched ? summarize_batches(x, K, kProbs) : summarize_iid(x, kProbs)});
  }
  if (impact) {
    std::vector<double> deficit(s.eps.size());
    for (std::size_t i = 0; i < deficit.size(); ++i) deficit[i] = s.eps_n[i] - s.eps[i];
    const bool batched = expl && deficit.size() == n && M >= 2;
    const Summary d = batched ? summarize_batches(deficit, K, kProbs) : summarize_iid(deficit, kProbs);
    r.eps_deficit = d.mean;
    double en = 0;
    for (double e : s.eps_n) en += e;
    r.eps_n_mean = en / double(s.eps_n.size());
  }
  r.no_impacts = s.no_impacts;

  std::string law_note;
  const bool impact_laws = s.no_impacts == 0 && s.eps.size() == n;
  std::vector<SkippedLaw> skipped;
  const auto law_sets = laws_for(scene.ensemble, scene.contact_stats, impact_laws, law_note, &skipped);
  r.ensemble_note += law_note;
  const std::string statistic = expl ? "KS-sphere-bootstrap" : "KS";
  const auto skip = [&](const std::string& quantity, const std::string& law, bool decisive_law, std::size_t count,
                        const std::string& reason) {
    r.tests.push_back({quantity, law, "all", statistic, kNaN, kNaN, count, kNaN, !expl, decisive_law && decisive_design,
                       "skipped", "not tested: " + reason});
  };
  const std::string printed_note = "as printed in the paper; reported for comparison, does not count toward the exit status";
  for (std::size_t si = 0; si < law_sets.size(); ++si) {
    const auto& set = law_sets[si];
    const auto& x0 = column(s, set.quantity);
    if (x0.empty()) continue;
    const bool any_atom = std::any_of(set.has_atom.begin(), set.has_atom.end(), [](bool b) { return b; });
    if (expl) {
      // Core contacts sit exactly at the atom of the corrected laws (eps = eps_n, Omega'_x = Omega_x up to
      // rounding): snap them so that the empirical cdf and the law's cdf step at the same point.
      std::vector<double> x(x0.begin(), x0.end());
      if (any_atom && s.eps_core.size() == x.size())
        for (std::size_t i = 0; i < x.size(); ++i)
          if (s.eps_core[i]) x[i] = set.atom;
      const std::vector<double> extra = any_atom ? std::vector<double>{set.atom} : std::vector<double>{};
      std::vector<Cdf> cdfs;
      std::vector<std::size_t> which;
      for (std::size_t li = 0; li < set.laws.size(); ++li) {
        // Every cdf is evaluated at ~10^3 grid points only; a law that cannot be evaluated is skipped.
        try {
          (void)set.laws[li].cdf(x[0]);
          cdfs.push_back(set.laws[li].cdf);
          which.push_back(li);
        } catch (const std::exception& ex) {
          r.ensemble_note += " Law " + set.laws[li].name + " not tested: it cannot be evaluated at these parameters (" +
                             ex.what() + ").";
          skip(set.quantity, set.laws[li].name, set.decisive[li], x.size(),
               std::string("cannot be evaluated at these parameters: ") + ex.what());
        }
      }
      if (cdfs.empty()) continue;
      const BlockBins bins = bin_by_block(x, x.size() == n ? K : 1, kKsGrid, kMaxBlocks, extra);
      std::vector<BlockKsResult> res;
      std::vector<double> dist;
      try {
        if (decisive_design && x.size() == n) {
          res = block_ks_tests(bins, cdfs, scene.alpha, scene.ensemble.seed, si);
        } else {
          for (const auto& f : cdfs) res.push_back({binned_ks_distance(bins, f), kNaN, 0, "not-decisive"});
        }
      } catch (const std::exception& ex) {
        for (std::size_t j = 0; j < which.size(); ++j)
          skip(set.quantity, set.laws[which[j]].name, set.decisive[which[j]], x.size(),
               std::string("cannot be evaluated at these parameters: ") + ex.what());
        continue;
      }
      for (std::size_t j = 0; j < which.size(); ++j) {
        const Law& law = set.laws[which[j]];
        const bool decisive_law = set.decisive[which[j]];
        TestReport t{set.quantity, law.name, "all", statistic, res[j].D, res[j].p, x.size(), law.mean, false,
                     decisive_law && decisive_design && res[j].verdict != "not-decisive", res[j].verdict, ""};
        if (res[j].verdict == "not-decisive") {
          t.p = kolmogorov_pvalue(res[j].D, x.size());
          t.note = K == 1 ? "one sphere: that sphere's own law against the ensemble law; the p-value assumes iid drops "
                            "(they are not): decides nothing"
                          : "fewer than " + std::to_string(kMinDecisiveSpheres) +
                                " spheres: the p-value assumes iid drops (they are not): decides nothing";
        } else {
          t.note = "B = " + std::to_string(res[j].replicates) + " sphere-block bootstrap replicates over " +
                   std::to_string(bins.blocks) + " blocks";
          if (res[j].verdict == "undecided") t.note += "; cannot decide at this B (smallest attainable p is not below alpha)";
          if (!decisive_law) t.note = printed_note + "; " + t.note;
        }
        if (set.has_atom.size() > which[j] && set.has_atom[which[j]])
          t.note += "; includes core contacts as an atom of mass " + fmt(set.atom_mass, 3);
        r.tests.push_back(t);
      }
      continue;
    }
    // Sampled: iid drops, the exact one-sample KS test.
    const auto all = sorted(x0);
    for (std::size_t li = 0; li < set.laws.size(); ++li) {
      const Law& law = set.laws[li];
      const bool decisive_law = set.decisive[li];
      TestReport t{set.quantity, law.name, "all", "KS", 0, 1, x0.size(), law.mean, true, decisive_law, "", ""};
      if (!decisive_law) t.note = printed_note;
      const bool atom = li < set.has_atom.size() && set.has_atom[li];
      KsResult ks;
      try {
        ks = atom ? ks_mixed(x0, s.eps_core, law, set.atom, set.atom_mass, scene.ensemble.seed)
                  : ks_one_sample(all, law.cdf);
      } catch (const std::exception& ex) {
        r.ensemble_note += " Law " + law.name + " not tested: it cannot be evaluated at these parameters (" +
                           ex.what() + ").";
        skip(set.quantity, law.name, decisive_law, x0.size(),
             std::string("cannot be evaluated at these parameters: ") + ex.what());
        continue;
      }
      if (atom) t.note = "includes core contacts as an atom of mass " + fmt(set.atom_mass, 3) + " (randomised PIT)";
      t.D = ks.D, t.p = ks.p;
      t.verdict = ks.p < scene.alpha ? "reject" : "accept";
      r.tests.push_back(t);
    }
  }

  for (const auto& l : skipped) skip(l.quantity, l.law, l.decisive, column(s, l.quantity).size(), l.reason);

  if (scene.contact_stats) {
    // Core contacts: binomial(drops, P_core) for iid drops; two-sided exact p-value. In the explicit
    // design the count of one sphere is overdispersed (its own core probability): information only.
    TestReport t{"core_contacts", "exact-sphere", "all", "binomial", kNaN, 1, n,
                 r.core_probability * double(n), !expl, !expl, "", ""};
    boost::math::binomial_distribution<double> b(double(n), r.core_probability);
    const double k = double(s.core_contacts);
    const double lower = boost::math::cdf(b, k);
    const double upper = k > 0 ? boost::math::cdf(boost::math::complement(b, k - 1)) : 1.0;
    t.p = std::min(1.0, 2.0 * std::min(lower, upper));
    t.verdict = t.p < scene.alpha ? "reject" : "accept";
    t.note = "central sphere touched first; the paper's estimate exp(-N a/R) = " + fmt(r.core_probability_paper, 3) +
             " per drop, exact (1 - a/2R)^N = " + fmt(r.core_probability, 3);
    if (expl) t.note += "; iid binomial p-value, the spread between spheres is not accounted for: information only";
    r.tests.push_back(t);
  }
  r.timings_s = {{"generate", s.seconds_generate}, {"index", s.seconds_index}, {"query", s.seconds_query}};
  if (scene.ensemble.impact.enabled) r.timings_s.emplace_back("impact", s.seconds_impact);
  if (expl) r.timings_s.emplace_back("cross_check", s.cross_check.seconds);
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
}  // namespace

std::string format_table(const GeometryReport& r) {
  std::ostringstream os;
  const auto& sp = r.scene.ensemble.sphere;
  os << "validate-geometry: scene " << r.scene.name << ", " << design_label(r) << ", N = " << sp.asperities
     << ", R = " << sp.radius << " m, a = " << sp.asperity_radius << " m, " << r.samples << " drops, seed "
     << r.scene.ensemble.seed << "\n";
  os << "lengths in micrometres, omega in rad/s; KS = one-sample Kolmogorov-Smirnov (iid), KS-sphere-bootstrap = KS of "
        "all drops with a sphere-block bootstrap p, alpha = "
     << r.scene.alpha << " per test\n\n";
  os << std::left << std::setw(14) << "quantity" << std::setw(24) << "measured mean +- se" << std::setw(18) << "law"
     << std::setw(12) << "law mean" << std::setw(21) << "test" << std::setw(10) << "KS D" << std::setw(11) << "p"
     << "verdict\n";
  os << std::string(117, '-') << "\n";
  for (const auto& t : r.tests) {
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
    std::string verdict = t.verdict;
    if (!t.decisive) verdict += " (info)";
    os << std::left << std::setw(14) << t.quantity << std::setw(24) << measured << std::setw(18) << t.law
       << std::setw(12) << fmt(t.predicted_mean * scale, t.quantity == "eps" ? 8 : 5) << std::setw(21) << t.statistic << std::setw(10) << fmt(t.D, 3)
       << std::setw(11) << fmt(t.p, 3) << verdict << "\n";
  }
  os << "\ncore contacts: " << r.core_contacts << " of " << r.samples << " drops (expected "
     << fmt(r.core_probability * double(r.samples), 4) << "; paper's estimate per drop " << fmt(r.core_probability_paper, 3)
     << ")\n";
  if (r.scene.ensemble.impact.enabled) {
    const auto& x = r.scene.ensemble.impact;
    os << "impact: u = " << x.speed << " m/s, Omega = (" << x.omega.x() << ", " << x.omega.y() << ", " << x.omega.z()
       << ") rad/s, eps_t = " << x.eps_t << ", Pade [1/4] beta = " << x.beta << "; mean eps_n = " << fmt(r.eps_n_mean, 8)
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
  os << "verdict: " << (r.rejected() ? "a law was REJECTED" : "no law rejected");
  if (const std::size_t k = r.skipped(); k > 0)
    os << "; " << k << " decisive test" << (k == 1 ? "" : "s")
       << " SKIPPED or UNDECIDED (could not be evaluated or decided, see the notes)";
  os << "\n";
  for (const auto& t : r.tests)  // the rows show the others
    if (t.decisive && (t.verdict == "skipped" || t.verdict == "undecided"))
      os << t.verdict << ": " << t.quantity << " " << t.law << " (" << t.scope << "): " << t.note << "\n";
  return os.str();
}

std::string to_json(const GeometryReport& r) {
  using nlohmann::json;
  const auto& e = r.scene.ensemble;
  json j;
  j["schema_version"] = kReportSchemaVersion;
  j["tool"] = "validate-geometry";
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
    const auto& x = e.impact;
    j["impact"] = {{"speed_m_s", x.speed},
                   {"omega_rad_s", {x.omega.x(), x.omega.y(), x.omega.z()}},
                   {"density_kg_m3", x.density},
                   {"beta", x.beta},
                   {"eps_t", x.eps_t},
                   {"restitution_model", "viscoelastic-pade14"},
                   {"solver", "closed form (Sherman-Morrison), tested against the general 3x3 solve"}};
    j["no_impacts"] = r.no_impacts;
    j["eps_n_mean"] = r.eps_n_mean;
    j["eps_deficit"] = {{"value", r.eps_deficit.value}, {"se", r.eps_deficit.se}};
  }
  j["ensemble_note"] = r.ensemble_note;
  if (!r.statistics.empty()) j["statistics"] = r.statistics;
  if (e.mode == Mode::explicit_spheres) j["quenched_deviation_scale"] = r.quenched_scale;
  {
    const auto& d = r.design;
    j["design"] = {{"kind", d.kind},
                   {"label", design_label(r)},
                   {"spheres", d.spheres},
                   {"rotations_per_sphere", d.rotations_per_sphere},
                   {"backend", d.backend},
                   {"statistical_scale", d.statistical_scale},
                   {"quenched_scale", d.quenched_scale},
                   {"model_error_scale", d.model_error_scale}};
    if (d.kind == "explicit")
      j["cross_check"] = {{"queries", r.cross_check.queries},
                          {"agreed", r.cross_check.agreed},
                          {"backends", r.cross_check.backends}};
  }
  j["runner_up_gap_m"] = {{"min", r.gap_min}, {"median", r.gap_median}};
  json q = json::object();
  for (const auto& qr : r.quantities) {
    const auto& s = qr.summary;
    json qs = json::array();
    for (std::size_t i = 0; i < s.probs.size(); ++i)
      qs.push_back({{"p", s.probs[i]}, {"value", s.quantiles[i].value}, {"se", s.quantiles[i].se}});
    q[qr.name] = {{"unit", si_unit(qr.name)},     {"n", s.n},       {"mean", s.mean.value}, {"mean_se", s.mean.se},
                  {"std", s.std.value}, {"std_se", s.std.se}, {"quantiles", qs},   {"se_batches", s.batches}};
  }
  j["quantities"] = q;
  json tests = json::array();
  for (const auto& t : r.tests) {
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
                     {"verdict", t.verdict},
                     {"note", t.note}});
  }
  j["tests"] = tests;
  j["rejected"] = r.rejected();
  j["skipped"] = r.skipped();
  j["timings_s"] = timings_json(r.timings_s);
  if (r.index_bytes) j["index_bytes_per_asperity"] = double(r.index_bytes) / double(e.sphere.asperities);
  j["plots"] = r.plots;
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
  j["scene"] = h.scene;
  if (!h.scene_toml.empty()) j["scene_file"] = h.scene_toml;
  if (!h.plan.empty()) j["plan"] = plan_json(h.plan);
  if (!h.timings_s.empty()) j["timings_s"] = timings_json(h.timings_s);
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
  sub << "N = " << sp.asperities << ", {/Symbol r} = " << sp.asperity_radius << " m";
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
      fig.xlabel = sym + " [{/Symbol m}m]";
      fig.x_scale = 1e6;
      fig.y_scale = 1e-6;
      fig.ylabel = "probability density [1/{/Symbol m}m]";
    } else {
      // Range from the data: the bulk plus the tails the log panel shows.
      std::vector<double> v(x.begin(), x.end());
      const auto q = quantiles_unsorted(v, std::vector<double>{1e-4, 1.0 - 1e-5});
      lo = q[0], hi = q[1];
      const double pad = 0.05 * (hi - lo);
      lo -= pad, hi += pad;
      if (!(hi > lo)) lo -= 1e-12, hi += 1e-12;
      const bool eps = set.quantity == "eps";
      fig.title = (eps ? std::string("{/Symbol e}") : std::string("{/Symbol W}'_x")) + ": " + sub.str();
      fig.xlabel = eps ? "{/Symbol e}" : "{/Symbol W}'_x [rad/s]";
      fig.ylabel = eps ? "probability density" : "probability density [s/rad]";
    }
    fig.histogram = make_histogram(x, lo, hi, 60);
    fig.data_label = data_label;
    for (const auto& law : set.laws) {
      const std::string label = law.name == "eq14"   ? "Eq. (14), Rayleigh"
                                : law.name == "eq18" ? "Eq. (18), Gaussian"
                                : law.name == "exact-sphere" ? "exact finite-N law on the sphere"
                                                             : law.name;
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
  // One gnuplot process per figure, run concurrently (write_figures).
  return write_figures(dir, figures);
}

}  // namespace asperity
