#include "asperity/app/cor_table.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "asperity/app/atomic_file.hpp"
#include "asperity/config.hpp"
#include "asperity/core/restitution.hpp"
#include "asperity/laws/statistics.hpp"

namespace asperity {
namespace {

// Shortest text that reads back to the same double (0.005, not 0.0050000000000000001).
std::string num(double x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

[[noreturn]] void bad(const std::string& field, const std::string& value, const std::string& why) {
  throw std::invalid_argument("cor_table: " + field + " = " + value + ": " + why);
}

// JSON numbers must be finite; NaN (an undefined standard error) is written as null.
nlohmann::json finite_or_null(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

std::pair<double, double> mean_std(const std::vector<double>& x) {
  double sum = 0, sq = 0;
  for (const double e : x) sum += e;
  const double mean = sum / static_cast<double>(x.size());
  for (const double e : x) sq += (e - mean) * (e - mean);
  return {mean, x.size() > 1 ? std::sqrt(sq / static_cast<double>(x.size() - 1)) : 0.0};
}

}  // namespace

CorTableSpec cor_table_spec(const Scene& s, std::size_t speeds) {
  if (s.mesh || s.radii || s.bounce.enabled)
    throw std::invalid_argument("cor_table: scene '" + s.name + "' is not a sphere impact scene (body.kind = \"sphere\", "
                                "fixed asperity radius, no bounce)");
  if (speeds < 1) bad("speeds", std::to_string(speeds), "needs at least one speed");
  CorTableSpec c;
  c.sphere = s.ensemble.sphere;
  c.impact = s.ensemble.impact;
  c.impact.enabled = true;
  c.seed = s.ensemble.seed;
  c.threads = s.ensemble.threads;
  const double u = c.impact.speed;
  for (std::size_t i = 0; i < speeds; ++i)
    c.speeds.push_back(speeds == 1 ? u : u * std::pow(10.0, -1.0 + 2.0 * static_cast<double>(i) / static_cast<double>(speeds - 1)));
  return c;
}

CorTableSpec cor_table_spec(const Scene& s, const CorTableScene& c) {
  CorTableSpec spec = cor_table_spec(s);
  if (!c.speeds.empty()) spec.speeds = c.speeds;
  spec.probabilities = c.probabilities;
  spec.drops = c.drops;
  return spec;
}

void validate(const CorTableSpec& c) {
  validate(c.sphere);
  if (c.speeds.empty()) bad("speeds", "[]", "needs at least one speed");
  for (std::size_t i = 0; i < c.speeds.size(); ++i) {
    const double v = c.speeds[i];
    if (!std::isfinite(v) || !(v > 0) || v > kMaxSpeed) bad("speeds[" + std::to_string(i) + "]", num(v), "must be finite, > 0 and <= 1e8 m/s");
    if (i > 0 && !(v > c.speeds[i - 1])) bad("speeds[" + std::to_string(i) + "]", num(v), "speeds must be strictly ascending");
  }
  if (c.probabilities < 2 || c.probabilities > 100001)
    bad("probabilities", std::to_string(c.probabilities), "must be in [2, 100001]");
  if (c.drops < 3) bad("drops", std::to_string(c.drops), "must be >= 3");
  if (!(c.impact.beta > 0) || !std::isfinite(c.impact.beta)) bad("beta", num(c.impact.beta), "must be finite and > 0");
}

CorTable make_cor_table(const CorTableSpec& spec, const Progress& progress) {
  validate(spec);
  CorTable t;
  t.spec = spec;
  const std::size_t P = spec.probabilities;
  for (std::size_t j = 0; j < P; ++j) t.probabilities.push_back(static_cast<double>(j) / static_cast<double>(P - 1));
  const auto eps_n = viscoelastic_pade14(spec.impact.beta);
  const std::uint64_t total = spec.drops * spec.speeds.size();
  for (std::size_t i = 0; i < spec.speeds.size(); ++i) {
    EnsembleConfig c;
    c.sphere = spec.sphere;
    c.mode = Mode::sampled;  // the exact finite-N law of the lowest asperity (the header says so)
    c.drops = spec.drops;
    c.seed = spec.seed;
    c.threads = spec.threads;
    c.impact = spec.impact;
    c.impact.enabled = true;
    c.impact.speed = spec.speeds[i];
    const std::uint64_t offset = spec.drops * i;
    Progress p;
    if (progress) p = [&](std::uint64_t done, std::uint64_t) { progress(offset + done, total); };
    ContactSamples s = run_contact_ensemble(c, p);
    // The ensemble reports from its thread 0 only, which may get no chunk of a small run: one
    // report per speed from here, so progress (and a Python binding's Ctrl-C check) always runs.
    if (progress) progress(offset + spec.drops, total);
    CorTableRow row;
    row.speed = spec.speeds[i];
    row.samples = s.eps.size();
    row.eps_n = (*eps_n)(row.speed);
    row.core_contacts = static_cast<std::uint64_t>(std::count(s.eps_core.begin(), s.eps_core.end(), std::uint8_t{1}));
    if (s.eps.empty()) bad("speeds[" + std::to_string(i) + "]", num(row.speed), "no drop approached the plate");
    std::sort(s.eps.begin(), s.eps.end());
    std::sort(s.omega_x_after.begin(), s.omega_x_after.end());
    for (const double p : t.probabilities) {
      row.quantiles.push_back(quantile_sorted(s.eps, p));
      row.omega_x_quantiles.push_back(quantile_sorted(s.omega_x_after, p));
    }
    std::tie(row.mean, row.std) = mean_std(s.eps);
    std::tie(row.omega_x_mean, row.omega_x_std) = mean_std(s.omega_x_after);
    try {
      row.fit = fit_asymmetric_laplace_sorted(s.eps);
      row.fitted = true;
    } catch (const std::exception& e) {
      row.fit_note = e.what();
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

std::string cor_table_csv(const CorTable& t) {
  std::ostringstream o;
  o << "# asperity-cor-table format=" << kCorTableFormatVersion << "\n"
    << "# eps quantiles: row = impact speed [m/s], column p = probability; sample eps by bilinear\n"
    << "# interpolation in (speed, p) with a uniform u (include/asperity/cor_table.h). Header: the .json file.\n"
    << "# N=" << t.spec.sphere.asperities << " R=" << num(t.spec.sphere.radius) << " a=" << num(t.spec.sphere.asperity_radius)
    << " beta=" << num(t.spec.impact.beta) << " eps_t=" << num(t.spec.impact.eps_t) << " Omega=" << num(t.spec.impact.omega.x())
    << "," << num(t.spec.impact.omega.y()) << "," << num(t.spec.impact.omega.z()) << " seed=" << t.spec.seed
    << " drops=" << t.spec.drops << " version=" << ASPERITY_VERSION << "\n";
  o << "speed_m_s";
  for (const double p : t.probabilities) o << ",p=" << num(p);
  o << "\n";
  for (const auto& r : t.rows) {
    o << num(r.speed);
    for (const double q : r.quantiles) o << "," << num(q);
    o << "\n";
  }
  return o.str();
}

std::string cor_table_json(const CorTable& t) {
  using nlohmann::json;
  const auto& s = t.spec;
  json j;
  j["format"] = "asperity-cor-table";
  j["format_version"] = kCorTableFormatVersion;
  j["tool"] = "asperity";
  j["version"] = ASPERITY_VERSION;
  j["quantity"] = "eps";
  j["body"] = {{"kind", "sphere"}, {"N", s.sphere.asperities}, {"R_m", s.sphere.radius}, {"a_m", s.sphere.asperity_radius}};
  j["material"] = {{"density_kg_m3", s.impact.density}, {"eps_t", s.impact.eps_t},
                   {"restitution", {{"model", "viscoelastic"}, {"beta", s.impact.beta}}}};
  j["Omega_rad_s"] = {s.impact.omega.x(), s.impact.omega.y(), s.impact.omega.z()};
  j["ensemble"] = {{"mode", "sampled"},
                   {"method", kCorTableEnsemble},
                   {"drops_per_speed", s.drops}, {"seed", s.seed}};
  j["speeds_m_s"] = s.speeds;
  j["probabilities"] = t.probabilities;
  json rows = json::array();
  for (const auto& r : t.rows) {
    json x = {{"speed_m_s", r.speed}, {"samples", r.samples}, {"core_contacts", r.core_contacts},
              {"eps_n", r.eps_n}, {"mean", r.mean}, {"std", r.std},
              {"omega_x_after", {{"mean", r.omega_x_mean}, {"std", r.omega_x_std}, {"quantiles", r.omega_x_quantiles}}}};
    if (r.fitted)
      x["eq2_fit"] = {{"m", r.fit.law.m}, {"a", r.fit.law.a()}, {"c", r.fit.law.c()},
                      {"se_m", finite_or_null(r.fit.m.se)}, {"se_a", finite_or_null(r.fit.a.se)},
                      {"se_c", finite_or_null(r.fit.c.se)}, {"log_likelihood", r.fit.log_likelihood}};
    else
      x["eq2_fit"] = {{"skipped", r.fit_note}};
    rows.push_back(std::move(x));
  }
  j["rows"] = std::move(rows);
  return j.dump(2) + "\n";
}

std::vector<std::filesystem::path> write_cor_table(const std::filesystem::path& csv, const CorTable& t) {
  auto header = csv;
  header.replace_extension(".json");
  if (header == csv) throw std::invalid_argument("cor_table: the table file must not end in .json: " + csv.string());
  write_file_atomic(csv, cor_table_csv(t));
  try {
    write_file_atomic(header, cor_table_json(t));
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(csv, ec);
    throw;
  }
  return {csv, header};
}

}  // namespace asperity
