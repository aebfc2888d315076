// SPDX-License-Identifier: GPL-3.0-or-later
// Tangential contact laws (tangential.hpp; derivations in docs/tangential-laws.md).
//
// The impulse process works in the contact frame B = (t1, t2, n): the contact velocity is
// u(P) = u0 + C P with C = B^T K B, K = I/M - [r]x J^-1 [r]x (symmetric positive definite), and the
// normal impulse p = P_n >= 0 is the clock. Per unit p the impulse is (f, 1) with f the tangential
// impulse rate: f = -mu s while slipping along s = u_t/|u_t|, f = tau = -A^-1 a while sticking
// (A = C_tt, a = C_tn), possible when |tau| <= mu. RK4 in p; phase ends (slip -> 0, u_n -> 0, the
// restitution rule) are located by bisection on the step.
#include "asperity/core/tangential.hpp"

#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/format.hpp"

namespace asperity {

using detail::num;

TangentialLaw TangentialLaw::kinematic(double eps_t) {
  TangentialLaw l;
  l.model = Model::kinematic;
  l.eps_t = eps_t;
  return l;
}
TangentialLaw TangentialLaw::coulomb(double mu, Normal normal) {
  TangentialLaw l;
  l.model = Model::coulomb;
  l.mu = mu;
  l.normal = normal;
  return l;
}
TangentialLaw TangentialLaw::walton(double mu, double beta0) {
  TangentialLaw l;
  l.model = Model::walton;
  l.mu = mu;
  l.beta0 = beta0;
  return l;
}
TangentialLaw TangentialLaw::stronge(double mu) { return coulomb(mu, Normal::energetic); }

std::string_view to_string(TangentialLaw::Model m) {
  switch (m) {
    case TangentialLaw::Model::kinematic: return "kinematic";
    case TangentialLaw::Model::coulomb: return "coulomb";
    case TangentialLaw::Model::walton: return "walton";
  }
  return "?";
}
std::string_view to_string(TangentialLaw::Normal n) {
  switch (n) {
    case TangentialLaw::Normal::newton: return "newton";
    case TangentialLaw::Normal::poisson: return "poisson";
    case TangentialLaw::Normal::energetic: return "energetic";
  }
  return "?";
}
TangentialLaw::Model parse_tangential_model(std::string_view s) {
  for (auto m : {TangentialLaw::Model::kinematic, TangentialLaw::Model::coulomb, TangentialLaw::Model::walton})
    if (s == to_string(m)) return m;
  throw std::invalid_argument("unknown tangential model '" + std::string(s) + "' (expected kinematic, coulomb or walton)");
}
TangentialLaw::Normal parse_normal_rule(std::string_view s) {
  for (auto n : {TangentialLaw::Normal::newton, TangentialLaw::Normal::poisson, TangentialLaw::Normal::energetic})
    if (s == to_string(n)) return n;
  throw std::invalid_argument("unknown normal restitution rule '" + std::string(s) + "' (expected newton, poisson or energetic)");
}

std::string TangentialLaw::describe() const {
  std::ostringstream o;
  o << to_string(model);
  if (model == Model::kinematic) o << " (eps_t = " << num(eps_t) << ")";
  if (model == Model::coulomb) o << " (mu = " << num(mu) << ", " << to_string(normal) << ")";
  if (model == Model::walton) o << " (mu = " << num(mu) << ", beta0 = " << num(beta0) << ")";
  return o.str();
}

void validate(const TangentialLaw& l) {
  if (!std::isfinite(l.eps_t)) throw std::invalid_argument("tangential eps_t must be finite, got " + num(l.eps_t));
  // Above ~1e12 every impact sticks anyway (the tests' sticking limit is 1e7); far above it mu |A|
  // overflows the slip direction's step control and the process never ends (seen at 1e160).
  if (!(l.mu >= 0 && l.mu <= TangentialLaw::kMaxMu))
    throw std::invalid_argument("tangential mu must be in [0, 1e12] (1e12 already sticks every impact), got " + num(l.mu));
  if (!std::isfinite(l.beta0) || l.beta0 < -1 || l.beta0 > 1)
    throw std::invalid_argument("tangential beta0 must be in [-1, 1], got " + num(l.beta0));
}

double kinetic_energy(const RigidBody& body, const Vec3& V, const Vec3& Omega) {
  return 0.5 * body.mass * V.squaredNorm() + 0.5 * Omega.dot(body.inertia * Omega);
}

namespace {

using Mat3 = Eigen::Matrix3d;
using Vec2 = Eigen::Vector2d;

// The contact problem in the contact frame.
struct Contact {
  Mat3 B;     ///< columns t1, t2, n (world)
  Mat3 C;     ///< B^T K B
  Mat3 Jinv;  ///< J^-1 (world)
  Vec3 u0;    ///< contact velocity before, contact frame
};

Mat3 cross_matrix(const Vec3& a) {
  Mat3 m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

Contact contact_frame(const RigidBody& body, const ImpactState& s) {
  Contact c;
  const Vec3 t1 = s.n.unitOrthogonal(), t2 = s.n.cross(t1);
  c.B.col(0) = t1, c.B.col(1) = t2, c.B.col(2) = s.n;
  c.Jinv = body.inertia.inverse();
  const Mat3 rx = cross_matrix(s.r);
  const Mat3 K = Mat3::Identity() / body.mass - rx * c.Jinv * rx;
  c.C = c.B.transpose() * K * c.B;
  c.u0 = c.B.transpose() * (s.V + s.Omega.cross(s.r));
  return c;
}

ImpactResult finish(const RigidBody& body, const ImpactState& s, const Contact& c, const Vec3& P_local, double eps_n) {
  const Vec3 P = c.B * P_local;
  ImpactResult r;
  r.P = P;
  r.V_after = s.V + P / body.mass;
  r.Omega_after = s.Omega + c.Jinv * s.r.cross(P);
  r.v_n = c.u0.z();
  r.eps_n = eps_n;
  r.eps = -r.V_after.dot(s.n) / s.V.dot(s.n);
  return r;
}

// State of the process: contact velocity u, impulse P (contact frame), works.
struct State {
  Vec3 u, P;
  double Wn = 0, W = 0;  ///< int u_n dp, int u . dP
};

// Direction in which slip resumes from u_t = 0 when sticking is impossible: a unit s with
// a - mu A s = lambda s, lambda > 0 (the slip grows along s while friction opposes it). Roots of
// the 2D cross product on a fine angle grid, refined by bisection; the largest lambda wins.
Vec2 resume_direction(const Mat3& C, double mu) {
  const Eigen::Matrix2d A = C.topLeftCorner<2, 2>();
  const Vec2 a = C.topRightCorner<2, 1>();
  auto g = [&](double phi) {
    const Vec2 sd(std::cos(phi), std::sin(phi));
    const Vec2 v = a - mu * A * sd;
    return std::array<double, 2>{sd.x() * v.y() - sd.y() * v.x(), sd.dot(v)};
  };
  constexpr int kGrid = 720;
  const double two_pi = 2.0 * std::acos(-1.0);
  double best_lambda = -1, best_phi = 0;
  double p0 = 0, g0 = g(0)[0];
  for (int k = 1; k <= kGrid; ++k) {
    const double p1 = two_pi * k / kGrid, g1 = g(p1)[0];
    if ((g0 <= 0) != (g1 <= 0)) {
      double lo = p0, hi = p1, glo = g0;
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi), gm = g(mid)[0];
        if ((gm <= 0) == (glo <= 0)) lo = mid, glo = gm;
        else hi = mid;
      }
      const double phi = 0.5 * (lo + hi), lambda = g(phi)[1];
      if (lambda > best_lambda) best_lambda = lambda, best_phi = phi;
    }
    p0 = p1, g0 = g1;
  }
  if (!(best_lambda > 0)) throw std::runtime_error("impact: no direction for slip to resume (friction law)");
  return Vec2(std::cos(best_phi), std::sin(best_phi));
}

enum class Phase { slip, stick, resumed };

// Tangential impulse rate in the current phase (per unit normal impulse).
Vec2 rate(Phase ph, const Vec3& u, const Vec2& tau, const Vec2& resume, double mu) {
  if (ph == Phase::stick) return tau;
  if (ph == Phase::resumed) return -mu * resume;
  const Vec2 ut = u.head<2>();
  const double m = ut.norm();
  return m > 0 ? Vec2(-mu * ut / m) : Vec2::Zero();
}

// One RK4 step of length h in p for the augmented state (u, P, int u_n dp, int u . dP). In the slip
// phase the rate is re-evaluated at each stage (the slip direction turns); in the other phases it
// is constant and the step is exact.
State step(const State& x, double h, Phase ph, const Mat3& C, const Vec2& tau, const Vec2& resume, double mu) {
  auto deriv = [&](const Vec3& u) {
    const Vec2 f = rate(ph, u, tau, resume, mu);
    return Vec3(f.x(), f.y(), 1.0);
  };
  const Vec3 u1 = x.u, d1 = deriv(u1);
  const Vec3 u2 = x.u + 0.5 * h * C * d1, d2 = deriv(u2);
  const Vec3 u3 = x.u + 0.5 * h * C * d2, d3 = deriv(u3);
  const Vec3 u4 = x.u + h * C * d3, d4 = deriv(u4);
  const Vec3 dP = h / 6.0 * (d1 + 2 * d2 + 2 * d3 + d4);
  State y;
  y.P = x.P + dP;
  y.u = x.u + C * dP;
  y.Wn = x.Wn + h / 6.0 * (u1.z() + 2 * u2.z() + 2 * u3.z() + u4.z());
  y.W = x.W + h / 6.0 * (u1.dot(d1) + 2 * u2.dot(d2) + 2 * u3.dot(d3) + u4.dot(d4));
  return y;
}

// The impulse process of Coulomb friction with a normal restitution rule. A numerical kernel kept
// in one piece on purpose: its phases (slip, stick, resumed; compression, restitution) share the
// integrator state and step control, and splitting it would scatter that state over many calls.
// A bound on the integration, not a physical limit: slip that crawls along the friction cone's edge
// takes tiny steps (one random cube-corner impact in 2.8e5 needed 9.1e6 steps, ~2 s; 4e6 refused it).
constexpr int kMaxProcessSteps = 30000000;

ImpactProcess coulomb_process(const RigidBody& body, const ImpactState& s, double e, const TangentialLaw& law) {
  const Contact c = contact_frame(body, s);
  const double mu = law.mu;
  const Eigen::Matrix2d A = c.C.topLeftCorner<2, 2>();
  const Vec2 tau = -A.ldlt().solve(Vec2(c.C.topRightCorner<2, 1>()));
  const bool can_stick = tau.norm() <= mu;
  const double slip_tol = 1e-13 * c.u0.norm();
  const double h = -c.u0.z() / c.C(2, 2) / 512.0;  // 1/512 of the frictionless compression impulse
  // Stiffness of the slip direction: it turns at a rate up to mu |A| / |u_t| per unit impulse.
  const double turn = mu * A.norm();

  ImpactProcess out;
  State x{c.u0, Vec3::Zero()};
  Vec2 resume = Vec2::Zero();
  const Vec2 s0 = c.u0.head<2>().norm() > 0 ? Vec2(c.u0.head<2>().normalized()) : Vec2::Zero();
  Phase ph = Phase::slip;
  // Slip has stopped (or never was): stick if the friction cone can hold it, else slip resumes
  // along the direction the inertia tensor dictates.
  auto slip_stopped = [&] {
    x.u.head<2>().setZero();
    if (can_stick) {
      ph = Phase::stick;
      out.stuck = true;
    } else {
      resume = resume_direction(c.C, mu);
      ph = Phase::resumed;
      out.slip_reversed = out.slip_reversed || s0.norm() == 0 || resume.dot(s0) < 1 - 1e-12;
    }
  };
  if (mu > 0 && c.u0.head<2>().norm() <= slip_tol) slip_stopped();

  bool compressing = true;
  double Wc = 0, pc = 0;
  // Distance to the current phase's end (> 0 before it).
  auto to_end = [&](const State& y) {
    if (compressing) return -y.u.z();
    switch (law.normal) {
      case TangentialLaw::Normal::newton: return -e * c.u0.z() - y.u.z();
      case TangentialLaw::Normal::poisson: return (1.0 + e) * pc - y.P.z();
      case TangentialLaw::Normal::energetic: return e * e * (-Wc) - (y.Wn - Wc);
    }
    return 0.0;
  };
  const bool slipping_law = mu > 0;
  for (int n = 0; n < kMaxProcessSteps; ++n) {
    if (to_end(x) <= 0) {  // also e = 0: restitution ends where compression ends
      if (!compressing) break;
      compressing = false;
      pc = x.P.z(), Wc = x.Wn;
      continue;
    }
    ++out.steps;
    // While slipping, a step may change the slip by at most a tenth of itself, both along it (so
    // it shrinks geometrically into a stop instead of overshooting through zero) and across it
    // (the direction turns at up to mu |A| / |u_t| per unit impulse: near |tau| = mu it crawls,
    // and larger steps make RK4 chatter about the equilibrium direction).
    double hs = h;
    if (ph == Phase::slip && slipping_law) {
      const Vec2 f = rate(ph, x.u, tau, resume, mu);
      const double rt = std::max((c.C * Vec3(f.x(), f.y(), 1.0)).head<2>().norm(), turn);
      if (rt > 0) hs = std::min(h, 0.1 * x.u.head<2>().norm() / rt);
    }
    State y = step(x, hs, ph, c.C, tau, resume, mu);
    if (to_end(y) <= 0) {  // the phase ends within the step: bisect to it
      double lo = 0, hi = hs;
      for (int it = 0; it < 200; ++it) {
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi) break;
        (to_end(step(x, mid, ph, c.C, tau, resume, mu)) <= 0 ? hi : lo) = mid;
      }
      y = step(x, hi, ph, c.C, tau, resume, mu);
    }
    x = y;
    if (ph == Phase::slip && slipping_law && x.u.head<2>().norm() <= slip_tol) slip_stopped();
  }
  if (compressing || to_end(x) > 0)
    throw std::runtime_error("impact: the frictional impulse process did not end within " + std::to_string(kMaxProcessSteps) +
                             " integration steps (a jam, or slip crawling along the friction cone's edge)");
  out.p_compression = pc;
  out.work_normal_compression = Wc;
  out.work_normal_restitution = x.Wn - Wc;
  out.work = x.W;
  out.result = finish(body, s, c, x.P, e);
  return out;
}

// Walton's law as an algebraic impulse: stick with tangential restitution beta0, else slide.
ImpactProcess walton_impact(const RigidBody& body, const ImpactState& s, double e, const TangentialLaw& law) {
  const Contact c = contact_frame(body, s);
  const Vec3 target(-(1.0 + law.beta0) * c.u0.x(), -(1.0 + law.beta0) * c.u0.y(), -(1.0 + e) * c.u0.z());
  Vec3 P = c.C.ldlt().solve(target);
  ImpactProcess out;
  if (P.head<2>().norm() > law.mu * P.z()) {
    const Vec2 ut = c.u0.head<2>();
    const Vec2 sd = ut.norm() > 0 ? Vec2(ut.normalized()) : Vec2(P.head<2>().normalized() * -1.0);
    const Vec3 dir(-law.mu * sd.x(), -law.mu * sd.y(), 1.0);
    const double k = c.C.row(2).dot(dir);
    if (!(k > 0)) throw std::runtime_error("impact: Walton sliding impulse does not separate the body (jam)");
    P = (-(1.0 + e) * c.u0.z() / k) * dir;
    out.sliding = true;
  }
  out.stuck = !out.sliding;
  const Vec3 u1 = c.u0 + c.C * P;
  out.work = 0.5 * P.dot(c.u0 + u1);
  out.result = finish(body, s, c, P, e);
  return out;
}

void check_state(const ImpactState& s) {
  if (!s.V.allFinite() || !s.Omega.allFinite() || !s.r.allFinite())
    throw std::invalid_argument("impact: V, Omega and r must be finite");
  if (!s.n.allFinite() || std::abs(s.n.norm() - 1.0) > 1e-12) throw std::invalid_argument("impact: n must be a unit vector");
  if (s.V.dot(s.n) == 0.0) throw std::invalid_argument("impact: V.n = 0, the macroscopic eps of Eq. 1 is undefined");
}

}  // namespace

std::optional<ImpactProcess> solve_impact_process(const RigidBody& body, const ImpactState& s, double eps_n,
                                                  const TangentialLaw& law) {
  validate(law);
  check_state(s);
  if (!std::isfinite(eps_n) || eps_n < 0) throw std::invalid_argument("impact: eps_n must be finite and >= 0, got " + num(eps_n));
  if (law.model == TangentialLaw::Model::kinematic) {
    const auto r = solve_impact(body, s, eps_n, law.eps_t);
    if (!r) return std::nullopt;
    ImpactProcess out;
    out.result = *r;
    const Vec3 u0 = s.V + s.Omega.cross(s.r);
    const Vec3 u1 = r->V_after + r->Omega_after.cross(s.r);
    out.work = 0.5 * r->P.dot(u0 + u1);
    return out;
  }
  if (!((s.V + s.Omega.cross(s.r)).dot(s.n) < 0)) return std::nullopt;
  if (law.model == TangentialLaw::Model::walton) return walton_impact(body, s, eps_n, law);
  return coulomb_process(body, s, eps_n, law);
}

std::optional<ImpactResult> solve_impact(const RigidBody& body, const ImpactState& s, double eps_n, const TangentialLaw& law) {
  if (law.model == TangentialLaw::Model::kinematic) {
    validate(law);
    return solve_impact(body, s, eps_n, law.eps_t);
  }
  const auto p = solve_impact_process(body, s, eps_n, law);
  if (!p) return std::nullopt;
  return p->result;
}

std::optional<ImpactResult> solve_impact(const RigidBody& body, const ImpactState& s, const Restitution& eps_n,
                                         const TangentialLaw& law) {
  check_state(s);
  const double vn = (s.V + s.Omega.cross(s.r)).dot(s.n);
  if (!(vn < 0)) return std::nullopt;
  return solve_impact(body, s, eps_n(-vn), law);
}

}  // namespace asperity
