// SPDX-License-Identifier: GPL-3.0-or-later
#include "checked_text.hpp"
#include "asperity/app/cor_table.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "app/io/atomic_file.hpp"
#include "asperity/config.hpp"
#include "asperity/core/restitution.hpp"
#include "asperity/cor_table.h"
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
  spec.spins = c.spins;
  spec.omega_bands = c.omega_bands;
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
  for (std::size_t i = 0; i < c.spins.size(); ++i) {
    const double w = c.spins[i];
    if (!std::isfinite(w) || std::abs(w) > 1e6) bad("spins[" + std::to_string(i) + "]", num(w), "must be finite, |spin| <= 1e6 rad/s");
    if (i > 0 && !(w > c.spins[i - 1])) bad("spins[" + std::to_string(i) + "]", num(w), "spins must be strictly ascending");
  }
  if (c.spins.size() > 1000) bad("spins", std::to_string(c.spins.size()) + " values", "at most 1000 spins");
  if (c.omega_bands > 1000 || (c.omega_bands > 0 && 2 * c.omega_bands > c.drops))
    bad("omega_bands", std::to_string(c.omega_bands), "must be in [0, 1000] and at most drops / 2");
  if (!(c.impact.beta > 0) || !std::isfinite(c.impact.beta)) bad("beta", num(c.impact.beta), "must be finite and > 0");
}

namespace {

// Omega'_x quantiles of the drops in each of `bands` equiprobable bands of eps (ranked by eps,
// ties by drop index so the bands do not depend on the sort).
std::vector<std::vector<double>> omega_band_quantiles(const ContactSamples& s, std::size_t bands,
                                                      const std::vector<double>& probabilities) {
  std::vector<std::size_t> order(s.eps.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return s.eps[a] < s.eps[b] || (s.eps[a] == s.eps[b] && a < b); });
  std::vector<std::vector<double>> out;
  const std::size_t n = order.size();
  for (std::size_t b = 0; b < bands; ++b) {
    std::vector<double> w;
    for (std::size_t r = b * n / bands; r < (b + 1) * n / bands; ++r) w.push_back(s.omega_x_after[order[r]]);
    std::sort(w.begin(), w.end());
    std::vector<double> q;
    for (const double p : probabilities) q.push_back(quantile_sorted(w, p));
    out.push_back(std::move(q));
  }
  return out;
}

// One (spin, speed) row: its drops, quantiles, moments and Eq. 2 fit. `where` names it in errors.
CorTableRow make_row(const CorTableSpec& spec, const Vec3& omega, double speed, const std::vector<double>& probabilities,
                     const Progress& progress, const std::string& where) {
  EnsembleConfig c;
  c.sphere = spec.sphere;
  c.mode = Mode::sampled;  // the exact finite-N law of the lowest asperity (the header says so)
  c.drops = spec.drops;
  c.seed = spec.seed;
  c.threads = spec.threads;
  c.impact = spec.impact;
  c.impact.enabled = true;
  c.impact.speed = speed;
  c.impact.omega = omega;
  ContactSamples s = run_contact_ensemble(c, progress);
  CorTableRow row;
  row.spin = omega.x();
  row.speed = speed;
  row.samples = s.eps.size();
  row.eps_n = (*viscoelastic_pade14(spec.impact.beta))(speed);
  row.core_contacts = static_cast<std::uint64_t>(std::count(s.eps_core.begin(), s.eps_core.end(), std::uint8_t{1}));
  if (s.eps.size() < std::max<std::size_t>(2, 2 * spec.omega_bands)) bad(where, num(speed), "too few drops approached the plate");
  if (spec.omega_bands > 0) row.omega_x_band_quantiles = omega_band_quantiles(s, spec.omega_bands, probabilities);
  std::sort(s.eps.begin(), s.eps.end());
  std::sort(s.omega_x_after.begin(), s.omega_x_after.end());
  for (const double p : probabilities) {
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
  return row;
}

}  // namespace

CorTable make_cor_table(const CorTableSpec& spec, const Progress& progress) {
  validate(spec);
  CorTable t;
  t.spec = spec;
  const std::size_t P = spec.probabilities;
  for (std::size_t j = 0; j < P; ++j) t.probabilities.push_back(static_cast<double>(j) / static_cast<double>(P - 1));
  std::vector<Vec3> omegas;
  if (spec.spins.empty()) omegas.push_back(spec.impact.omega);
  for (const double w : spec.spins) omegas.push_back(Vec3(w, 0, 0));
  const std::uint64_t total = spec.drops * spec.speeds.size() * omegas.size();
  std::uint64_t offset = 0;
  for (const Vec3& omega : omegas)
    for (std::size_t i = 0; i < spec.speeds.size(); ++i) {
      Progress p;
      if (progress) p = [&](std::uint64_t done, std::uint64_t) { progress(offset + done, total); };
      t.rows.push_back(make_row(spec, omega, spec.speeds[i], t.probabilities, p, "speeds[" + std::to_string(i) + "]"));
      offset += spec.drops;
      // The ensemble reports from its thread 0 only, which may get no chunk of a small run: one
      // report per row from here, so progress (and a Python binding's Ctrl-C check) always runs.
      if (progress) progress(offset, total);
    }
  return t;
}

namespace {

void write_quantiles(std::ostream& o, const std::vector<double>& q) {
  for (const double x : q) o << "," << num(x);
  o << "\n";
}

}  // namespace

std::string cor_table_csv(const CorTable& t) {
  std::ostringstream o;
  const int format = t.format();
  // Line 1 states the counts, so a reader can refuse a table that lost rows or blocks
  // (include/asperity/cor_table.h, "THE FORMAT"); the values must lie in the ranges it states.
  const std::size_t speeds = t.spec.speeds.size(), spins = speeds ? t.rows.size() / speeds : 0;
  const std::size_t bands = t.rows.empty() ? 0 : t.rows.front().omega_x_band_quantiles.size();
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const auto& r = t.rows[i];
    for (const double e : r.quantiles)
      if (!(e >= 0.0 && e <= ASPERITY_COR_EPS_MAX)) bad("rows[" + std::to_string(i) + "] eps", num(e), "outside [0, 1000]: not a restitution table");
    for (const auto& q : r.omega_x_band_quantiles)
      for (const double w : q)
        if (!(std::abs(w) <= ASPERITY_COR_OMEGA_MAX)) bad("rows[" + std::to_string(i) + "] Omega'_x", num(w), "outside [-1e15, 1e15] rad/s");
    if (r.omega_x_band_quantiles.size() != bands) bad("omega_bands", std::to_string(bands), "differs between rows");
  }
  o << "# asperity-cor-table format=" << format;
  if (format == 1) o << " speeds=" << t.rows.size() << " probabilities=" << t.probabilities.size() << "\n";
  else
    o << " spins=" << spins << " speeds=" << speeds << " probabilities=" << t.probabilities.size() << " bands=" << bands << "\n";
  if (format == 1)
    o << "# eps quantiles: row = impact speed [m/s], column p = probability; sample eps by bilinear\n"
      << "# interpolation in (speed, p) with a uniform u (include/asperity/cor_table.h). Header: the .json file.\n";
  else
    o << "# eps quantiles per incoming spin Omega_x [rad/s] and impact speed [m/s], then Omega'_x quantiles per\n"
      << "# eps band (omega_x:<b>); sample with include/asperity/cor_table.h. Header: the .json file.\n";
  o << "# N=" << t.spec.sphere.asperities << " R=" << num(t.spec.sphere.radius) << " a=" << num(t.spec.sphere.asperity_radius)
    << " beta=" << num(t.spec.impact.beta) << " eps_t=" << num(t.spec.impact.eps_t) << " Omega=" << num(t.spec.impact.omega.x())
    << "," << num(t.spec.impact.omega.y()) << "," << num(t.spec.impact.omega.z()) << " seed=" << t.spec.seed
    << " drops=" << t.spec.drops << " version=" << ASPERITY_VERSION << "\n";
  o << (format == 1 ? "speed_m_s" : "spin_rad_s,speed_m_s,row");
  for (const double p : t.probabilities) o << ",p=" << num(p);
  o << "\n";
  for (const auto& r : t.rows) {
    if (format == 1) {
      o << num(r.speed);
      write_quantiles(o, r.quantiles);
      continue;
    }
    o << num(r.spin) << "," << num(r.speed) << ",eps";
    write_quantiles(o, r.quantiles);
    for (std::size_t b = 0; b < r.omega_x_band_quantiles.size(); ++b) {
      o << num(r.spin) << "," << num(r.speed) << ",omega_x:" << b;
      write_quantiles(o, r.omega_x_band_quantiles[b]);
    }
  }
  return detail::checked_text(std::move(o), "the restitution table");
}

std::string cor_table_json(const CorTable& t) {
  using nlohmann::json;
  const auto& s = t.spec;
  json j;
  j["format"] = "asperity-cor-table";
  j["format_version"] = t.format();
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
  if (t.format() == kCorTableFormatVersionSpins) {
    std::vector<double> spins;
    for (const auto& r : t.rows)
      if (spins.empty() || r.spin != spins.back()) spins.push_back(r.spin);
    j["spins_rad_s"] = spins;  // incoming Omega = (spin, 0, 0); the scene's Omega when none were asked for
    j["omega_bands"] = s.omega_bands;
  }
  j["probabilities"] = t.probabilities;
  json rows = json::array();
  for (const auto& r : t.rows) {
    json x = {{"spin_rad_s", r.spin}, {"speed_m_s", r.speed}, {"samples", r.samples}, {"core_contacts", r.core_contacts},
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
