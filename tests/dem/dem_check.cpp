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
//   dem_check bounce TABLE IMPACTS_LOG
//     Balls bouncing on the plate: impact k's achieved eps = u_{k+1}/u_k (the flight is ballistic:
//     the next approach speed is the lift-off speed). Residual rho = eps - eps_n(u_k) against the
//     product's Sec. V law (bounce_residual_laws) for this sphere without spin -- every DEM impact is
//     a first impact, the ball never spins -- i.e. Eq. 2 with left rate 1/a1(u) and no right tail:
//     KS of the probability-integral transform (accept at alpha = 0.01), the same with a1 x 1.1
//     (must be rejected), and the ML fit of Eq. 2 to rho/a1(u): left rate 1 within 4 se, right rate
//     > 20x the left one; every |achieved - drawn| < 2e-4.
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
  int type;  // 1: started on the left, moving +x; 2: on the right
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

asperity::KsResult ks_uniform(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  return asperity::ks_one_sample(x, [](double v) { return v < 0 ? 0.0 : (v > 1 ? 1.0 : v); });
}

int headon(const asperity_cor_table& t, const std::string& log, const std::string& dump, double speed, bool expect_accept) {
  const auto contacts = read_log(log);
  const auto vx = read_dump(dump);
  std::vector<double> pit_achieved, pit_drawn;
  double max_diff = 0.0, sum = 0.0, bias = 0.0, bias2 = 0.0;
  for (const auto& c : contacts) {
    const auto i = vx.find(c.a), j = vx.find(c.b);
    if (i == vx.end() || j == vx.end()) throw std::runtime_error("contact of an atom missing from the dump");
    if (i->second.type == j->second.type) throw std::runtime_error("a contact between two atoms of one side");
    // after the collision the right sphere (type 2) moves +x relative to the left one
    const double sign = i->second.type == 1 ? 1.0 : -1.0;
    const double achieved = sign * (j->second.vx - i->second.vx) / speed;
    bias += achieved - c.eps;
    bias2 += (achieved - c.eps) * (achieved - c.eps);
    max_diff = std::max(max_diff, std::fabs(achieved - c.eps));
    sum += achieved;
    pit_achieved.push_back(table_cdf(t, speed, achieved));
    pit_drawn.push_back(table_cdf(t, speed, c.eps));
  }
  if (contacts.empty()) throw std::runtime_error("no contacts in " + log);
  const auto ka = ks_uniform(pit_achieved), kd = ks_uniform(pit_drawn);
  const bool accepted = ka.p >= kAlpha;
  std::printf("headon: n = %zu collisions at %.6g m/s; mean achieved eps %.8f; table eps_n(u) at p = 1: %.8f\n",
              contacts.size(), speed, sum / contacts.size(), asperity_cor_sample(&t, speed, 1.0));
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

int bounce(const std::string& log) {
  auto contacts = read_log(log);
  std::stable_sort(contacts.begin(), contacts.end(), [](const Contact& x, const Contact& y) {
    return x.a != y.a ? x.a < y.a : x.step < y.step;
  });
  std::vector<double> pit, pit_wrong, scaled;
  double max_diff = 0.0, umin = 1e300, umax = 0.0;
  for (std::size_t k = 0; k + 1 < contacts.size(); ++k) {
    if (contacts[k + 1].a != contacts[k].a) continue;  // a ball's last impact has no lift-off speed
    const double u = contacts[k].vn, achieved = contacts[k + 1].vn / u;
    max_diff = std::max(max_diff, std::fabs(achieved - contacts[k].eps));
    const auto law = asperity::bounce_residual_laws(rough_sphere(u), 1).at(0);
    const double rho = achieved - law.eps_n;
    pit.push_back(law.cdf(rho));
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
  std::printf("bounce: max |achieved - drawn| = %.3g (bound 2e-4)\n", max_diff);
  return ok_law && wrong_rejected && ok_rate && one_sided && max_diff < 2e-4 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (!((mode == "headon" && argc == 7) || (mode == "bounce" && argc == 4))) {
      std::fprintf(stderr,
                   "usage: dem_check headon TABLE CONTACTS_LOG FINAL_DUMP SPEED accept|reject\n"
                   "       dem_check bounce TABLE IMPACTS_LOG\n");
      return 2;
    }
    asperity_cor_table t;
    char err[512];
    if (asperity_cor_load(&t, argv[2], err, sizeof err) != 0) throw std::runtime_error(err);
    int rc;
    if (mode == "headon") {
      const std::string expect = argv[6];
      if (expect != "accept" && expect != "reject") throw std::runtime_error("expectation must be accept or reject");
      rc = headon(t, argv[3], argv[4], std::atof(argv[5]), expect == "accept");
    } else {
      rc = bounce(argv[3]);
    }
    asperity_cor_free(&t);
    std::printf("dem_check %s: %s\n", mode.c_str(), rc == 0 ? "as expected" : "NOT as expected");
    return rc;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dem_check: %s\n", e.what());
    return 2;
  }
}
