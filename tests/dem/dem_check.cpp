// SPDX-License-Identifier: GPL-3.0-or-later
// Checks what LAMMPS (with the asperity coupling, src/dem/lammps) did against asperity's own laws.
//
//   dem_check headon TABLE CONTACTS_LOG FINAL_DUMP SPEED accept|reject
//     10^4 head-on pairs: achieved eps = -(v_j - v_i)'/speed per pair, from the final velocities.
//     Each achieved eps goes through the table's cdf at SPEED (the header's sampler inverted by
//     bisection); the values must be U(0, 1): one-sample KS, alpha = 0.01. "accept": p >= 0.01,
//     every |achieved - drawn| < 3e-4 and their mean below 5e-6 in size (the velocity-Verlet error at
//     1000 steps per contact: mean ~0, sd 4e-5, random with the contact's phase in the time step;
//     docs/dem-coupling.md); "reject" (a run with deliberately scaled damping): p < 0.01.
//   dem_check headon_ref REF CONTACTS_LOG FINAL_DUMP SPEED accept|reject TABLE_DROPS REF_DROPS
//     The same, but the law checked against is REF: a one-speed table generated independently at
//     exactly SPEED (its own seed), read here by a parser of its own (not the header's reader, not its
//     interpolation), its cdf the piecewise-linear inverse of its quantiles. The run draws from the
//     42-speed table at a SPEED between two of its rows: an error of the header's reader or of its
//     interpolation in speed or p shows here, where a check through the same header would share it.
//     A REF whose speed is not SPEED (to 1e-9) is refused (exit 2). Both tables are samples (TABLE_DROPS
//     drops per row of the drawing table, REF_DROPS of REF): their laws differ by sampling noise, so the
//     KS p-value is taken at n_eff = (1/n + 1/TABLE_DROPS + 1/REF_DROPS)^-1 (n the collisions), the
//     usual effective size of a comparison of independent samples.
//   dem_check bounce TABLE IMPACTS_LOG [accept|reject]
//     Balls bouncing on the plate: impact k's achieved eps = u_{k+1}/u_k (the flight is ballistic:
//     the next approach speed is the lift-off speed). Residual rho = eps - eps_n(u_k) against the
//     product's Sec. V law (bounce_residual_laws) for this sphere without spin -- every DEM impact is
//     a first impact, the ball never spins -- i.e. Eq. 2 with left rate 1/a1(u) and no right tail:
//     KS of the probability-integral transform (accept at alpha = 0.01), the same with a1 x 1.1
//     (must be rejected), and the ML fit of Eq. 2 to rho/a1(u): left rate 1 within 4 se, mode 0
//     within 4 se, right rate > 20x the left one; every |achieved - drawn| < 2e-4; and per band of
//     u between two table rows holding >= 50 impacts, KS of the same transform at alpha = 0.01 / bands
//     (Bonferroni): a wrong row (two rows swapped) moves one band's law while the pooled KS, over all
//     41 bands, stays blind to it. "reject" (a run from a damaged table): some check must fail.
// The sphere is examples/dem/rough-sphere.toml's (N = 1000, R = 3 mm, a = 0.1 mm, beta = 0.0467).
// Exit 0: the expectation holds; 1: it does not; 2: bad input.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "asperity/cor_table.h"
#include "asperity/laws/laplace.hpp"
#include "asperity/laws/statistics.hpp"
#include "asperity/laws/theory_impact.hpp"

namespace {

constexpr double kAlpha = 0.01;

struct Contact {
  long long step;
  unsigned long long a, b;
  double vn, u, eps;
};

std::vector<Contact> read_log(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::vector<Contact> out;
  std::string line, kind;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    Contact c;
    double gamma;
    if (!(s >> c.step >> kind >> c.a >> c.b >> c.vn >> c.u >> c.eps >> gamma))
      throw std::runtime_error(path + ": bad line '" + line + "'");
    out.push_back(c);
  }
  return out;
}

struct Atom {
  int type;  // 2: started on the right, moving -x; any other (1, 3): on the left
  double vx;
};

// id -> (type, vx) from a LAMMPS custom dump "id type vx".
std::map<unsigned long long, Atom> read_dump(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::map<unsigned long long, Atom> vx;
  std::string line;
  bool atoms = false;
  while (std::getline(in, line)) {
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      atoms = true;
      continue;
    }
    if (!atoms) continue;
    std::istringstream s(line);
    unsigned long long id;
    int type;
    double v;
    if (!(s >> id >> type >> v)) throw std::runtime_error(path + ": bad atom line '" + line + "'");
    vx[id] = Atom{type, v};
  }
  return vx;
}

// The table's cdf at `speed`: the u whose sample is eps (bisection; the sampler is nondecreasing in u).
double table_cdf(const asperity_cor_table& t, double speed, double eps) {
  double lo = 0.0, hi = 1.0;
  if (eps <= asperity_cor_sample(&t, speed, 0.0)) return 0.0;
  if (eps >= asperity_cor_sample(&t, speed, 1.0)) return 1.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (asperity_cor_sample(&t, speed, mid) <= eps ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// REF: a one-speed format-1 table read without the header: line 1 "# asperity-cor-table format=1
// speeds=1 probabilities=P", '#' comments, the column header "speed_m_s,p=...", one row. Checked:
// P probabilities from 0 to 1 ascending, P quantiles nondecreasing.
struct RefLaw {
  double speed = 0;
  std::vector<double> p, q;
  double cdf(double eps) const {  // the inverse of the piecewise-linear quantile function
    if (eps < q.front()) return 0.0;
    if (eps >= q.back()) return 1.0;
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(q.begin(), q.end(), eps) - q.begin());  // q[k-1] <= eps < q[k]
    const double w = (eps - q[k - 1]) / (q[k] - q[k - 1]);
    return p[k - 1] + w * (p[k] - p[k - 1]);
  }
};

std::vector<double> split_numbers(const std::string& line, const std::string& path, bool strip_p) {
  std::vector<double> out;
  std::istringstream s(line);
  std::string cell;
  while (std::getline(s, cell, ',')) {
    if (strip_p) {
      if (cell.rfind("p=", 0) != 0) throw std::runtime_error(path + ": header cell '" + cell + "' is not p=...");
      cell = cell.substr(2);
    }
    std::size_t used = 0;
    const double x = std::stod(cell, &used);
    if (used != cell.size()) throw std::runtime_error(path + ": '" + cell + "' is not a number");
    out.push_back(x);
  }
  return out;
}

RefLaw read_ref(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::string line;
  std::getline(in, line);
  if (line.rfind("# asperity-cor-table format=1 speeds=1 ", 0) != 0)
    throw std::runtime_error(path + ": not a one-speed format-1 table ('" + line + "')");
  RefLaw r;
  std::vector<std::string> rows;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#') rows.push_back(line);
  if (rows.size() != 2) throw std::runtime_error(path + ": expected a header and one row");
  if (rows[0].rfind("speed_m_s,", 0) != 0) throw std::runtime_error(path + ": bad column header");
  r.p = split_numbers(rows[0].substr(10), path, true);
  const auto row = split_numbers(rows[1], path, false);
  if (row.size() != r.p.size() + 1 || r.p.size() < 2) throw std::runtime_error(path + ": row and header differ in length");
  r.speed = row[0];
  r.q.assign(row.begin() + 1, row.end());
  if (r.p.front() != 0.0 || r.p.back() != 1.0) throw std::runtime_error(path + ": p must run from 0 to 1");
  for (std::size_t k = 1; k < r.p.size(); ++k)
    if (!(r.p[k] > r.p[k - 1]) || r.q[k] < r.q[k - 1]) throw std::runtime_error(path + ": p or eps not ascending");
  return r;
}

asperity::KsResult ks_uniform(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  return asperity::ks_one_sample(x, [](double v) { return v < 0 ? 0.0 : (v > 1 ? 1.0 : v); });
}

template <class Cdf>
int headon(const Cdf& cdf, double top, const std::string& log, const std::string& dump, double speed, bool expect_accept,
           double extra_inv_n = 0.0) {
  const auto contacts = read_log(log);
  const auto vx = read_dump(dump);
  std::vector<double> pit_achieved, pit_drawn;
  double max_diff = 0.0, sum = 0.0, bias = 0.0, bias2 = 0.0;
  for (const auto& c : contacts) {
    const auto i = vx.find(c.a), j = vx.find(c.b);
    if (i == vx.end() || j == vx.end()) throw std::runtime_error("contact of an atom missing from the dump");
    if ((i->second.type == 2) == (j->second.type == 2)) throw std::runtime_error("a contact between two atoms of one side");
    // after the collision the right sphere (type 2) moves +x relative to the left one
    const double sign = i->second.type != 2 ? 1.0 : -1.0;
    const double achieved = sign * (j->second.vx - i->second.vx) / speed;
    bias += achieved - c.eps;
    bias2 += (achieved - c.eps) * (achieved - c.eps);
    max_diff = std::max(max_diff, std::fabs(achieved - c.eps));
    sum += achieved;
    pit_achieved.push_back(cdf(achieved));
    pit_drawn.push_back(cdf(c.eps));
  }
  if (contacts.empty()) throw std::runtime_error("no contacts in " + log);
  auto ka = ks_uniform(pit_achieved), kd = ks_uniform(pit_drawn);
  if (extra_inv_n > 0.0) {  // the reference is itself a sample: the p-value at the effective size
    const double n_eff = 1.0 / (1.0 / static_cast<double>(contacts.size()) + extra_inv_n);
    ka.p = asperity::kolmogorov_pvalue(ka.D, static_cast<std::size_t>(n_eff));
    kd.p = asperity::kolmogorov_pvalue(kd.D, static_cast<std::size_t>(n_eff));
    std::printf("headon: n = %zu against sampled tables: KS p at n_eff = %.0f\n", contacts.size(), n_eff);
  }
  const bool accepted = ka.p >= kAlpha;
  std::printf("headon: n = %zu collisions at %.6g m/s; mean achieved eps %.8f; table eps_n(u) at p = 1: %.8f\n",
              contacts.size(), speed, sum / contacts.size(), top);
  std::printf("headon: achieved eps vs the table's law: KS D = %.5f, p = %.3g (alpha %.2g): %s\n", ka.D, ka.p, kAlpha,
              accepted ? "accepted" : "rejected");
  std::printf("headon: drawn eps vs the table's law: KS D = %.5f, p = %.3g\n", kd.D, kd.p);
  bias /= static_cast<double>(contacts.size());
  const double sd = std::sqrt(std::max(0.0, bias2 / static_cast<double>(contacts.size()) - bias * bias));
  std::printf("headon: achieved - drawn: mean %.3g (bound 5e-6), sd %.3g, max |.| %.3g (bound 3e-4)\n", bias, sd, max_diff);
  if (expect_accept) return accepted && max_diff < 3e-4 && std::fabs(bias) < 5e-6 ? 0 : 1;
  return accepted ? 1 : 0;
}

asperity::ImpactScene rough_sphere(double speed) {
  asperity::ImpactScene s;
  s.asperities = 1000;
  s.radius = 3e-3;
  s.asperity_radius = 1e-4;
  s.beta = 0.0467;
  s.omega_x = s.omega_y = 0.0;
  s.speed = speed;
  return s;
}

int bounce(const asperity_cor_table& t, const std::string& log, bool expect_accept) {
  auto contacts = read_log(log);
  std::stable_sort(contacts.begin(), contacts.end(), [](const Contact& x, const Contact& y) {
    return x.a != y.a ? x.a < y.a : x.step < y.step;
  });
  std::vector<double> pit, pit_wrong, scaled;
  std::map<int, std::vector<double>> bands;  // the transform per interval between two table rows
  double max_diff = 0.0, umin = 1e300, umax = 0.0;
  for (std::size_t k = 0; k + 1 < contacts.size(); ++k) {
    if (contacts[k + 1].a != contacts[k].a) continue;  // a ball's last impact has no lift-off speed
    const double u = contacts[k].vn, achieved = contacts[k + 1].vn / u;
    max_diff = std::max(max_diff, std::fabs(achieved - contacts[k].eps));
    const auto law = asperity::bounce_residual_laws(rough_sphere(u), 1).at(0);
    const double rho = achieved - law.eps_n;
    pit.push_back(law.cdf(rho));
    const int band = static_cast<int>(std::upper_bound(t.speeds, t.speeds + t.n_speeds, u) - t.speeds);
    bands[band].push_back(pit.back());
    auto wrong = law;
    wrong.a1 *= 1.1;  // a deliberately wrong law: the predicted scale 10% too wide
    pit_wrong.push_back(wrong.cdf(rho));
    scaled.push_back(rho / law.a1);
    umin = std::min(umin, u), umax = std::max(umax, u);
  }
  if (pit.size() < 100) throw std::runtime_error("too few impacts in " + log);
  const auto k = ks_uniform(pit), kw = ks_uniform(pit_wrong);
  const auto fit = asperity::fit_asymmetric_laplace(scaled);
  const bool ok_law = k.p >= kAlpha, wrong_rejected = kw.p < kAlpha;
  const bool ok_rate = std::fabs(fit.a.value - 1.0) < 4.0 * fit.a.se, one_sided = fit.c.value > 20.0 * fit.a.value;
  const bool ok_mode = std::fabs(fit.m.value) < 4.0 * fit.m.se;
  std::size_t tested = 0;
  for (const auto& b : bands) tested += b.second.size() >= 50;
  const double alpha_band = kAlpha / static_cast<double>(std::max<std::size_t>(tested, 1));
  double p_min = 1.0;
  int worst = -1;
  std::size_t worst_n = 0;
  for (const auto& b : bands) {
    if (b.second.size() < 50) continue;
    const auto kb = ks_uniform(b.second);
    if (kb.p < p_min) p_min = kb.p, worst = b.first, worst_n = b.second.size();
  }
  const bool ok_bands = p_min >= alpha_band;
  std::printf("bounce: n = %zu impacts, u in [%.4g, %.4g] m/s\n", pit.size(), umin, umax);
  std::printf("bounce: residual eps - eps_n(u) vs the Sec. V law (k = 1, no spin): KS D = %.5f, p = %.3g: %s\n", k.D, k.p,
              ok_law ? "accepted" : "rejected");
  std::printf("bounce: the same law with a1 x 1.1 (wrong): KS D = %.5f, p = %.3g: %s\n", kw.D, kw.p,
              wrong_rejected ? "rejected" : "ACCEPTED");
  std::printf("bounce: Eq. 2 fitted to residual/a1(u): mode %.4g +- %.2g, left rate a = %.4f +- %.4f (predicted 1), "
              "right rate c = %.4g (predicted infinite)\n",
              fit.m.value, fit.m.se, fit.a.value, fit.a.se, fit.c.value);
  for (const double u : {1.0, 0.3, 0.1}) {
    const auto law = asperity::bounce_residual_laws(rough_sphere(u), 1).at(0);
    std::printf("bounce: Sec. V law at u = %.1f m/s: eps_n = %.6f, left rate 1/a1 = %.1f, right rate %g\n", u, law.eps_n,
                law.rate_below(), law.rate_above());
  }
  std::printf("bounce: mode %s (|m| < 4 se), left rate %s (|a - 1| < 4 se), right tail %s (c > 20 a)\n",
              ok_mode ? "ok" : "OFF", ok_rate ? "ok" : "OFF", one_sided ? "absent" : "PRESENT");
  if (worst >= 0)
    std::printf("bounce: %zu bands of u between table rows with >= 50 impacts; the worst, u in [%.4g, %.4g] m/s "
                "(n = %zu): KS p = %.3g (Bonferroni threshold %.2g): %s\n",
                tested, worst > 0 ? t.speeds[worst - 1] : 0.0, worst < t.n_speeds ? t.speeds[worst] : INFINITY, worst_n, p_min,
                alpha_band, ok_bands ? "accepted" : "rejected");
  std::printf("bounce: max |achieved - drawn| = %.3g (bound 2e-4)\n", max_diff);
  const bool all = ok_law && wrong_rejected && ok_rate && ok_mode && one_sided && ok_bands && max_diff < 2e-4;
  return (all == expect_accept) ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (!((mode == "headon" && argc == 7) || (mode == "headon_ref" && argc == 9) || (mode == "bounce" && (argc == 4 || argc == 5)))) {
      std::fprintf(stderr,
                   "usage: dem_check headon TABLE CONTACTS_LOG FINAL_DUMP SPEED accept|reject\n"
                   "       dem_check headon_ref REF_ONE_SPEED_TABLE CONTACTS_LOG FINAL_DUMP SPEED accept|reject TABLE_DROPS REF_DROPS\n"
                   "       dem_check bounce TABLE IMPACTS_LOG [accept|reject]\n");
      return 2;
    }
    const std::string expect = mode == "bounce" ? (argc == 5 ? argv[4] : "accept") : argv[6];
    if (expect != "accept" && expect != "reject") throw std::runtime_error("expectation must be accept or reject");
    int rc;
    if (mode == "headon_ref") {
      const RefLaw ref = read_ref(argv[2]);
      const double speed = std::atof(argv[5]);
      if (!(std::fabs(ref.speed - speed) <= 1e-9 * speed))
        throw std::runtime_error(std::string(argv[2]) + " is the law at " + std::to_string(ref.speed) + " m/s, not at " + argv[5]);
      const double drops_table = std::atof(argv[7]), drops_ref = std::atof(argv[8]);
      if (!(drops_table >= 1.0 && drops_ref >= 1.0)) throw std::runtime_error("TABLE_DROPS and REF_DROPS must be >= 1");
      rc = headon([&](double e) { return ref.cdf(e); }, ref.q.back(), argv[3], argv[4], speed, expect == "accept",
                  1.0 / drops_table + 1.0 / drops_ref);
    } else {
      asperity_cor_table t;
      char err[512];
      if (asperity_cor_load(&t, argv[2], err, sizeof err) != 0) throw std::runtime_error(err);
      if (mode == "headon") {
        const double speed = std::atof(argv[5]);
        rc = headon([&](double e) { return table_cdf(t, speed, e); }, asperity_cor_sample(&t, speed, 1.0), argv[3], argv[4],
                    speed, expect == "accept");
      } else {
        rc = bounce(t, argv[3], expect == "accept");
      }
      asperity_cor_free(&t);
    }
    std::printf("dem_check %s: %s\n", mode.c_str(), rc == 0 ? "as expected" : "NOT as expected");
    return rc;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dem_check: %s\n", e.what());
    return 2;
  }
}
