#include "asperity/body_experiments.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "format.hpp"

#include "asperity/plot.hpp"
#include "asperity/report.hpp"
#include "asperity/screening.hpp"
#include "asperity/support.hpp"
#include "asperity/theory.hpp"
#include "asperity/theory_radii.hpp"

namespace asperity {
namespace {

using detail::num;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<double> sorted_copy(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v;
}

LawCheck ks_check(const std::string& quantity, const std::vector<double>& sorted, const Law& law, double lambda,
                  double alpha, bool power, std::string note = {}) {
  LawCheck c;
  c.quantity = quantity;
  c.law = law.name;
  c.lambda = lambda;
  c.ks = ks_one_sample(sorted, law.cdf);
  c.power_check = power;
  c.verdict = c.ks.p < alpha ? "reject" : "accept";
  c.note = std::move(note);
  return c;
}

Curve curve_of(const Law& law, const std::string& label, double lo, double hi) {
  Curve c;
  c.label = label;
  for (int i = 0; i <= 300; ++i) {
    const double t = lo + (hi - lo) * i / 300.0;
    const double y = law.pdf(t);
    c.x.push_back(t);
    c.y.push_back(std::isfinite(y) ? y : 0.0);
  }
  return c;
}

nlohmann::json json_of(const Estimate& e) { return {{"value", e.value}, {"se", e.se}}; }
nlohmann::json json_of(const LawCheck& c) {
  return {{"quantity", c.quantity}, {"law", c.law},     {"lambda", c.lambda},           {"statistic", "KS"},
          {"D", c.ks.D},            {"p", c.ks.p},       {"n", c.ks.n},                  {"power_check", c.power_check},
          {"verdict", c.verdict},   {"note", c.note}};
}

}  // namespace

void validate(const RadiiExperiment& e) {
  if (e.asperities < 1 || e.asperities > 0xffffffffull)
    throw std::invalid_argument("asperities must be in [1, 2^32-1], got " + std::to_string(e.asperities));
  if (!std::isfinite(e.radius) || e.radius <= 0)
    throw std::invalid_argument("radius must be a finite number > 0 m, got " + num(e.radius));
  validate(e.radii);
  if (e.radii.kind == RadiusDistribution::Kind::lognormal)
    throw std::invalid_argument("radii: the radii experiment needs fixed or level radii (exact law), got " +
                                e.radii.describe());
  if (e.drops < 2) throw std::invalid_argument("drops must be >= 2, got " + std::to_string(e.drops));
  if (!(e.alpha > 0 && e.alpha < 1)) throw std::invalid_argument("alpha must be in (0,1), got " + num(e.alpha));
}

RadiiReport run_radii_experiment(const RadiiExperiment& e) {
  validate(e);
  RadiiReport r;
  r.experiment = e;
  const double R = e.radius, area = 4.0 * std::numbers::pi * R * R;
  r.lambda = static_cast<double>(e.asperities) / area;
  std::vector<double> lv = e.radii.kind == RadiusDistribution::Kind::levels ? e.radii.levels
                                                                            : std::vector<double>{e.radii.radius};
  std::vector<double> fr = e.radii.kind == RadiusDistribution::Kind::levels ? e.radii.fractions
                                                                            : std::vector<double>{1.0};
  const std::size_t top = static_cast<std::size_t>(std::max_element(lv.begin(), lv.end()) - lv.begin());
  r.lambda_top = r.lambda * fr[top];

  // (1) Screening of explicit bodies.
  auto t0 = std::chrono::steady_clock::now();
  SphereParams p;
  p.asperities = e.asperities;
  p.radius = R;
  std::vector<double> lam_eff;
  std::vector<double> kept_by(lv.size(), 0), total_by(lv.size(), 0);
  for (std::uint64_t k = 0; k < e.screen_bodies; ++k) {
    const RoughBody b = make_rough_sphere_body(p, e.radii, e.seed, k);
    const auto q = make_support_tree(b.centres, b.radii);
    const ScreeningResult s = screen_sphere(b, *q);
    const ScreeningCheck c = check_screening(b, *q, s, e.screen_directions, e.seed + k);
    lam_eff.push_back(s.lambda_eff);
    if (k == 0) r.theta_cover = s.theta_cover;
    r.mean_competitors += s.mean_competitors / static_cast<double>(e.screen_bodies);
    r.witnessed += s.witnessed;
    r.helly += s.helly;
    r.screened += s.screened;
    r.winners_screened += c.winners_screened;
    r.kept_never_hit += c.kept_never_hit;
    r.directions += c.directions;
    for (std::size_t i = 0; i < b.size(); ++i) {
      const std::size_t m = static_cast<std::size_t>(std::find(lv.begin(), lv.end(), b.radii[i]) - lv.begin());
      if (m >= lv.size()) continue;
      total_by[m] += 1;
      kept_by[m] += s.status[i] != Screen::screened;
    }
  }
  for (std::size_t m = 0; m < lv.size(); ++m) r.kept_fraction_by_level.push_back(total_by[m] > 0 ? kept_by[m] / total_by[m] : kNaN);
  if (!lam_eff.empty()) {
    double m = 0, v = 0;
    for (double x : lam_eff) m += x;
    m /= static_cast<double>(lam_eff.size());
    for (double x : lam_eff) v += (x - m) * (x - m);
    r.lambda_eff.value = m;
    r.lambda_eff.se = lam_eff.size() > 1 ? std::sqrt(v / static_cast<double>(lam_eff.size() - 1) / static_cast<double>(lam_eff.size())) : kNaN;
  }
  r.seconds_screen = seconds_since(t0);

  // (2) Fresh drops: iid, each a pure function of (seed, drop).
  t0 = std::chrono::steady_clock::now();
  const auto n = static_cast<std::int64_t>(e.drops);
  std::vector<double> rx(e.drops), rxy(e.drops);
  std::vector<std::uint32_t> level(e.drops);
  std::vector<std::uint8_t> core(e.drops);
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < n; ++k) {
    const FreshContact c = fresh_levels_contact(e.asperities, R, e.radii, e.seed, static_cast<std::uint64_t>(k));
    const auto i = static_cast<std::size_t>(k);
    rx[i] = c.r.x();
    rxy[i] = std::hypot(c.r.x(), c.r.y());
    level[i] = c.level;
    core[i] = c.core;
  }
  r.seconds_fresh = seconds_since(t0);
  r.winner_level_fraction.assign(lv.size(), 0.0);
  // fresh_levels_contact numbers levels after dropping zero fractions; map back.
  std::vector<std::size_t> nz;
  for (std::size_t m = 0; m < fr.size(); ++m)
    if (fr[m] > 0) nz.push_back(m);
  for (std::size_t i = 0; i < level.size(); ++i) r.winner_level_fraction[nz[level[i]]] += 1.0 / static_cast<double>(e.drops);
  for (auto c : core) r.core_contacts += c;
  const std::vector<double> probs{0.5};
  const Summary sx = summarize_iid(rx, probs);
  r.rx_std = sx.std;
  r.lambda_fit = 1.0 / (2.0 * std::numbers::pi * sx.std.value * sx.std.value);

  // (3) Tests of r_x (the paper's conjecture: Gaussian -- with which lambda?).
  const auto srx = sorted_copy(rx), srxy = sorted_copy(rxy);
  const Law exact = levels_sphere_rx(e.asperities, R, e.radii);
  const Law wrong = levels_sphere_rx(e.asperities, R, e.radii, 1.05);
  const Law g_all = gaussian_rx(r.lambda, "gauss-lambda");
  const Law g_top = gaussian_rx(r.lambda_top, "gauss-lambda-top");
  r.tests.push_back(ks_check("r_x", srx, exact, kNaN, e.alpha, false, "exact finite-N law, level radii"));
  r.tests.push_back(ks_check("r_x", srx, wrong, kNaN, e.alpha, true, "exact law stretched by 5%: must be rejected"));
  r.tests.push_back(ks_check("r_x", srx, g_all, r.lambda, e.alpha, false, "Eq. 18 with all asperities"));
  if (r.lambda_eff.value > 0)
    r.tests.push_back(ks_check("r_x", srx, gaussian_rx(r.lambda_eff.value, "gauss-lambda-eff"), r.lambda_eff.value, e.alpha,
                               false, "Eq. 18 with the density of asperities that can touch (screening)"));
  r.tests.push_back(ks_check("r_x", srx, g_top, r.lambda_top, e.alpha, false, "Eq. 18 with the largest level only"));
  r.tests.push_back(ks_check("r_x", srx, gaussian_rx(r.lambda_fit, "gauss-lambda-fit"), r.lambda_fit, e.alpha, false,
                             "Gaussian with the sample variance (fitted: p is optimistic)"));
  r.tests.push_back(ks_check("r_xy", srxy, levels_sphere_rxy(e.asperities, R, e.radii), kNaN, e.alpha, false,
                             "exact finite-N law of r_xy"));

  // (4) Figures and files.
  std::filesystem::create_directories(e.out);
  if (e.plots && plotting_available()) {
    const double sigma = 1.0 / std::sqrt(2.0 * std::numbers::pi * std::min(r.lambda_top, r.lambda_fit));
    const double hi = 4.0 * sigma;
    HistogramFigure fig;
    std::ostringstream t;
    t << "r_x, N = " << e.asperities << ", radii " << e.radii.describe() << ", " << e.drops << " fresh drops";
    fig.title = t.str();
    fig.xlabel = "r_x [{/Symbol m}m]";
    fig.ylabel = "probability density [1/{/Symbol m}m]";
    fig.x_scale = 1e6;
    fig.y_scale = 1e-6;
    fig.histogram = make_histogram(rx, -hi, hi, 60);
    fig.curves.push_back(curve_of(exact, "exact law, level radii", -hi, hi));
    fig.curves.push_back(curve_of(g_all, "Eq. (18), {/Symbol l} of all asperities", -hi, hi));
    if (r.lambda_eff.value > 0)
      fig.curves.push_back(curve_of(gaussian_rx(r.lambda_eff.value, "g"), "Eq. (18), {/Symbol l}_{eff} (screening)", -hi, hi));
    fig.curves.push_back(curve_of(g_top, "Eq. (18), {/Symbol l} of the largest level", -hi, hi));
    write_histogram_png(e.out / "r_x.png", fig);
    r.plots.push_back("r_x.png");
  }
  write_file_atomic(e.out / "report.json", to_json(r));
  write_file_atomic(e.out / "report.txt", format_table(r));
  return r;
}

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
  os << "fresh drops: " << e.drops << ", touching level fractions:";
  for (double f : r.winner_level_fraction) os << " " << f;
  os << ", core contacts " << r.core_contacts << ", std(r_x) = " << r.rx_std.value << " +- " << r.rx_std.se << " m\n";
  os << std::left << std::setw(6) << "qty" << std::setw(20) << "law" << std::setw(13) << "lambda" << std::setw(11) << "KS D"
     << std::setw(11) << "p" << "verdict\n";
  for (const auto& t : r.tests) {
    os << std::setw(6) << t.quantity << std::setw(20) << t.law << std::setw(13) << t.lambda << std::setw(11) << t.ks.D
       << std::setw(11) << t.ks.p << t.verdict << (t.power_check ? " (power check: must reject)" : "") << "\n";
  }
  return os.str();
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
  j["tests"] = nlohmann::json::array();
  for (const auto& t : r.tests) j["tests"].push_back(json_of(t));
  j["plots"] = r.plots;
  j["seconds_fresh"] = r.seconds_fresh;
  return j.dump(2) + "\n";
}

}  // namespace asperity
