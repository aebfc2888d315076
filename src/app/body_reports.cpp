// SPDX-License-Identifier: GPL-3.0-or-later
// Tables and report.json bodies of the experiments beyond the paper (radii, mesh impacts).
#include "checked_text.hpp"
#include "asperity/app/experiment_reports.hpp"

#include "asperity/app/plot.hpp"
#include "asperity/app/report.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <iomanip>
#include <sstream>

namespace asperity {
namespace {

nlohmann::json json_of(const Estimate& e) { return {{"value", e.value}, {"se", e.se}}; }
nlohmann::json json_of(const LawCheck& c, double adjusted_p, bool family_reject) {
  return {{"quantity", c.quantity}, {"law", c.law},     {"lambda", c.lambda},           {"statistic", "KS"},
          {"D", c.ks.D},            {"p", c.ks.p},       {"n", c.ks.n},                  {"power_check", c.power_check},
          {"decisive", c.decisive}, {"verdict", to_string(c.verdict)},   {"note", c.note},
          {"adjusted_p", std::isnan(adjusted_p) ? nlohmann::json(nullptr) : nlohmann::json(adjusted_p)},
          {"family_reject", family_reject}};
}

// tests[], plots, rejected (the family's decision, Holm at alpha), family, skipped of a report body.
void add_tests(nlohmann::json& j, const std::vector<LawCheck>& tests, const std::vector<std::string>& plots, double alpha) {
  const FamilyDecision family = check_family(tests, alpha);
  std::vector<std::string> names;
  j["tests"] = nlohmann::json::array();
  for (std::size_t i = 0; i < tests.size(); ++i) {
    j["tests"].push_back(json_of(tests[i], family.adjusted_p[i], family.reject[i]));
    names.push_back(tests[i].quantity + " " + tests[i].law + " (KS)");
  }
  j["plots"] = image_files(plots);
  j["plot_data"] = data_files(plots);
  j["rejected"] = family.rejected;
  j["family"] = nlohmann::json::parse(family_json(family, names));
  j["skipped"] = decisive_skipped(tests);
}

// The tests as table rows (the lambda column if asked), then why any test was skipped.
void write_tests(std::ostream& os, const std::vector<LawCheck>& tests, const char* quantity_label, int qw, int lw,
                 bool lambda, double alpha) {
  os << std::left << std::setw(qw) << quantity_label << std::setw(lw) << "law";
  if (lambda) os << std::setw(13) << "lambda";
  os << std::setw(11) << "KS D" << std::setw(11) << "p" << "verdict\n";
  for (const auto& t : tests) {
    os << std::setw(qw) << t.quantity << std::setw(lw) << t.law;
    if (lambda) os << std::setw(13) << t.lambda;
    os << std::setw(11) << t.ks.D << std::setw(11) << t.ks.p << to_string(t.verdict)
       << (t.power_check ? " (power check: must reject)" : "") << "\n";
  }
  const FamilyDecision f = check_family(tests, alpha);
  os << "family (Holm, " << f.tests << " decided decisive test" << (f.tests == 1 ? "" : "s") << ", alpha = " << alpha
     << "): " << (f.rejected ? "REJECT" : "accept");
  if (f.tests > 0) os << ", smallest adjusted p = " << f.min_adjusted_p;
  os << "\n";
  for (const auto& t : tests)
    if (t.verdict == Verdict::skipped)
      os << "skipped: " << t.quantity << " " << t.law << (t.decisive ? " (decisive)" : "") << ": " << t.note << "\n";
}
}  // namespace

std::string format_table(const RadiiReport& r) {
  std::ostringstream os;
  const auto& e = r.experiment;
  os << "unequal asperities: N = " << e.asperities << ", R = " << e.radius << " m, radii " << e.radii.describe() << "\n";
  os << std::setprecision(4);
  os << "lambda = " << r.lambda << " 1/m^2, lambda_top = " << r.lambda_top << ", lambda_eff = " << r.lambda_eff.value
     << " +- " << r.lambda_eff.se << " (" << e.screen_bodies << " screened spheres), lambda_fit = " << r.lambda_fit << "\n";
  os << "screening: kept " << (r.witnessed + r.helly) << " (witness " << r.witnessed << ", Helly " << r.helly
     << "), screened " << r.screened << "; kept fraction by level:";
  for (double f : r.kept_fraction_by_level) os << " " << f;
  os << "\n  largest empty cap " << r.theta_cover << " rad, mean competitors " << r.mean_competitors << ", "
     << r.seconds_screen << " s\n";
  os << "cross-check: " << r.directions << " random directions, winners screened " << r.winners_screened
     << ", kept but never hit " << r.kept_never_hit << "\n";
  if (e.radii.kind == RadiusDistribution::Kind::lognormal) {
    os << "drops: " << e.drops << " (rotations of the screened spheres)";
  } else {
    os << "fresh drops: " << e.drops << ", touching level fractions:";
    for (double f : r.winner_level_fraction) os << " " << f;
  }
  os << ", core contacts " << r.core_contacts << ", std(r_x) = " << r.rx_std.value << " +- " << r.rx_std.se << " m\n";
  write_tests(os, r.tests, "qty", 6, 24, true, e.alpha);
  return detail::checked_text(std::move(os), "report.txt");
}

std::string to_json(const RadiiReport& r) {
  nlohmann::json j;
  const auto& e = r.experiment;
  j["schema_version"] = kReportSchemaVersion;
  j["experiment"] = "unequal-radii";
  j["asperities"] = e.asperities;
  j["radius"] = e.radius;
  j["radii"] = e.radii.describe();
  j["drops"] = e.drops;
  j["seed"] = e.seed;
  j["alpha"] = e.alpha;
  j["lambda"] = r.lambda;
  j["lambda_top"] = r.lambda_top;
  j["lambda_eff"] = json_of(r.lambda_eff);
  j["lambda_fit"] = r.lambda_fit;
  j["kept_fraction_by_level"] = r.kept_fraction_by_level;
  j["screening"] = {{"bodies", e.screen_bodies},           {"witnessed", r.witnessed},
                    {"helly", r.helly},                     {"screened", r.screened},
                    {"theta_cover", r.theta_cover},         {"mean_competitors", r.mean_competitors},
                    {"directions", r.directions},           {"winners_screened", r.winners_screened},
                    {"kept_never_hit", r.kept_never_hit},   {"seconds", r.seconds_screen}};
  j["winner_level_fraction"] = r.winner_level_fraction;
  j["core_contacts"] = r.core_contacts;
  j["rx_std"] = json_of(r.rx_std);
  add_tests(j, r.tests, r.plots, e.alpha);
  j["seconds_fresh"] = r.seconds_fresh;
  return j.dump(2) + "\n";
}

std::string format_table(const MeshImpactReport& r) {
  std::ostringstream os;
  const auto& e = r.experiment;
  os << std::setprecision(4);
  os << "mesh body " << e.mesh.string() << (e.smooth_ellipsoid.empty() ? " (centres on the facets)" : " (centres on the smooth surface)")
     << ": N = " << e.asperities << ", radii " << e.radii.describe() << ", " << e.bodies << " bodies x "
     << e.drops / e.bodies << " rotations\n";
  os << "mass " << r.mass.mass << " kg, volume " << r.mass.volume << " m^3, area " << r.mass.area
     << " m^2, principal moments " << r.principal_moments.transpose() << " kg m^2\n";
  os << "comparison sphere: R = " << r.law_radius << " m, N = " << r.law_asperities << " (same areal density)\n";
  os << "drops " << r.samples << ", no impact " << r.no_impacts << ", base surface lower than every asperity "
     << r.core_contacts << "\n";
  os << "tangential law " << tangential_law(e).describe() << ": impacts gaining kinetic energy " << 100 * r.energy_gain_fraction
     << " %, largest relative change " << r.energy_gain_max << "\n";
  if (const auto& s = r.screening; s.bodies > 0) {
    os << "screening (" << s.bodies << " bodies): lambda = " << s.lambda << ", lambda_eff = " << s.lambda_eff.value << " +- "
       << s.lambda_eff.se << " 1/m^2, kept fraction " << s.kept_fraction << ", by level:";
    for (double f : s.kept_fraction_by_level) os << " " << f;
    os << "\n  witnessed " << s.witnessed << ", kept without proof " << s.helly << ", screened " << s.screened
       << ", mean competitors " << s.mean_competitors << ", " << s.seconds << " s; cross-check: " << s.directions
       << " random directions, winners screened " << s.winners_screened << ", kept but never hit " << s.kept_never_hit << "\n";
  }
  os << std::left << std::setw(15) << "quantity" << std::setw(24) << "mean +- se" << std::setw(13) << "std" << "q01 / q50 / q99\n";
  for (const auto& q : r.quantities) {
    std::ostringstream m;
    m << std::setprecision(5) << q.summary.mean.value << " +- " << std::setprecision(2) << q.summary.mean.se;
    os << std::setw(15) << q.name << std::setw(24) << m.str() << std::setw(13) << q.summary.std.value;
    for (const auto& x : q.summary.quantiles) os << x.value << " ";
    os << "\n";
  }
  write_tests(os, r.tests, "quantity", 15, 28, false, e.alpha);
  return detail::checked_text(std::move(os), "report.txt");
}

std::string to_json(const MeshImpactReport& r) {
  nlohmann::json j;
  const auto& e = r.experiment;
  j["schema_version"] = kReportSchemaVersion;
  j["experiment"] = "mesh-impacts";
  j["mesh"] = e.mesh.string();
  j["smooth_ellipsoid"] = e.smooth_ellipsoid;
  j["asperities"] = e.asperities;
  j["radii"] = e.radii.describe();
  j["bodies"] = e.bodies;
  j["drops"] = e.drops;
  j["speed"] = e.speed;
  j["omega"] = {e.omega.x(), e.omega.y(), e.omega.z()};
  j["seed"] = e.seed;
  j["tangential"] = tangential_law(e).describe();
  j["energy_gain_fraction"] = r.energy_gain_fraction;
  j["energy_gain_max"] = r.energy_gain_max;
  j["mass"] = {{"mass", r.mass.mass},
               {"volume", r.mass.volume},
               {"area", r.mass.area},
               {"centroid", {r.mass.centroid.x(), r.mass.centroid.y(), r.mass.centroid.z()}},
               {"principal_moments", {r.principal_moments.x(), r.principal_moments.y(), r.principal_moments.z()}}};
  j["law_radius"] = r.law_radius;
  j["law_asperities"] = r.law_asperities;
  j["samples"] = r.samples;
  j["no_impacts"] = r.no_impacts;
  j["core_contacts"] = r.core_contacts;
  j["quantities"] = nlohmann::json::array();
  for (const auto& q : r.quantities)
    j["quantities"].push_back({{"name", q.name},
                               {"n", q.summary.n},
                               {"mean", json_of(q.summary.mean)},
                               {"std", json_of(q.summary.std)},
                               {"batches", q.summary.batches}});
  add_tests(j, r.tests, r.plots, e.alpha);
  j["seconds"] = r.seconds;
  if (const auto& s = r.screening; s.bodies > 0)
    j["screening"] = {{"bodies", s.bodies},
                      {"lambda", s.lambda},
                      {"lambda_eff", json_of(s.lambda_eff)},
                      {"levels", s.levels},
                      {"kept_fraction_by_level", s.kept_fraction_by_level},
                      {"kept_fraction", s.kept_fraction},
                      {"witnessed", s.witnessed},
                      {"helly", s.helly},
                      {"screened", s.screened},
                      {"mean_competitors", s.mean_competitors},
                      {"directions", s.directions},
                      {"winners_screened", s.winners_screened},
                      {"kept_never_hit", s.kept_never_hit},
                      {"seconds", s.seconds}};
  return j.dump(2) + "\n";
}

}  // namespace asperity
