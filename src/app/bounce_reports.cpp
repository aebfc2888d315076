// SPDX-License-Identifier: GPL-3.0-or-later
// Tables, report.json bodies and figures of bounce runs (spheres and mesh bodies).
#include "checked_text.hpp"
#include "asperity/app/experiment_reports.hpp"

#include "asperity/app/report.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <locale>
#include <sstream>
#include <vector>

#include "asperity/app/plot.hpp"
#include "asperity/core/restitution.hpp"
#include "core/format.hpp"

namespace asperity {

using detail::fmt;
using detail::num;

std::string format_bounce_table(const std::vector<BounceVariantReport>& reports) {
  std::ostringstream o;
  o.imbue(std::locale::classic());
  char line[512];
  // Rates in units of a power of ten set by the largest left rate: ~1e5 for the rough sphere (the
  // roughness scatter), ~1e1 for a mesh body (the shape scatter). c can diverge (one-sided law).
  double a_max = 0;
  for (const auto& r : reports)
    for (const auto& g : r.groups)
      if (g.fitted && std::isfinite(g.fit.a.value)) a_max = std::max(a_max, g.fit.a.value);
  const int e10 = a_max > 0 ? static_cast<int>(std::floor(std::log10(a_max))) : 5;
  const double unit = std::pow(10.0, e10);
  const std::string scale = "[1e" + std::to_string(e10) + "]";
  std::snprintf(line, sizeof line, "%-18s %-13s %8s %6s %-22s %-24s %-18s %-18s %8s %6s\n", "variant", "group", "n", "<u>",
                "<eps> +- se", "mode m +- se", ("a +- se " + scale).c_str(), ("c +- se " + scale).c_str(), "KS D", "p");
  o << line << std::string(150, '-') << "\n";
  for (const auto& r : reports) {
    for (const auto& g : r.groups) {
      const std::string grp = g.by == "speed" ? "u in [" + fmt("%.1f", g.lo) + "," + fmt("%.1f", g.hi) + "]" : "k = " + fmt("%.0f", g.lo);
      std::string mean = g.n ? fmt(g.by == "speed" ? "%.2e" : "%.7f", g.eps_mean.value) + " +- " + fmt("%.1e", g.eps_mean.se) : "-";
      std::string m = "-", a = "-", c = "-", D = "-", p = "-";
      if (g.fitted) {
        m = fmt(g.by == "speed" ? "%.3e" : "%.8f", g.fit.m.value) + " +- " + fmt("%.1e", g.fit.m.se);
        a = fmt("%.3f", g.fit.a.value / unit) + " +- " + fmt("%.3f", g.fit.a.se / unit);
        c = fmt("%.3f", g.fit.c.value / unit) + " +- " + fmt("%.3f", g.fit.c.se / unit);
        D = fmt("%.4f", g.gof.D),
        p = fmt("%.2f", g.gof.p) + (g.gof_verdict == Verdict::undecided ? "?" : g.gof.stopped_early ? "~" : "");
      }
      std::snprintf(line, sizeof line, "%-18s %-13s %8zu %6.3f %-22s %-24s %-18s %-18s %8s %6s\n",
                    std::string(to_string(r.variant)).c_str(), grp.c_str(), g.n, g.mean_speed, mean.c_str(), m.c_str(),
                    a.c_str(), c.c_str(), D.c_str(), p.c_str());
      o << line;
    }
    std::snprintf(line, sizeof line,
                  "%-18s %llu sequences, %.2f impacts each, %.2f s; eps(times) - eps(velocities): mean %.3g, sd %.3g, max |.| %.3g "
                  "(n = %zu)\n",
                  std::string(to_string(r.variant)).c_str(), static_cast<unsigned long long>(r.sequences), r.impacts_per_sequence,
                  r.seconds, r.time_diff_mean, r.time_diff_sd, r.time_diff_max_abs, r.time_n);
    o << line;
    std::snprintf(line, sizeof line, "%-18s lag-1 correlation of eps - eps_n(u): %.4f +- %.4f (%zu pairs); <|Omega|> before the last impact %.3f rad/s\n",
                  std::string(to_string(r.variant)).c_str(), r.lag1_correlation.value, r.lag1_correlation.se, r.lag1_pairs,
                  r.spin_final_mean);
    o << line;
  }
  o << "a, c: rates of the asymmetric Laplace law (Eq. 2) left/right of the mode [1]; KS p from a parametric bootstrap\n"
       "(p? = undecided: no replicate reached D and 1/(1+B) >= alpha, cannot decide at this B, not an acceptance;\n"
       "p~ = estimated as K/L after a sequential stop once K replicates reached D and only 'accept' was left: the verdict is\n"
       "that of all B replicates, the value has a relative se of ~1/sqrt(K); report.json ks.replicates, ks.exceedances).\n"
       "Speed windows fit eps - eps_n(u) (eps_n of Eq. 9 at the impact speed), impact numbers k fit eps itself.\n";
  // The residual eps - eps_n(u) in every group against the semi-analytic law (theory_impact.hpp).
  bool any_theory = false;
  for (const auto& r : reports)
    for (const auto& g : r.groups) any_theory = any_theory || g.residual_fitted;
  if (any_theory) {
    std::snprintf(line, sizeof line, "\n%-18s %-13s %-10s %-9s %-19s %-19s %-17s %-8s %-8s %-16s\n", "variant", "group", "res mean",
                  "res sd", "a fit (theory)", "c fit (theory)", ("[" + scale.substr(1, scale.size() - 2) + "]").c_str(), "KS D",
                  "KS p", "corr(u, res)");
    o << line << std::string(150, '-') << "\n";
    for (const auto& r : reports)
      for (const auto& g : r.groups) {
        if (!g.residual_fitted) continue;
        const std::string grp = g.by == "speed" ? "u in [" + fmt("%.1f", g.lo) + "," + fmt("%.1f", g.hi) + "]" : "k = " + fmt("%.0f", g.lo);
        auto rate = [&](double fit, double th) {
          std::string x = fmt("%.3f", fit / unit);
          if (g.has_theory && th > 0) x += " (" + (std::isfinite(th) ? fmt("%.3f", th / unit) : std::string("inf")) + ")";
          return x;
        };
        std::snprintf(line, sizeof line, "%-18s %-13s %-10s %-9s %-19s %-19s %-17s %-8s %-8s %-16s\n",
                      std::string(to_string(r.variant)).c_str(), grp.c_str(), fmt("%.3e", g.residual_mean.value).c_str(),
                      fmt("%.2e", g.residual_std).c_str(), rate(g.residual_fit.a.value, g.theory_rate_below).c_str(),
                      rate(g.residual_fit.c.value, g.theory_rate_above).c_str(), "",
                      g.has_theory ? fmt("%.4f", g.theory_ks.D).c_str() : "-", g.has_theory ? fmt("%.2g", g.theory_ks.p).c_str() : "-",
                      // undefined where u does not vary (k = 1: every sequence starts at the same speed): "-", as null in the JSON
                      (std::isfinite(g.speed_residual_correlation.value)
                           ? fmt("%+.4f", g.speed_residual_correlation.value) + " +- " + fmt("%.4f", g.speed_residual_correlation.se)
                           : std::string("- (u constant)")).c_str());
        o << line;
      }
    o << "res = eps - eps_n(u_k); a, c fit: Eq. 2 fitted to res (no bootstrap); (theory): rates of the semi-analytic law at "
         "impact k (bounce_residual_laws; paper: with Eq. 26's beta1); KS D, p: res against that law (speed windows: its mixture over k).\n";
  }
  return detail::checked_text(std::move(o), "report.txt");
}

std::string bounce_to_json(const std::string& scene_name, const SphereParams& sphere, const BounceExperiment& b,
                           std::uint64_t seed, const std::vector<BounceVariantReport>& reports,
                           const std::vector<std::string>& plots, const std::vector<BounceComparison>& comparisons) {
  using nlohmann::json;
  auto jnum = [](double x) { return std::isfinite(x) ? json(x) : json(nullptr); };
  json j;
  j["schema_version"] = 1;
  j["tool"] = "validate-geometry";
  j["scene"] = scene_name;
  j["mode"] = "bounce";
  std::uint64_t impacts = 0;
  for (const auto& r : reports) impacts += r.impacts;
  j["samples"] = impacts;
  j["parameters"] = {{"asperities", sphere.asperities}, {"radius_m", sphere.radius}, {"asperity_radius_m", sphere.asperity_radius},
                     {"seed", seed}};
  j["rejected"] = false;
  j["plots"] = image_files(plots);
  j["plot_data"] = data_files(plots);
  json variants = json::array();
  for (const auto& r : reports) {
    json v;
    v["name"] = std::string(to_string(r.variant));
    v["sequences"] = r.sequences, v["impacts"] = r.impacts, v["impacts_per_sequence"] = r.impacts_per_sequence;
    v["no_impacts"] = r.no_impacts, v["seconds"] = r.seconds;
    v["sequences_per_second"] = jnum(static_cast<double>(r.sequences) / r.seconds);
    v["lazy_cells_per_sequence"] = r.cells_per_sequence, v["lazy_centres_per_sequence"] = r.centres_per_sequence;
    v["spin_before_last_impact_mean_rad_s"] = r.spin_final_mean;
    v["lag1_correlation"] = {{"value", jnum(r.lag1_correlation.value)}, {"se", jnum(r.lag1_correlation.se)}, {"pairs", r.lag1_pairs},
                             {"quantity", "eps-eps_n(u)"}};
    v["eps_time_vs_velocity"] = {{"n", r.time_n}, {"mean", jnum(r.time_diff_mean)}, {"sd", jnum(r.time_diff_sd)},
                                 {"max_abs", jnum(r.time_diff_max_abs)}};
    json groups = json::array();
    for (const auto& g : r.groups) {
      json x;
      x["by"] = g.by;
      x["range"] = {g.lo, g.hi};
      x["n"] = g.n;
      x["quantity"] = g.quantity;
      x["mean_speed_m_s"] = jnum(g.mean_speed);
      x["eps_mean"] = jnum(g.eps_mean.value), x["eps_mean_se"] = jnum(g.eps_mean.se), x["eps_std"] = jnum(g.eps_std);
      x["spin_mean_rad_s"] = jnum(g.spin_mean);
      x["eps_time_minus_eps"] = {{"mean", jnum(g.eps_time_minus_eps.value)}, {"se", jnum(g.eps_time_minus_eps.se)}};
      if (g.fitted) {
        const auto& f = g.fit;
        x["fit"] = {{"law", "asymmetric-laplace"}, {"m", f.m.value}, {"m_se", jnum(f.m.se)}, {"log_a", f.log_a.value},
                    {"log_a_se", jnum(f.log_a.se)}, {"log_c", f.log_c.value}, {"log_c_se", jnum(f.log_c.se)},
                    {"a", f.a.value}, {"a_se", jnum(f.a.se)}, {"c", f.c.value}, {"c_se", jnum(f.c.se)},
                    {"log_likelihood", f.log_likelihood}, {"se_method", "Fisher information"}};
        x["ks"] = {{"statistic", "KS"}, {"D", g.gof.D}, {"p", jnum(g.gof.p)}, {"bootstrap", g.gof.bootstrap},
                   {"replicates", g.gof.replicates}, {"exceedances", g.gof.exceedances},
                   {"p_method", g.gof.stopped_early ? "parametric bootstrap (parameters refitted), sequential: stopped after "
                                                      "the replicates shown, p = exceedances/replicates (verdict as with all)"
                                                    : "parametric bootstrap (parameters refitted)"},
                   {"decisive", false},
                   {"p_floor", g.gof.bootstrap ? 1.0 / (1.0 + static_cast<double>(g.gof.bootstrap)) : 1.0},
                   {"verdict", std::string(to_string(g.gof_verdict))}};
      } else {
        x["fit"] = nullptr, x["ks"] = nullptr;
      }
      if (g.residual_fitted) {
        const auto& f = g.residual_fit;
        x["residual"] = {{"quantity", "eps-eps_n(u)"}, {"mean", jnum(g.residual_mean.value)}, {"mean_se", jnum(g.residual_mean.se)},
                         {"std", jnum(g.residual_std)}, {"fit", {{"m", f.m.value}, {"a", f.a.value}, {"a_se", jnum(f.a.se)},
                                                                  {"c", f.c.value}, {"c_se", jnum(f.c.se)}}},
                         {"speed_correlation", jnum(g.speed_residual_correlation.value)},
                         {"speed_correlation_se", jnum(g.speed_residual_correlation.se)}};
        if (g.has_theory)
          x["residual"]["theory"] = {{"law", "semi-analytic asymmetric Laplace (planar spin random walk x Gaussian offset)"},
                                     {"rate_below", jnum(g.theory_rate_below)}, {"rate_above", jnum(g.theory_rate_above)},
                                     {"ks_D", g.theory_ks.D}, {"ks_p", jnum(g.theory_ks.p)}};
      }
      groups.push_back(std::move(x));
    }
    v["groups"] = std::move(groups);
    variants.push_back(std::move(v));
  }
  json cmp = json::array();
  for (const auto& c : comparisons)
    cmp.push_back({{"a", std::string(to_string(c.a))}, {"b", std::string(to_string(c.b))}, {"by", c.by}, {"range", {c.lo, c.hi}},
                   {"statistic", "KS two-sample"}, {"D", c.ks.D}, {"p", jnum(c.ks.p)}, {"n_eff", c.ks.n}});
  j["bounce"] = {{"variants", variants},
                 {"variant_comparisons", cmp},
                 {"grouping_note", bounce_grouping_note()},
                 {"first_speed_m_s", b.speed},
                 {"stop_speed_m_s", b.stop_speed},
                 {"gravity_m_s2", b.gravity},
                 {"density_kg_m3", b.density},
                 {"beta", b.beta},
                 {"eps_t", b.eps_t},
                 {"tangential", [&] {
                    TangentialLaw law = b.tangential;
                    if (law.model == TangentialLaw::Model::kinematic) law.eps_t = b.eps_t;
                    return law.describe();
                  }()},
                 {"bootstrap", b.bootstrap},
                 {"bootstrap_stop", b.bootstrap_stop},
                 {"alpha", b.alpha},
                 {"eps_time_note", "eps(times) = T_k / T_(k-1) from the flight times before and after impact k; it differs "
                                   "from eps = V'_z/V_z by the height differences of successive lowest points"}};
  return j.dump(2) + "\n";
}

namespace {
// One variant's figure: its speed windows' histograms and fitted Eq. 2 densities, in units of
// 1e-6 about each window's mode, on a log scale.
Figure bounce_figure(const BounceVariantReport& r, const std::vector<const BounceGroup*>& gs) {
  Figure fig;
  fig.title = "Fig. 6, " + std::string(to_string(r.variant)) + ": impact-speed windows, fitted asymmetric Laplace (Eq. 2)";
  fig.xlabel = "ε - ε_n(u) - m [10^{-6}]";
  fig.height = 650;
  Panel p;
  p.ylabel = "probability density [1/10^{-6}]";
  p.log_y = true;
  p.legend = LegendAt::top_left;
  double ymin = 1e300, ymax = 0;
  for (std::size_t k = 0; k < gs.size(); ++k) {
    const auto& g = *gs[k];
    const auto& f = g.fit.law;
    const Rgb colour = kOkabeIto[(k + 1) % std::size(kOkabeIto)];
    // eps - m in units of 1e-6, range from the 0.1% and 99.9% sample quantiles.
    const double lo = (quantile_sorted(g.sorted, 0.001) - f.m) * 1e6, hi = (quantile_sorted(g.sorted, 0.999) - f.m) * 1e6;
    std::vector<double> x(g.sorted.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = (g.sorted[i] - f.m) * 1e6;
    const auto h = make_histogram(x, lo, hi, 60);
    PointSeries pts;
    pts.label = "u in [" + num(g.lo) + "," + num(g.hi) + "] m/s (n = " + std::to_string(g.n) + ")";
    pts.colour = colour, pts.size = 0.8;
    for (std::size_t i = 0; i < h.bins(); ++i)
      if (h.counts[i] > 0) {
        pts.x.push_back(h.centre(i)), pts.y.push_back(h.density(i)), pts.se.push_back(h.density_se(i));
        pts.count.push_back(h.counts[i]);
        ymin = std::min(ymin, h.density(i)), ymax = std::max(ymax, h.density(i));
      }
    LineSeries law;  // not in the legend: the window's colour says which fit it is
    law.colour = colour, law.in_legend = false;
    for (int i = 0; i <= 400; ++i) {
      const double t = lo + (hi - lo) * i / 400.0;
      law.x.push_back(t), law.y.push_back(f.pdf(f.m + t * 1e-6) * 1e-6);
    }
    law.label = "Eq. 2 fit, u in [" + num(g.lo) + "," + num(g.hi) + "] m/s";
    p.points.push_back(std::move(pts));
    p.lines.push_back(std::move(law));
  }
  if (ymax > 0) p.y_lo = ymin / 3, p.y_hi = ymax * 3;
  fig.panels = {std::move(p)};
  return fig;
}
}  // namespace

std::vector<std::string> write_bounce_plots(const std::filesystem::path& dir, const std::vector<BounceVariantReport>& reports,
                                            const PlotFormats& formats) {
  std::vector<std::string> files;
  for (const auto& r : reports) {
    std::vector<const BounceGroup*> gs;
    for (const auto& g : r.groups)
      if (g.by == "speed" && g.fitted) gs.push_back(&g);
    if (gs.empty()) continue;
    // A failure throws; the run's own clean-up removes the figures written before it.
    const auto written = write_figure(dir, "fig6_" + std::string(to_string(r.variant)), bounce_figure(r, gs), formats);
    files.insert(files.end(), written.begin(), written.end());
  }
  return files;
}

namespace {

// eps against impact speed: mean +- se and the 10/90% quantiles per speed bin, eps_n(u) of Eq. 9
// (what a smooth sphere would give) for reference. `title` is figure markup (user text escaped).
Figure eps_vs_speed_figure(const BodyBounceReport& r, const BounceExperiment& b, const std::string& title) {
  const auto en = viscoelastic_pade14(b.beta);
  Figure fig;
  fig.title = title;
  fig.xlabel = "impact speed u = -V_z [m/s]";
  fig.height = 600;
  Panel p;
  p.ylabel = "ε = -V'_z/V_z";
  p.legend = LegendAt::bottom_right;
  p.grid = true;
  p.y_lo = -0.5, p.y_hi = 3;
  BandSeries band;
  band.label = "10%-90% of impacts";
  PointSeries mean;
  mean.label = "mean ± se";
  mean.colour = {0x00, 0x72, 0xB2};
  mean.size = 1.2;
  for (const auto& x : r.by_speed)
    if (x.n >= 5) {
      const double u = 0.5 * (x.lo + x.hi);
      band.x.push_back(u), band.lo.push_back(x.eps_q10), band.hi.push_back(x.eps_q90);
      mean.x.push_back(u), mean.y.push_back(x.eps.value), mean.se.push_back(x.eps.se), mean.count.push_back(double(x.n));
    }
  LineSeries smooth;
  smooth.label = "ε_n(u), Eq. (9): smooth sphere";
  for (int i = 0; i <= 100; ++i) {
    const double u = b.stop_speed + (b.speed - b.stop_speed) * i / 100.0;
    smooth.x.push_back(u), smooth.y.push_back((*en)(u));
  }
  fig.x_lo = std::min(b.stop_speed, b.speed), fig.x_hi = std::max(b.stop_speed, b.speed);
  p.bands = {std::move(band)};
  p.points = {std::move(mean)};
  p.lines = {std::move(smooth)};
  fig.panels = {std::move(p)};
  return fig;
}

}  // namespace

std::string format_table(const MeshBounceReport& r) {
  const auto& e = r.experiment;
  const auto& b = r.report;
  const auto& st = b.stops;
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os << std::setprecision(4);
  os << "bounce sequences of a rough body: " << r.body_name
     << (e.mesh.empty() ? "" : e.smooth.empty() ? " (centres on the facets)" : " (centres on the smooth surface)") << ", N = "
     << e.asperities << ", radii " << e.radii.describe() << ", " << e.bodies << " bodies\n";
  os << "mass " << r.mass << " kg, principal moments " << r.principal_moments.transpose() << " kg m^2, max |c_i| " << r.c_max
     << " m\n";
  TangentialLaw law = e.options.tangential;
  if (law.model == TangentialLaw::Model::kinematic) law.eps_t = e.options.bounce.eps_t;
  os << "tangential law " << law.describe() << "\n";
  os << "first impact u = " << e.options.bounce.speed << " m/s, Omega = " << e.options.bounce.omega.transpose() << " rad/s, stop below "
     << e.options.bounce.stop_speed << " m/s, g = " << e.options.bounce.gravity << " m/s^2\n";
  os << b.base.sequences << " sequences, " << b.base.impacts << " impacts: " << b.base.impacts_per_sequence << " +- "
     << b.impacts_per_sequence_sd << " (sd) per sequence, max " << b.impacts_max << "\n";
 os << "stops: slow " << st.slow << ", no approach " << st.no_approach
     << ", max impacts " << st.max_impacts << ", max time " << st.max_time << ", max steps " << st.max_steps << "\n";
  os << "impacts with the centre rising (u <= 0: rocking onto another asperity): " << b.rising_fraction << "\n";
  os << "eps < 0: " << b.eps_below_0 << ", eps > 1: " << b.eps_above_1 << " (fractions of impacts); <|Omega|> before the last impact "
     << b.base.spin_final_mean << " rad/s; rotational share of the kinetic energy after the last impact " << b.rot_fraction_last
     << "\n";
  os << "energy: impacts gaining energy " << b.energy_gain_fraction << " (max gain " << b.energy_gain_max
     << " of E), work identity max rel. residual " << b.work_identity_max << ", flight energy max rel. drift " << b.flight_energy_max
     << "\n";
  os << "landing search: " << b.queries_per_flight << " support queries per flight, flights < 1 ms: " << b.short_flights << "\n";
  os << "run " << r.seconds_run << " s (" << static_cast<double>(b.base.sequences) / r.seconds_run << " sequences/s), bodies "
     << r.seconds_build << " s, support trees " << r.seconds_index << " s, analysis " << r.seconds_analysis << " s, figures "
     << r.seconds_plots << " s\n\n";
  os << "u bin [m/s]        n   <eps> +- se          eps 10% .. 90%     <|Omega|> [rad/s]\n";
  for (const auto& x : b.by_speed) {
    char line[160];
    std::snprintf(line, sizeof line, "%.3f-%.3f %7zu   %8.4f +- %-8.4f  %7.3f .. %-7.3f  %8.2f\n", x.lo, x.hi, x.n, x.eps.value,
                  x.eps.se, x.eps_q10, x.eps_q90, x.spin_mean);
    os << line;
  }
  os << "\n";
  os << format_bounce_table({b.base});
  return detail::checked_text(std::move(os), "report.txt");
}

std::string to_json(const MeshBounceReport& r) {
  const auto& e = r.experiment;
  const auto& b = r.report;
  auto jnum = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  // The fig6 report of the same groups and fits (bounce.hpp), with the body in place of the sphere.
  SphereParams none;
  none.asperities = e.asperities;
  nlohmann::json j = nlohmann::json::parse(bounce_to_json("", none, e.options.bounce, e.seed, {b.base}, r.plots));
  j.erase("scene");  // the header's (with_header, report.hpp)
  j["mode"] = "body-bounce";
  TangentialLaw law = e.options.tangential;
  if (law.model == TangentialLaw::Model::kinematic) law.eps_t = e.options.bounce.eps_t;
  j["tangential"] = law.describe();
  j["bounce"]["tangential"] = law.describe();  // the body's law, not the sphere variants' default
  j["parameters"] = {{"asperities", e.asperities}, {"radii", e.radii.describe()}, {"bodies", e.bodies}, {"seed", e.seed}};
  j["body"] = {{"name", r.body_name},
               {"mesh", e.mesh.string()},
               {"scale", e.scale},
               {"smooth", e.smooth},
               {"sphere_radius_m", e.mesh.empty() ? jnum(e.sphere_radius) : nlohmann::json(nullptr)},
               {"mass_kg", r.mass},
               {"density_kg_m3", e.density},
               {"principal_moments_kg_m2", {r.principal_moments.x(), r.principal_moments.y(), r.principal_moments.z()}},
               {"c_max_m", r.c_max}};
  nlohmann::json bins = nlohmann::json::array();
  for (const auto& x : b.by_speed)
    bins.push_back({{"range", {x.lo, x.hi}}, {"n", x.n}, {"eps_mean", jnum(x.eps.value)}, {"eps_mean_se", jnum(x.eps.se)},
                    {"eps_q10", jnum(x.eps_q10)}, {"eps_q90", jnum(x.eps_q90)}, {"spin_mean_rad_s", jnum(x.spin_mean)}});
  const auto& st = b.stops;
  const Vec3& w0 = e.options.bounce.omega;
  j["bounce"]["omega_rad_s"] = {w0.x(), w0.y(), w0.z()};
  j["bounce"]["max_time_s"] = e.options.max_time;
  j["bounce"]["max_impacts"] = e.options.bounce.max_impacts;
  j["bounce"]["time_tolerance_s"] = e.options.landing.time_tolerance;
  j["bounce"]["stop_rule"] =
      "before each impact: total time > max_time; no approach of the lowest asperity; its normal approach speed "
      "-v_n < stop_speed ('slow'); after impact max_impacts; a landing search > max_steps";
  j["bounce"]["body"] = {{"stops", {{"slow", st.slow}, {"no_approach", st.no_approach},
                                    {"max_impacts", st.max_impacts}, {"max_time", st.max_time}, {"max_steps", st.max_steps}}},
                         {"impacts_per_sequence_sd", b.impacts_per_sequence_sd},
                         {"impacts_max", b.impacts_max},
                         {"support_queries_per_flight", jnum(b.queries_per_flight)},
                         {"rising_fraction", jnum(b.rising_fraction)},
                         {"eps_below_0_fraction", jnum(b.eps_below_0)},
                         {"eps_above_1_fraction", jnum(b.eps_above_1)},
                         {"rotational_share_after_last", jnum(b.rot_fraction_last)},
                         {"energy_gain_fraction", jnum(b.energy_gain_fraction)},
                         {"energy_gain_max_rel", jnum(b.energy_gain_max)},
                         {"work_identity_max_rel", b.work_identity_max},
                         {"flight_energy_max_rel", b.flight_energy_max},
                         {"short_flight_fraction", jnum(b.short_flights)},
                         {"eps_by_speed", bins},
                         {"seconds_build", r.seconds_build},
                         {"seconds_index", r.seconds_index},
                         {"seconds_run", r.seconds_run},
                         {"sequences_per_second", jnum(static_cast<double>(b.base.sequences) / r.seconds_run)},
                         {"seconds_analysis", r.seconds_analysis},
                         {"seconds_plots", r.seconds_plots}};
  return j.dump(2) + "\n";
}

std::vector<std::string> write_mesh_bounce_plots(const std::filesystem::path& dir, const MeshBounceReport& r,
                                                 const PlotFormats& formats) {
  std::vector<std::string> plots =
      write_figure(dir, "eps_vs_speed",
                   eps_vs_speed_figure(r.report, r.experiment.options.bounce, "ε against impact speed: " + mesh_bounce_subtitle(r)), formats);
  try {
    for (const auto& f : write_figures(dir, r.figures, formats)) plots.push_back(f);
    for (const auto& f : write_bounce_plots(dir, {r.report.base}, formats)) plots.push_back(f);
  } catch (...) {
    for (const auto& f : plots) {
      std::error_code ec;
      std::filesystem::remove(dir / f, ec);
    }
    throw;
  }
  return plots;
}

}  // namespace asperity
