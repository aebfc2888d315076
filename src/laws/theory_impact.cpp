// SPDX-License-Identifier: GPL-3.0-or-later
// Sec. IV laws: eps (Eq. 28) and Omega'_x (Eq. 33), as printed and as corrected. Derivations and
// the error budget of every approximation: docs/sec4-derivations.md.
#include "asperity/laws/theory_impact.hpp"

#include <boost/math/distributions/non_central_chi_squared.hpp>
#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/special_functions/erf.hpp>
#include <boost/math/tools/minima.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace asperity {

namespace {

constexpr double pi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();
using GK = boost::math::quadrature::gauss_kronrod<double, 31>;
using GL = boost::math::quadrature::gauss<double, 20>;

std::string num(double v, int prec = 6) {
  std::ostringstream os;
  os.precision(prec);
  os << v;
  return os.str();
}

// `what` as a C string: a std::string parameter built one string per check, and the paper's bounce
// procedure validates a scene per impact.
void require(bool ok, const char* what, double v) {
  if (!ok) throw std::invalid_argument(std::string("ImpactScene: ") + what + ", got " + num(v, 17));
}

// Standard normal cdf and density of N(0, s^2) at y.
double normal_cdf(double y, double s) { return 0.5 * boost::math::erfc(-y / (s * std::numbers::sqrt2)); }
double normal_pdf(double y, double s) {
  const double z = y / s;
  return std::exp(-0.5 * z * z) / (s * std::sqrt(2.0 * pi));
}

// d eps_n/dv at u by a central difference (step 1e-3 u: truncation ~1e-7 relative for the
// v^(1/10) Pade, rounding ~1e-13): keeps the law consistent with the Restitution in use.
double derivative(const Restitution& e, double u) {
  const double h = 1e-3 * u;
  return (e(u + h) - e(u - h)) / (2.0 * h);
}

// Integral of f over [lo, hi] split at the given interior points, where the integrand has
// square-root kinks. Adaptive Gauss-Kronrod on each piece: tanh-sinh would converge faster, but
// Boost 1.74's tanh_sinh mis-places abscissas for intervals away from 0 (its `position` falls
// through to the wrong branch and trips its own assertion in debug builds).
template <class F>
double integrate_pieces(F f, double lo, double hi, std::vector<double> cuts, double tol = 1e-12) {
  cuts.push_back(lo);
  cuts.push_back(hi);
  std::sort(cuts.begin(), cuts.end());
  double sum = 0;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = std::max(lo, cuts[i]), b = std::min(hi, cuts[i + 1]);
    if (b > a) sum += GK::integrate(f, a, b, 15, tol);
  }
  return sum;
}

// ---- Core contacts (bare central sphere touches): the part of the asperity law that moves into
// the atom. r ~ N(0, sigma^2 I_2) in the plane; the core touches when |r| > r*. With
// rho^2 = r*^2 + 2 sigma^2 v the radial measure of {|r| > r*} is p0 e^{-v} dv.
struct Core {
  double sigma = 0, r_star = 0, p0 = 0;
  double rho(double v) const { return std::sqrt(r_star * r_star + 2.0 * sigma * sigma * v); }
  double v_of(double rho_) const { return (rho_ * rho_ - r_star * r_star) / (2.0 * sigma * sigma); }
  static constexpr double vmax = 60.0;  // e^-60 ~ 1e-26

  // P(W >= Y, |r| > r*), W = |r + d e|^2 for a fixed unit vector e (d >= 0).
  double tail_W(double Y, double d) const {
    if (p0 == 0) return 0.0;
    if (Y <= 0) return p0;
    if (d == 0) return std::exp(-std::max(r_star * r_star, Y) / (2.0 * sigma * sigma));
    const double sY = std::sqrt(Y);
    // Fraction of the circle |r| = rho with |r + d e|^2 >= Y: cos(phi) >= c0.
    auto g = [&](double v) {
      const double p = rho(v);
      const double c0 = (Y - p * p - d * d) / (2.0 * p * d);
      return std::exp(-v) * (c0 <= -1 ? 1.0 : c0 >= 1 ? 0.0 : std::acos(c0) / pi);
    };
    std::vector<double> cuts;
    for (double k : {std::abs(sY - d), sY + d})
      if (k > r_star) cuts.push_back(std::min(v_of(k), vmax));
    return p0 * integrate_pieces(g, 0.0, vmax, cuts, 1e-11);
  }
  // Density of W at Y restricted to |r| > r*.
  double tail_W_density(double Y, double d) const {
    if (p0 == 0 || Y <= 0) return 0.0;
    const double s2 = sigma * sigma;
    if (d == 0) return Y > r_star * r_star ? std::exp(-Y / (2.0 * s2)) / (2.0 * s2) : 0.0;
    const double sY = std::sqrt(Y), kappa = sY * d / s2;
    const double c1 = (Y + d * d - r_star * r_star) / (2.0 * sY * d);
    if (c1 <= -1) return 0.0;
    const double psi1 = c1 >= 1 ? 0.0 : std::acos(c1);
    auto h = [&](double psi) { return std::exp(kappa * (std::cos(psi) - 1.0)); };
    const double I = GK::integrate(h, psi1, pi, 10, 1e-12);
    const double z = (sY - d) / sigma;
    return std::exp(-0.5 * z * z) / (4.0 * pi * s2) * 2.0 * I;
  }
  // P(r_y <= y, |r| > r*).
  double tail_y(double y) const {
    if (p0 == 0) return 0.0;
    auto h = [&](double v) {
      const double q = y / rho(v);
      return std::exp(-v) * (0.5 + (q <= -1 ? -0.5 : q >= 1 ? 0.5 : std::asin(q) / pi));
    };
    std::vector<double> cuts;
    if (std::abs(y) > r_star) cuts.push_back(std::min(v_of(std::abs(y)), vmax));
    return p0 * integrate_pieces(h, 0.0, vmax, cuts, 1e-11);
  }
};

struct Setup {
  ImpactScene s;
  ImpactLawParameters p;
  double u = 0, R = 0, a = 0, omega = 0;  // omega = |Omega_xy|
  Core core;
};

// `eps_n`: viscoelastic_pade14(s.beta) built by the caller (impact_law_parameters' overload), or
// null for one built here.
Setup setup(const ImpactScene& s, const Restitution* eps_n = nullptr) {
  validate(s);
  Setup x;
  x.s = s;
  x.u = s.speed, x.R = s.radius, x.a = s.asperity_radius;
  x.omega = std::hypot(s.omega_x, s.omega_y);
  auto& p = x.p;
  std::unique_ptr<Restitution> own;
  if (!eps_n) own = viscoelastic_pade14(s.beta), eps_n = own.get();
  const Restitution& en = *eps_n;
  p.lambda = areal_density(s.asperities, x.R);
  p.sigma = 1.0 / std::sqrt(2.0 * pi * p.lambda);
  p.inertia = 0.4 * (s.literal_eq23 ? x.a * x.a : x.R * x.R);
  const double rz = x.R + x.a;
  p.c2 = p.inertia + rz * rz;
  p.eps_n = en(x.u);
  p.eps_n_prime = derivative(en, x.u);
  p.alpha = (1.0 + p.eps_n) / p.c2;
  p.b = x.omega * ((1.0 + p.eps_n) / x.u + p.eps_n_prime);
  p.shift = p.b / (2.0 * p.alpha);
  p.noncentrality = (p.shift / p.sigma) * (p.shift / p.sigma);
  p.eps_max = p.eps_n + p.alpha * p.shift * p.shift;
  p.sigma_c = (1.0 + p.eps_n) * x.u * p.sigma / p.c2;
  // Eq. 33 as printed: P_z/(J sqrt(2 lambda pi)) (1 + r_z^2/(r_z^2 + I)), P_z = M u (1 + eps_n),
  // J = M I_g: M cancels.
  p.sigma_printed = x.u * (1.0 + p.eps_n) * p.sigma / p.inertia * (1.0 + rz * rz / (rz * rz + p.inertia));
  p.r_star = std::sqrt(x.a * (2.0 * x.R - x.a));
  p.p_core = std::exp(-p.r_star * p.r_star / (2.0 * p.sigma * p.sigma));
  x.core = Core{p.sigma, p.r_star, s.core_contacts ? p.p_core : 0.0};
  return x;
}

std::string scene_text(const Setup& x) {
  return "N=" + std::to_string(x.s.asperities) + ", R=" + num(x.R) + " m, a=" + num(x.a) + " m, u=" + num(x.u) +
         " m/s, Omega=(" + num(x.s.omega_x) + "," + num(x.s.omega_y) + ",0) rad/s, eps_n(u)=" + num(x.p.eps_n, 8);
}

// =====================================================================================
// Eq. 28 as printed, evaluated literally in log space. Paper frame: V_z = u > 0, Omega_x as
// given; c^2 = I + r_z^2, Q = (1 + eps_n) c^2, f^2 = A0 + B0 (1+t)(eps_n - t) with
// A0 = (1 + eps_n) Q Omega_x^2 (as printed), B0 = 4 u^2 c^2, h = 2 (1+t) u^2 + Q Omega_x^2,
// p(t) = -pi lambda (Q Omega_x + f) Q (h + f Omega_x) / (2 u^2 (1+t)^3 f) exp[-pi lambda (h+f)^2/(4 (1+t)^2 u^2)].
// f is real on [t_lo, t_hi] (roots of f^2). With t = t_c - hw cos(phi), phi in [0, pi], the 1/f
// singularity at both ends cancels: f = sqrt(B0) hw sin(phi), dt = hw sin(phi) dphi, so
// q(phi) = p dt/dphi = -pi lambda (Q Omega_x + f) Q (h + f Omega_x) / (2 u^2 (1+t)^3 sqrt(B0)) e^E
// is smooth; its mass sits in narrow spikes that are located, bracketed and integrated below.
//
// Small spin (issue 41 item 7): the spike sits where h + f = 0 with x = 1 + t < 0, in
// [x_lo, 0), x_lo = 1 + t_lo = -O(Omega_x^2), at an offset y_s = x - x_lo = O(Omega_x^4) above x_lo
// and with a width O(Omega_x^4) in x. Everything is therefore computed from the offset y from the
// nearer end (x = x_lo + y, x_lo without the cancellation of 1 + t_lo), phi measured from the lower
// end (so that phi ~ Omega_x^2 keeps its relative precision), and the spike's offset y_s from the
// small root of a quadratic: at Omega_x = 1e-5 rad/s (fig4's sphere) y_s = 6e-17 and the spike is
// 2e-21 wide, far below the spacing of t near -1 (2.2e-16), where 1 + t lost every digit.
struct Printed {
  double u = 0, wx = 0, e = 0, Q = 0, pl = 0, A0 = 0, B0 = 0, sqB0 = 0;
  double tlo = 0, thi = 0, hw = 0;
  double xlo = 0, xhi = 0;        // 1 + tlo, 1 + thi, each without cancellation
  double log_cq = 0, log_cp = 0;  // log of the constant factors of |q| and |p|
  // A bracket of the mass, integrated with a composite 20-point Gauss-Legendre rule on kPanels
  // equal panels: the bracket spans ~20 widths of the spike, so each panel sees a smooth,
  // well-resolved integrand (no adaptive recursion on a function that is 0 almost everywhere).
  static constexpr int kPanels = 256;
  struct Piece {
    double a, b, peak;
    std::vector<double> cum;  // integral of q e^{-ref} from a to each panel boundary
    double mass() const { return cum.back(); }
    double width() const { return (b - a) / kPanels; }
  };
  std::vector<Piece> pieces;
  double ref = 0;       // log scale of the pieces
  double Z = 0;         // sum of the piece masses (signed)
  double Zcoarse = 0;   // the same with half the panels
  double log_raw = -kInf;  // log |integral of p dt|
  int sign_raw = 0;
  bool negative_everywhere = true, positive_somewhere = false;

  struct Point {
    double t, x, f;
  };
  // The point at phi in [0, pi]: t = t_lo + y below phi = pi/2, t = t_hi - y above, with
  // y = 2 hw sin^2(distance from the end / 2); x = 1 + t from x_lo or x_hi.
  Point at_phi(double ph) const {
    Point P;
    if (ph <= 0.5 * pi) {
      const double s = std::sin(0.5 * ph), y = 2.0 * hw * s * s;
      P.t = tlo + y, P.x = xlo + y;
    } else {
      const double s = std::sin(0.5 * (pi - ph)), y = 2.0 * hw * s * s;
      P.t = thi - y, P.x = xhi - y;
    }
    P.f = sqB0 * hw * std::max(0.0, std::sin(ph));
    return P;
  }
  // phi of t; the lower half from x = 1 + t (exact for t in [-2, -1/2]) minus x_lo.
  double phi_of(double t) const {
    const double du = thi - t, dl = (1.0 + t) - xlo;
    if (!(dl > 0)) return 0.0;  // not t <= t_lo: at Omega_x < 1e-8 t_lo rounds to -1 > the spike
    if (!(du > 0)) return pi;
    if (du < dl) return pi - 2.0 * std::asin(std::sqrt(du / (2.0 * hw)));
    return 2.0 * std::asin(std::sqrt(std::min(1.0, dl / (2.0 * hw))));
  }
  // log|.| of the t-dependent factors and their sign: (Q wx + f)(h + f wx)/(x^3) e^E.
  double log_core(double x, double f, int& sign) const {
    sign = 0;
    if (x == 0) return -kInf;
    const double A = Q * wx + f, h = 2.0 * x * u * u + Q * wx * wx, B = h + f * wx;
    if (A == 0 || B == 0) return -kInf;
    const double g = (h + f) / (2.0 * x * u);
    const double E = -pl * g * g;
    sign = -(A > 0 ? 1 : -1) * (B > 0 ? 1 : -1) * (x > 0 ? 1 : -1);
    return std::log(std::abs(A)) + std::log(std::abs(B)) - 3.0 * std::log(std::abs(x)) + E;
  }
  double log_q(double ph, int& sign) const {
    const Point P = at_phi(ph);
    const double l = log_core(P.x, P.f, sign);
    return std::isnan(l) ? -kInf : log_cq + l;
  }
  double q_scaled(double ph) const {  // q e^{-ref}
    int sg;
    const double l = log_q(ph, sg);
    return sg == 0 ? 0.0 : sg * std::exp(l - ref);
  }
  // Printed p (raw sign) in log form at a point of the interval.
  double log_p_at(const Point& P, int& sign) const {
    sign = 0;
    if (P.f == 0) return -kInf;
    const double l = log_core(P.x, P.f, sign);
    return std::isnan(l) ? -kInf : log_cp + l - std::log(P.f);
  }
  // Printed p(t) (raw sign) in log form; t - t_lo as (1 + t) - x_lo.
  double log_p(double t, int& sign) const {
    sign = 0;
    const double dl = (1.0 + t) - xlo, du = thi - t;
    if (!(dl > 0 && du > 0)) return -kInf;
    return log_p_at({t, 1.0 + t, sqB0 * std::sqrt(du * dl)}, sign);
  }

  // Sign of the printed p where it is representable (|p| > 1e-300): it is also positive in
  // places, but only where it underflows (e.g. fig4: -7.8e-5 < 1+t < 0).
  void survey(double ph) {
    int sg;
    const double l = log_p_at(at_phi(ph), sg);
    if (sg > 0 && l > -690) positive_somewhere = true;
  }

  // phi of the zero of h + f on the lower half (x < 0, h < 0), where the small-spin spike sits,
  // or -1 where there is none. With x = x_lo + y, h = H0 + 2 u^2 y (H0 = h at x_lo) and
  // f^2 = B0 y (2 hw - y), h = -f is (4u^4 + B0) y^2 + (4u^2 H0 - 2 hw B0) y + H0^2 = 0; both
  // roots are positive for H0 < 0 and the small one, C/q without cancellation, is the zero.
  double spike_phi() const {
    const double H0 = 2.0 * u * u * xlo + Q * wx * wx;
    if (!(A0 > 0) || !(H0 < 0)) return -1.0;
    const double a = 4.0 * u * u * u * u + B0, b = 4.0 * u * u * H0 - 2.0 * hw * B0, c = H0 * H0;
    const double disc = b * b - 4.0 * a * c;
    if (!(disc >= 0)) return -1.0;
    const double qq = -0.5 * (b - std::sqrt(disc));  // b < 0: qq > 0
    const double y = c / qq;
    if (!(y > 0) || !(y < hw) || !(H0 + 2.0 * u * u * y < 0)) return -1.0;
    return 2.0 * std::asin(std::sqrt(y / (2.0 * hw)));
  }

  void build() {
    // 1. Grid in phi; local maxima of log|q| (NaN/-inf treated as -inf).
    constexpr int K = 4096;
    std::vector<double> th(K + 1), ph(K + 1);
    int sg;
    for (int k = 0; k <= K; ++k) {
      th[k] = pi * k / K;
      ph[k] = log_q(th[k], sg);
      survey(th[k]);
    }
    struct Cand {
      double th, ph;
    };
    std::vector<Cand> cands;
    auto neg = [&](double t) {
      int s2;
      const double v = log_q(t, s2);
      return v > -kInf ? -v : std::numeric_limits<double>::max();
    };
    for (int k = 0; k <= K; ++k) {
      const double l = k > 0 ? ph[k - 1] : -kInf, r = k < K ? ph[k + 1] : -kInf;
      if (!(ph[k] > -kInf) && !(l > -kInf) && !(r > -kInf)) continue;
      if (ph[k] >= l && ph[k] >= r) {
        // Brent on [th[k-1], th[k+1]]: locates the maximum to ~sqrt(eps) in phi; the spike may
        // be narrower, which the adaptive quadrature below resolves.
        const double lo = th[std::max(k - 1, 0)], hi = th[std::min(k + 1, K)];
        const auto m = boost::math::tools::brent_find_minima(neg, lo, hi, 60);
        int s2;
        double best_th = m.first, best = log_q(m.first, s2);
        if (ph[k] > best) best_th = th[k], best = ph[k];
        if (best > -kInf) cands.push_back({best_th, best});
      }
    }
    // The zero of h + f, located analytically: at small spin its spike is far narrower than a
    // grid cell (and than Brent's sqrt(eps) on the grid's bracket). Added unless the grid search
    // already found that spike (fig4's spin: the results stay as they were).
    if (const double ps = spike_phi(); ps > 0) {
      const double lo = ps * (1.0 - 1e-3), hi = ps * (1.0 + 1e-3);
      bool found = false;
      for (const auto& c : cands) found = found || (c.th >= lo && c.th <= hi);
      if (!found) {
        const auto m = boost::math::tools::brent_find_minima(neg, lo, hi, 60);
        int s2;
        double best_th = ps, best = log_q(ps, s2);
        if (const double v = log_q(m.first, s2); v > best) best_th = m.first, best = v;
        if (best > -kInf) cands.push_back({best_th, best});
      }
    }
    if (cands.empty()) return;
    ref = -kInf;
    for (const auto& c : cands) ref = std::max(ref, c.ph);
    const double thr = ref - 80.0;
    // 2. Bracket {log|q| >= thr} around each candidate by bisection against grid points below
    // thr (a relative stopping rule: phi may be ~1e-10 at small spin).
    auto edge = [&](double inside, double outside) {
      const double tol = std::min(1e-17, 1e-12 * std::abs(inside));
      for (int i = 0; i < 400 && std::abs(outside - inside) > tol; ++i) {
        const double mid = 0.5 * (inside + outside);
        if (mid == inside || mid == outside) break;
        int s2;
        (log_q(mid, s2) >= thr ? inside : outside) = mid;
      }
      return inside;
    };
    std::vector<Piece> raw;
    for (const auto& c : cands) {
      if (c.ph < thr) continue;
      double a = 0.0, b = pi;
      // nearest grid point to the left with log|q| < thr
      int k = static_cast<int>(std::floor(c.th / pi * K));
      k = std::clamp(k, 0, K);
      for (int j = k; j >= 0; --j)
        if (th[j] < c.th && ph[j] < thr) {
          double in = c.th;
          for (int i = j + 1; i <= K && th[i] < c.th; ++i)
            if (ph[i] >= thr) {
              in = th[i];
              break;
            }
          a = edge(in, th[j]);
          break;
        }
      for (int j = std::max(k, 0); j <= K; ++j)
        if (th[j] > c.th && ph[j] < thr) {
          double in = c.th;
          for (int i = j - 1; i >= 0 && th[i] > c.th; --i)
            if (ph[i] >= thr) {
              in = th[i];
              break;
            }
          b = edge(in, th[j]);
          break;
        }
      raw.push_back({a, b, c.th, {}});
    }
    std::sort(raw.begin(), raw.end(), [](const Piece& l, const Piece& r) { return l.a < r.a; });
    for (const auto& p : raw) {
      if (!pieces.empty() && p.a <= pieces.back().b) {
        pieces.back().b = std::max(pieces.back().b, p.b);
      } else {
        pieces.push_back(p);
      }
    }
    // 3. Integrate each piece panel by panel.
    auto qs = [this](double t) { return q_scaled(t); };
    for (auto& p : pieces) {
      p.peak = std::clamp(p.peak, p.a, p.b);
      p.cum.assign(kPanels + 1, 0.0);
      for (int j = 0; j < kPanels; ++j)
        p.cum[j + 1] = p.cum[j] + GL::integrate(qs, p.a + j * p.width(), p.a + (j + 1) * p.width());
      Z += p.mass();
      double coarse = 0;  // the same with half the panels: a convergence check
      for (int j = 0; j < kPanels / 2; ++j)
        coarse += GL::integrate(qs, p.a + 2 * j * p.width(), p.a + 2 * (j + 1) * p.width());
      Zcoarse += coarse;
      for (int i = 0; i <= 200; ++i) survey(p.a + (p.b - p.a) * i / 200.0);
    }
    negative_everywhere = !positive_somewhere;
    if (Z != 0) {
      log_raw = ref + std::log(std::abs(Z));
      sign_raw = Z > 0 ? 1 : -1;
    }
  }

  // Normalised cdf: integral of p from t_lo to t over the raw integral.
  double cdf(double t) const {
    if (Z == 0) return t >= thi ? 1.0 : 0.0;
    const double th = phi_of(t);
    double acc = 0;
    auto qs = [this](double v) { return q_scaled(v); };
    for (const auto& p : pieces) {
      if (th >= p.b) {
        acc += p.mass();
      } else if (th > p.a) {
        const int j = std::clamp(static_cast<int>((th - p.a) / p.width()), 0, kPanels - 1);
        const double left = p.a + j * p.width();
        acc += p.cum[j] + (th > left ? GL::integrate(qs, left, th) : 0.0);
      }
    }
    return std::clamp(acc / Z, 0.0, 1.0);
  }
  double pdf(double t) const {
    if (Z == 0) return 0.0;
    int sg;
    const double l = log_p(t, sg);
    if (sg == 0) return 0.0;
    return sg * sign_raw * std::exp(l - log_raw);
  }
  // Moments about x0 = 1 + t0 of the normalised law: {E[x - x0], E[(x - x0)^2]} (x, not t: at
  // small spin x - x0 ~ 1e-21 is far below the spacing of t).
  std::pair<double, double> moments(double x0) const {
    double m1 = 0, m2 = 0;
    for (const auto& p : pieces) {
      auto g1 = [&](double th) { return (at_phi(th).x - x0) * q_scaled(th); };
      auto g2 = [&](double th) {
        const double d = at_phi(th).x - x0;
        return d * d * q_scaled(th);
      };
      for (int j = 0; j < kPanels; ++j) {
        const double l = p.a + j * p.width(), r = l + p.width();
        m1 += GL::integrate(g1, l, r);
        m2 += GL::integrate(g2, l, r);
      }
    }
    return {m1 / Z, m2 / Z};
  }
};

std::string log_number(double log_abs, int sign) {
  if (sign == 0) return "0 (underflows)";
  const double l10 = log_abs / std::log(10.0);
  std::string s = sign < 0 ? "-" : "";
  if (std::abs(l10) < 300) return s + num(std::exp(log_abs), 6);
  const double ex = std::floor(l10);
  return s + num(std::pow(10.0, l10 - ex), 4) + "e" + num(ex, 12);
}

}  // namespace

void validate(const ImpactScene& s) {
  require(s.asperities >= 1, "asperities must be >= 1", static_cast<double>(s.asperities));
  require(std::isfinite(s.radius) && s.radius > 0, "radius must be finite and > 0 m", s.radius);
  require(std::isfinite(s.asperity_radius) && s.asperity_radius >= 0 && s.asperity_radius < s.radius,
          "asperity_radius must be finite with 0 <= a < R", s.asperity_radius);
  require(std::isfinite(s.speed) && s.speed > 0, "speed must be finite and > 0 m/s", s.speed);
  require(std::isfinite(s.omega_x), "omega_x must be finite", s.omega_x);
  require(std::isfinite(s.omega_y), "omega_y must be finite", s.omega_y);
  require(std::isfinite(s.beta) && s.beta > 0, "beta must be finite and > 0", s.beta);
}

ImpactLawParameters impact_law_parameters(const ImpactScene& s) { return setup(s).p; }

ImpactLawParameters impact_law_parameters(const ImpactScene& s, const Restitution& eps_n) { return setup(s, &eps_n).p; }

// =====================================================================================
Law eq28_corrected(const ImpactScene& s, double alpha_scale) {
  if (!(alpha_scale > 0) || !std::isfinite(alpha_scale)) throw std::invalid_argument("eq28_corrected: alpha_scale must be > 0");
  const Setup x = setup(s);
  const auto& p = x.p;
  const double al = p.alpha * alpha_scale;
  const double d = p.b / (2.0 * al);           // shift of the Gaussian centre [m]
  const double e0 = p.eps_n + al * d * d;      // supremum of eps
  const double S = al * p.sigma * p.sigma;     // eps per unit of W/sigma^2
  const double nc = (d / p.sigma) * (d / p.sigma);
  const double eps_n = p.eps_n;
  const Core core = x.core;
  using NC = boost::math::non_central_chi_squared_distribution<double>;
  auto dist = std::make_shared<NC>(2.0, nc > 0 ? nc : 1.0);  // nc = 0 uses closed forms below
  auto survival = [nc, dist](double y) {                        // P(W/sigma^2 >= y)
    if (y <= 0) return 1.0;
    if (nc == 0) return std::exp(-0.5 * y);
    return boost::math::cdf(boost::math::complement(*dist, y));
  };
  auto density = [nc, dist](double y) {
    if (y < 0) return 0.0;
    if (nc == 0) return 0.5 * std::exp(-0.5 * y);
    return boost::math::pdf(*dist, y);
  };
  Law law;
  law.name = alpha_scale == 1.0 ? "eq28-corrected" : "eq28-corrected-alpha-x" + num(alpha_scale);
  law.description =
      "eps = eps_n(u) + b^2/(4 alpha) - alpha W, W/sigma^2 ~ noncentral chi2(2, " + num(nc) + "); alpha = (1+eps_n)/(I_g+(R+a)^2) = " +
      num(al) + " 1/m^2, b = |Omega|((1+eps_n)/u + eps_n'(u)) = " + num(p.b) + " 1/m, sigma = " + num(p.sigma) +
      " m (full solve, eps_t = 1, z-up frame); " + scene_text(x) +
      (s.core_contacts ? "; with core contacts: atom of mass " + num(core.p0) + " at eps_n(u)"
                       : "; asperity contacts only (core-contact probability " + num(p.p_core) + " ignored)");
  law.cdf = [=](double t) {
    const double y = (e0 - t) / S;
    double F = survival(y);
    if (core.p0 > 0) {
      F -= core.tail_W(y * p.sigma * p.sigma, d);
      if (t >= eps_n) F += core.p0;
    }
    return std::clamp(F, 0.0, 1.0);
  };
  law.pdf = [=](double t) {
    const double y = (e0 - t) / S;
    if (y < 0) return 0.0;
    double f = density(y) / S;
    if (core.p0 > 0) f -= core.tail_W_density(y * p.sigma * p.sigma, d) / al;
    return std::max(f, 0.0);
  };
  // E[eps] = eps_n - 2 alpha sigma^2 (the linear term averages out); core contacts replace
  // E[eps; |r| > r*] = p0 (eps_n - alpha (r*^2 + 2 sigma^2)) by p0 eps_n.
  law.mean = eps_n - 2.0 * S + al * (core.r_star * core.r_star + 2.0 * p.sigma * p.sigma) * core.p0;
  return law;
}

Law eq33_corrected(const ImpactScene& s, double sigma_scale) {
  if (!(sigma_scale > 0) || !std::isfinite(sigma_scale)) throw std::invalid_argument("eq33_corrected: sigma_scale must be > 0");
  const Setup x = setup(s);
  const auto& p = x.p;
  const double k = (1.0 + p.eps_n) * x.u / p.c2 * sigma_scale;  // Omega'_x - Omega_x = k r_y
  const double sigma = p.sigma, w0 = s.omega_x;
  const Core core = x.core;
  Law law;
  law.name = sigma_scale == 1.0 ? "eq33-corrected" : "eq33-corrected-sigma-x" + num(sigma_scale);
  law.description = "Omega'_x ~ Normal(Omega_x, sigma_c^2), sigma_c = (1+eps_n(u)) u sigma/(I_g+(R+a)^2) = " +
                    num(k * sigma) + " rad/s (Omega' = Omega - K (r_y, -r_x, 0), eps_t = 1); " + scene_text(x) +
                    (s.core_contacts ? "; with core contacts: atom of mass " + num(core.p0) + " at Omega_x"
                                     : "; asperity contacts only (core-contact probability " + num(p.p_core) + " ignored)");
  law.cdf = [=](double t) {
    const double y = (t - w0) / k;
    double F = normal_cdf(y, sigma);
    if (core.p0 > 0) {
      F -= core.tail_y(y);
      if (t >= w0) F += core.p0;
    }
    return std::clamp(F, 0.0, 1.0);
  };
  law.pdf = [=](double t) {
    const double y = (t - w0) / k;
    double f = normal_pdf(y, sigma) / k;
    if (core.p0 > 0) {
      const double h2 = core.r_star * core.r_star - y * y;
      f *= h2 > 0 ? boost::math::erf(std::sqrt(h2) / (sigma * std::numbers::sqrt2)) : 0.0;
    }
    return f;
  };
  law.mean = w0;
  return law;
}

Law eq33_printed(const ImpactScene& s) {
  const Setup x = setup(s);
  const double sp = x.p.sigma_printed, w0 = s.omega_x;
  Law law;
  law.name = "eq33-printed";
  law.description = "Eq. 33 as printed: Normal(Omega_x, sigma^2), sigma = P_z/(J sqrt(2 lambda pi)) (1 + r_z^2/(r_z^2+I)) = " +
                    num(sp) + " rad/s with I -> J = (2/5) M R^2 in the prefactor (I = J/M gives kg/(m s)), I = J/M in the "
                    "bracket, r_z = R + a, P_z = M u (1 + eps_n(u)); " +
                    num(x.p.sigma_printed / x.p.sigma_c, 5) + " x the corrected sigma; " + scene_text(x);
  law.cdf = [=](double t) { return normal_cdf(t - w0, sp); };
  law.pdf = [=](double t) { return normal_pdf(t - w0, sp); };
  law.mean = w0;
  return law;
}

// =====================================================================================
Law eq28_paper_route(const ImpactScene& s) {
  const Setup x = setup(s);
  const auto& p = x.p;
  const double u = x.u, wx = s.omega_x, e = p.eps_n, c2 = p.c2, Q = (1.0 + e) * c2, pl = pi * p.lambda;
  // Non-negative roots of x u s^2 - Q wx s + c2 u (t - e) = 0 (x = 1 + t): eps(s) = t.
  struct Roots {
    double s1, s2, f;  // s1 <= s2; f = sqrt(discriminant) (0: none)
    bool real;
  };
  auto roots = [=](double t) {
    Roots r{0, 0, 0, false};
    const double X = 1.0 + t;
    if (!(X > 0)) return r;
    const double A = X * u, B = -Q * wx, C = c2 * u * (t - e);
    const double disc = B * B - 4.0 * A * C;
    if (!(disc > 0)) return r;
    r.f = std::sqrt(disc);
    const double qq = -0.5 * (B + (B >= 0 ? r.f : -r.f));
    double a1 = qq / A, a2 = qq != 0 ? C / qq : -a1;
    if (a1 > a2) std::swap(a1, a2);
    r.s1 = a1, r.s2 = a2, r.real = true;
    return r;
  };
  Law law;
  law.name = "eq28-paper-route";
  law.description =
      "the paper's route done right: eps(s) = -1 + Q (u + Omega_x s)/(u (s^2 + c^2)), s = r_xy ~ Rayleigh(sigma) "
      "(Eq. 26: r_x + r_y ~ r_xy), r_z = R + a, c^2 = I + r_z^2, Q = (1+eps_n(u)) c^2, all non-negative preimages; "
      "paper frame (V_z = u > 0); " +
      scene_text(x);
  law.cdf = [=](double t) {
    if (!(1.0 + t > 0)) return 0.0;
    const Roots r = roots(t);
    if (!r.real) return 1.0;  // the quadratic is >= 0 for all s: eps(s) <= t everywhere
    if (r.s2 <= 0) return 1.0;
    // eps <= t  <=>  s <= s1 or s >= s2
    const double low = r.s1 > 0 ? -std::expm1(-pl * r.s1 * r.s1) : 0.0;
    return std::clamp(low + std::exp(-pl * r.s2 * r.s2), 0.0, 1.0);
  };
  law.pdf = [=](double t) {
    const Roots r = roots(t);
    if (!r.real || r.f == 0) return 0.0;
    double sum = 0;
    for (double si : {r.s1, r.s2})
      if (si > 0) sum += 2.0 * pl * si * std::exp(-pl * si * si) * u * (si * si + c2) / r.f;
    return sum;
  };
  auto eps_of = [=](double z) {  // z = pi lambda s^2 ~ Exp(1)
    const double si = std::sqrt(z / pl);
    return (-1.0 + Q * (u + wx * si) / (u * (si * si + c2))) * std::exp(-z);
  };
  law.mean = GK::integrate(eps_of, 0.0, 80.0, 10, 1e-14);
  return law;
}

// =====================================================================================
Law eq28_printed(const ImpactScene& s) {
  const Setup x = setup(s);
  const auto& p = x.p;
  auto P = std::make_shared<Printed>();
  // Below kFloor rad/s the spike's offset from x_lo (~ 6e-17 (Omega_x / 1e-5 rad/s)^4) leaves
  // double precision, and A0 underflows below ~1e-160. There the law is the same in double (a step
  // at t = -1, since 1 + t = O(Omega_x^2) < 1e-16 from Omega_x ~ 1e-8 down), and the raw integral
  // and 1 + t follow their leading orders, ~ 1/Omega_x and ~ Omega_x^2 (tests/laws: constant to
  // 6 digits from 1e-12 to 1e-30 rad/s): evaluated at kFloor and scaled.
  constexpr double kFloor = 1e-30;
  const bool scaled = s.omega_x != 0 && std::abs(s.omega_x) < kFloor;
  const double w_eval = scaled ? std::copysign(kFloor, s.omega_x) : s.omega_x;
  P->u = x.u, P->wx = w_eval, P->e = p.eps_n;
  P->Q = (1.0 + p.eps_n) * p.c2;
  P->pl = pi * p.lambda;
  P->A0 = (1.0 + p.eps_n) * P->Q * P->wx * P->wx;
  P->B0 = 4.0 * x.u * x.u * p.c2;
  P->sqB0 = std::sqrt(P->B0);
  const double disc = std::sqrt((1.0 + p.eps_n) * (1.0 + p.eps_n) + 4.0 * P->A0 / P->B0);
  P->hw = 0.5 * disc;
  P->tlo = 0.5 * ((p.eps_n - 1.0) - disc);
  P->thi = 0.5 * ((p.eps_n - 1.0) + disc);
  P->xhi = 0.5 * ((1.0 + p.eps_n) + disc);
  P->xlo = -2.0 * (P->A0 / P->B0) / ((1.0 + p.eps_n) + disc);  // 0.5 ((1 + eps_n) - disc) without cancellation
  P->log_cq = std::log(P->pl * P->Q / (2.0 * x.u * x.u * P->sqB0));
  P->log_cp = std::log(P->pl * P->Q / (2.0 * x.u * x.u));
  P->build();
  Law law;
  law.name = "eq28-printed";
  std::ostringstream d;
  d << "Eqs. 28-31 as printed (paper frame: V_z = u > 0, Omega_x as given, I = J/M, r_z = R + a, eps_n(u)); "
       "dimensionally inconsistent: f^2 adds (1+eps_n) Q Omega_x^2 [m^2/s^2] to 4 V_z^2 (...) (I + r_z^2) [m^4/s^2] "
       "and the exponent pi lambda (h+f)^2/(4 (1+t)^2 V_z^2) has units 1/s^2, so SI numbers are used as they come. "
       "f real on t in ["
    << num(P->tlo, 10) << ", " << num(P->thi, 10) << "]; raw integral of the printed pdf over it = "
    << log_number(P->log_raw + (scaled ? std::log(kFloor) - std::log(std::abs(s.omega_x)) : 0.0), P->sign_raw) << (P->negative_everywhere ? " (the printed pdf is < 0 wherever it does not underflow; its exponent is ~ -1e9 almost everywhere)" : " (the printed pdf changes sign)");
  double mean = P->thi;
  if (P->Z != 0) {
    const double x0 = P->at_phi(P->pieces.front().peak).x;
    const auto m = P->moments(x0);
    const double sd = std::sqrt(std::max(0.0, m.second - m.first * m.first));
    mean = (x0 + m.first) - 1.0;
    d << "; this Law = printed pdf / raw integral: mass at t = " << num(mean, 12);
    const double xm = scaled ? (x0 + m.first) * (s.omega_x / kFloor) * (s.omega_x / kFloor) : x0 + m.first;
    if (std::abs(x0 + m.first) < 1e-6) d << " (1 + t = " << num(xm, 6) << ")";
    d << " (sd " << num(sd, 3) << ")";
  } else {
    d << "; the printed pdf underflows everywhere: this Law is a step at t_hi";
  }
  if (scaled)
    d << "; |Omega_x| < " << num(kFloor) << " rad/s: evaluated at " << num(w_eval)
      << " rad/s, the raw integral scaled by its leading order ~ 1/Omega_x and 1 + t by ~ Omega_x^2";
  // (At Omega = 0 the exponent is ~ -3e9 + O(1): its rounding makes q noisy at ~3e-7 relative,
  // which limits the agreement of the two rules to ~3e-8. That is the floor of the literal formula
  // in double precision, far below the 1e-6 required.)
  // Where the signed spike's raw integral cancels (Omega_x = 1 rad/s at fig4's sphere: h + f Omega_x
  // = h + f vanishes at the spike's centre and the raw integral passes through 0, -8.7 at 0.99 and
  // +8.5 at 1.01), there is no normalised law: the two rules disagree, and the cdf throws (a report
  // skips the law, naming why) and the pdf is NaN, instead of dividing by rounding noise.
  const bool unresolved = P->Z != 0 && std::abs(P->Zcoarse / P->Z - 1.0) > 1e-6;
  if (unresolved)
    d << "; UNDEFINED: the raw integral cancels to rounding (relative change " << num(std::abs(P->Zcoarse / P->Z - 1.0), 2)
      << " between 128 and 256 panels), so the printed pdf cannot be normalised";
  d << "; " << scene_text(x);
  law.description = d.str();
  if (unresolved) {
    const std::string why = "eq28_printed: the printed pdf's raw integral cancels at Omega_x = " + num(s.omega_x, 17) +
                            " rad/s (relative change " + num(std::abs(P->Zcoarse / P->Z - 1.0), 2) +
                            " between 128 and 256 panels): no normalised law";
    law.cdf = [why](double) -> double { throw std::domain_error(why); };
    law.pdf = [](double) { return std::numeric_limits<double>::quiet_NaN(); };  // figures draw no curve
    law.mean = std::numeric_limits<double>::quiet_NaN();
    return law;
  }
  law.cdf = [P](double t) { return P->cdf(t); };
  law.pdf = [P](double t) { return P->pdf(t); };
  law.mean = mean;
  return law;
}

// =====================================================================================
double eq28_paper_route_eps(const ImpactLawParameters& p, double u, double omega_x, double s) {
  const double c2 = p.c2, e = p.eps_n;
  return e + (1.0 + e) * s * (omega_x * c2 - u * s) / (u * (s * s + c2));
}

double BounceResidualLaw::cdf(double t) const {
  const double tot = a1 + a2;
  if (t < 0) return a1 / tot * std::exp(t / a1);
  if (a2 == 0) return 1.0;
  return 1.0 - a2 / tot * std::exp(-t / a2);
}

std::vector<BounceResidualLaw> bounce_residual_laws(const ImpactScene& s0, unsigned k_max, bool paper_route) {
  ImpactScene s = s0;
  s.omega_x = s.omega_y = 0;
  s.core_contacts = false;
  std::vector<BounceResidualLaw> out;
  double u = s.speed, S2 = 0;
  for (unsigned k = 1; k <= k_max; ++k) {
    // The linearised law predicts the k-th impact speed; where it predicts none (a spread of r so
    // wide that -- e.g. N = 1 -- the mean rebound turns negative) the law of that impact and of
    // every later one does not exist: the groups that need it get no theory test.
    if (!(u > 0) || !std::isfinite(u)) break;
    s.speed = u;
    const auto p = impact_law_parameters(s);
    BounceResidualLaw L;
    L.k = k, L.speed = u, L.eps_n = p.eps_n, L.spin_sd = std::sqrt(S2);
    const double beta1 = (1.0 + p.eps_n) / u + (paper_route ? 0.0 : p.eps_n_prime);
    L.tau = beta1 * L.spin_sd / (2.0 * p.alpha);
    const double s2 = p.sigma * p.sigma, lp = 0.5 * (s2 + std::sqrt(s2 * s2 + 4.0 * s2 * L.tau * L.tau));
    const double lm = -s2 * L.tau * L.tau / lp;  // lambda_+ lambda_- = -sigma^2 tau^2, no cancellation
    L.a1 = 2.0 * p.alpha * lp, L.a2 = -2.0 * p.alpha * lm;
    out.push_back(L);
    S2 += p.sigma_c * p.sigma_c;
    u *= p.eps_n - 2.0 * p.alpha * s2;
  }
  return out;
}

}  // namespace asperity
