// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/core/free_rotation.hpp"

#include <Eigen/Eigenvalues>
#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/special_functions/ellint_1.hpp>
#include <boost/math/special_functions/jacobi_elliptic.hpp>

#include <algorithm>
#include <limits>
#include <numbers>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/format.hpp"

namespace asperity {

using detail::num;

namespace {

// Boost.Math promotes double to long double internally by default: x87 arithmetic, 10x slower
// (2.3 us per jacobi_elliptic call against 0.22-0.37 us), for digits the closed form does not need:
// jacobi_elliptic forms k' from 1 - k without cancellation. ellint_1 (constructor only) keeps the
// promotion: in double, 1 - k^2 loses the digits of k' near the separatrix (measured without it:
// 7.6e-12 of the tennis-racket period in the tests, 4e-10 in the state 1e-9 off the separatrix).
using Fast = boost::math::policies::policy<boost::math::policies::promote_double<false>>;

void validate(const Eigen::Matrix3d& J, const Rotation& q0, const Vec3& w0) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!std::isfinite(J(i, j)))
        throw std::invalid_argument("FreeRotation: inertia_body(" + std::to_string(i) + "," + std::to_string(j) +
                                    ") must be finite, got " + num(J(i, j)));
  const double scale = J.cwiseAbs().maxCoeff();
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      if (std::abs(J(i, j) - J(j, i)) > 1e-12 * scale)
        throw std::invalid_argument("FreeRotation: inertia_body must be symmetric, got (" + std::to_string(i) + "," +
                                    std::to_string(j) + ") = " + num(J(i, j)) + " and (" + std::to_string(j) + "," +
                                    std::to_string(i) + ") = " + num(J(j, i)));
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(J, Eigen::EigenvaluesOnly).eigenvalues();
  if (!(ev(0) > 0))
    throw std::invalid_argument("FreeRotation: inertia_body must be positive definite, smallest principal moment " +
                                num(ev(0)) + " kg m^2");
  // A rigid body has J1 + J2 >= J3 (equality for a flat plate); rounding of the eigen-solver allowed.
  if (ev(0) + ev(1) < ev(2) * (1 - 1e-12))
    throw std::invalid_argument("FreeRotation: principal moments " + num(ev(0)) + ", " + num(ev(1)) + ", " +
                                num(ev(2)) + " kg m^2 violate the triangle inequality J1 + J2 >= J3");
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(w0(i)))
      throw std::invalid_argument("FreeRotation: omega0(" + std::to_string(i) + ") must be finite, got " + num(w0(i)));
  const double n = q0.norm();
  if (!std::isfinite(n) || std::abs(n - 1) > 1e-9)
    throw std::invalid_argument("FreeRotation: q0 must be a unit quaternion, |q0| = " + num(n));
}

}  // namespace


// The closed form (Landau & Lifshitz Sec. 37). Principal moments ascending J1 <= J2 <= J3 and
// D = L^2 / 2T. For D > J2 the body circulates about axis 3, for D < J2 about axis 1; the second
// case is the first in the working frame (e3, -e2, e1) with moments (J3, J2, J1), so one set of
// formulas with SIGNED differences d_ij = J_i - J_j serves both (sigma = sign d32). In the working
// frame w = (s1 A1 cn u, A2 sn u, s3 A3 dn u), u = u0 + wp t, s3 = sign w3(0), s1 = sigma s3.
//
// Orientation: l(t) = J w / |L| (working frame) must map onto the fixed world direction of L. With
// n = s3 e3 (n.l > 0 always: w3 never changes sign), M(t) = the minimal rotation taking l to n, and
// R(t) = G0 Rot_n(psi) M(t) (working frame -> world), R^T R' = [w] gives w = psi' l + mu (mu the
// body angular velocity of M), so psi' = w.l - mu.l = 2T/|L| - n.(l x l')/(1 + n.l) (the twist of
// the minimal rotation; its sign is checked by the Odeint comparison, and flipping it fails there).
// With the elliptic form l1 l2' - l2 l1' = (J1 J2 s1 A1 A2 / L^2) wp dn u, hence
//   psi(t) = (2T/|L|) t - sigma J1 J2 A1 A2 / L^2 [G(u) - G(u0)],  G(u) = int_0^u dn/(1 + c dn),
// c = J3 A3 / |L| = n.l at dn = 1. The integrand has period 2K and is even, so G(u) = 2 m G(K) + G(r)
// with |r| <= K: one quadrature over [0, K] in the constructor, one over [0, |r|] per call.
// (The third-kind elliptic integral form of G cancels catastrophically as c -> 1, i.e. near pure
// rotation about axis 3: its two terms grow like 1 / (1 - c^2).)
//
// No threshold separates the cases: c = L^2 - 2 T J2 = J3 d32 w3^2 - J1 d21 w1^2 (without the
// cancellation of the large terms of L^2 and 2 T J2) decides the regime. c = 0 with w3 = 0 or
// d32 = 0 (then both terms vanish) means J w || w: a steady rotation about a principal axis (incl.
// rest, the spherical top and the unstable intermediate axis); any other c = 0 is the separatrix
// (k = 1: sn = tanh, cn = dn = sech). Symmetric tops are k = 0 (regular precession), and nearly
// degenerate moments are just small k or wp: the parameters are products and quotients of the
// signed differences d_ij (no cancellation), so they keep their relative precision as d_ij -> 0.
struct FreeRotation::Impl {
  enum class Kind { steady, periodic, separatrix } kind = Kind::steady;
  Rotation q0;
  Vec3 omega0;
  Vec3 L;
  double T = 0;
  // elliptic parameters (working frame)
  Rotation Pw = Rotation::Identity();  // working frame -> body
  Rotation G0 = Rotation::Identity();  // R(0) M(0)^T
  double J[3] = {0, 0, 0};
  double A[3] = {0, 0, 0};  // signed: (s1 A1, A2, s3 A3)
  double Lnorm = 0, rate0 = 0, coef = 0, c = 0;
  double wp = 0, k = 0, K = 0, GK = 0, u0 = 0, Gu0 = 0;
  Vec3 n{0, 0, 1};

  static constexpr double kSeparatrixU = 40;  // sech(40) = 8.5e-18: the rest of G is below rounding

  double g(double u) const {
    double cn, dn;
    boost::math::jacobi_elliptic(k, u, &cn, &dn, Fast());
    return dn / (1 + c * dn);
  }
  // int_0^x g, x >= 0, by 20-point Gauss-Legendre on pieces of length <= 2.5. g is analytic in the
  // strip |Im u| < K' >= pi/2 (at the poles of dn, g -> 1/c is finite; g is singular only where
  // dn = -1/c, beyond K'), so on a piece of half-length h <= 1.25 the error is ~ rho^-40 with
  // rho = b/h + sqrt(1 + b^2/h^2) >= 2.87: below 1e-18 relative. (Boost 1.74's adaptive
  // Gauss-Kronrod compares an unscaled error with a scaled tolerance and bisects short intervals
  // to its depth limit: 1e3-6e4 evaluations instead of 31.)
  double quad(double x) const {
    if (x == 0) return 0;
    const int pieces = static_cast<int>(std::ceil(x / 2.5));
    const double h = x / pieces;
    double sum = 0;
    for (int i = 0; i < pieces; ++i)
      sum += boost::math::quadrature::gauss<double, 20>::integrate([this](double u) { return g(u); }, i * h,
                                                                 (i + 1) * h);
    return sum;
  }
  double G(double u) const {
    if (kind == Kind::separatrix) return std::copysign(quad(std::min(std::abs(u), kSeparatrixU)), u);
    const double m = std::floor((u + K) / (2 * K));
    const double r = u - 2 * K * m;
    return 2 * m * GK + std::copysign(quad(std::abs(r)), r);
  }
  Vec3 w_work(double u) const {
    // Reduced by whole periods first, so that sn^2 + cn^2 = 1 and dn^2 + k^2 sn^2 = 1 hold to
    // rounding at any t (T and |L| conserved); the phase keeps its unavoidable error eps u.
    if (kind == Kind::periodic) u -= 4 * K * std::round(u / (4 * K));
    double cn, dn;
    const double sn = boost::math::jacobi_elliptic(k, u, &cn, &dn, Fast());
    return {A[0] * cn, A[1] * sn, A[2] * dn};
  }
  Rotation M(const Vec3& w) const {  // minimal rotation l -> n
    const Vec3 l = Vec3(J[0] * w.x(), J[1] * w.y(), J[2] * w.z()) / Lnorm;
    const Vec3 ax = l.cross(n);
    return Rotation(1 + l.dot(n), ax.x(), ax.y(), ax.z()).normalized();
  }
};

FreeRotation::FreeRotation(const Eigen::Matrix3d& inertia_body, const Rotation& q0, const Vec3& omega0) {
  validate(inertia_body, q0, omega0);
  auto p = std::make_shared<Impl>();
  const Eigen::Matrix3d Jb = 0.5 * (inertia_body + inertia_body.transpose());
  p->q0 = q0.normalized();
  p->omega0 = omega0;
  const Eigen::Matrix3d Rq = p->q0.toRotationMatrix();
  p->L = Rq * (Jb * (Rq.transpose() * omega0));
  p->T = 0.5 * omega0.dot(p->L);

  // Principal frame: deterministic signs (largest component of each axis positive), right-handed.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(Jb);
  Eigen::Matrix3d P = es.eigenvectors();
  for (int j = 0; j < 3; ++j) {
    Eigen::Index i;
    P.col(j).cwiseAbs().maxCoeff(&i);
    if (P(i, j) < 0) P.col(j) = -P.col(j);
  }
  if (P.determinant() < 0) P.col(1) = -P.col(1);
  const Eigen::Vector3d Jp = es.eigenvalues();
  const Vec3 w = P.transpose() * (Rq.transpose() * omega0);
  const double d21 = Jp(1) - Jp(0), d32 = Jp(2) - Jp(1);
  const double c = Jp(2) * d32 * w.z() * w.z() - Jp(0) * d21 * w.x() * w.x();  // L^2 - 2 T J2
  if (c == 0 && (w.z() == 0 || d32 == 0)) {
    p->kind = Impl::Kind::steady;  // J w parallel to w: rest, spherical top, principal axis
    impl_ = std::move(p);
    return;
  }
  Eigen::Matrix3d Pw = P;
  Vec3 ww = w;
  double Jw[3] = {Jp(0), Jp(1), Jp(2)};
  if (c < 0) {  // about axis 1: working frame (e3, -e2, e1)
    Pw.col(0) = P.col(2), Pw.col(1) = -P.col(1), Pw.col(2) = P.col(0);
    ww = Vec3(w.z(), -w.y(), w.x());
    std::swap(Jw[0], Jw[2]);
  }
  p->Pw = Rotation(Pw).normalized();
  for (int i = 0; i < 3; ++i) p->J[i] = Jw[i];
  const double J1 = Jw[0], J2 = Jw[1], J3 = Jw[2];
  const double e21 = J2 - J1, e31 = J3 - J1, e32 = J3 - J2;  // signed; e32 and e31 have sign sigma
  const double sigma = e32 > 0 ? 1.0 : -1.0;
  const double w1 = ww.x(), w2 = ww.y(), w3 = ww.z();
  const double A1 = std::sqrt(w1 * w1 + (J2 * e32) / (J1 * e31) * w2 * w2);
  const double A2 = std::sqrt(w2 * w2 + (J1 * e31) / (J2 * e32) * w1 * w1);
  const double A3 = std::sqrt(w3 * w3 + (J2 * e21) / (J3 * e31) * w2 * w2);
  const double a = J1 * e31 * w1 * w1 + J2 * e32 * w2 * w2;  // 2 T J3 - L^2 (signed like sigma)
  const double b = J2 * e21 * w2 * w2 + J3 * e31 * w3 * w3;  // L^2 - 2 T J1 (signed like sigma)
  const double s3 = w3 > 0 ? 1.0 : -1.0, s1 = sigma * s3;
  p->A[0] = s1 * A1, p->A[1] = A2, p->A[2] = s3 * A3;
  p->n = Vec3(0, 0, s3);
  p->Lnorm = p->L.norm();
  p->rate0 = 2 * p->T / p->Lnorm;
  p->coef = -sigma * J1 * J2 * A1 * A2 / (p->Lnorm * p->Lnorm);
  p->c = J3 * A3 / p->Lnorm;
  p->wp = std::sqrt(e32 * b / (J1 * J2 * J3));
  const double k2 = e21 * a / (e32 * b);
  p->k = std::sqrt(std::min(1.0, std::max(0.0, k2)));
  if (c == 0 || p->k >= 1) {
    p->k = 1;
    p->kind = Impl::Kind::separatrix;
    // sinh u0 = tanh u0 / sech u0 = (w2 / A2) / (|w3| / A3)
    p->u0 = std::asinh((w2 / A2) * (A3 / std::abs(w3)));
  } else {
    p->kind = Impl::Kind::periodic;
    p->K = boost::math::ellint_1(p->k);
    const double phi0 = (A1 == 0 && A2 == 0) ? 0.0 : std::atan2(w2 / A2, w1 / p->A[0]);
    p->u0 = boost::math::ellint_1(p->k, phi0);
    p->GK = p->quad(p->K);
  }
  p->Gu0 = p->G(p->u0);
  p->G0 = p->q0 * p->Pw * p->M(p->w_work(p->u0)).conjugate();
  impl_ = std::move(p);
}

RotationState FreeRotation::at(double t) const {
  const Impl& p = *impl_;
  if (p.kind == Impl::Kind::steady) {
    const double wn = p.omega0.norm();
    if (wn == 0 || t == 0) return {p.q0, p.omega0};
    return {(Rotation(Eigen::AngleAxisd(wn * t, p.omega0 / wn)) * p.q0).normalized(), p.omega0};
  }
  const double u = p.u0 + p.wp * t;
  const Vec3 w = p.w_work(u);
  const double psi = p.rate0 * t + p.coef * (p.G(u) - p.Gu0);
  const Rotation R = p.G0 * Rotation(Eigen::AngleAxisd(psi, p.n)) * p.M(w);
  RotationState s;
  s.q = (R * p.Pw.conjugate()).normalized();
  s.omega = R * w;
  return s;
}

double FreeRotation::period() const {
  const Impl& p = *impl_;
  if (p.kind != Impl::Kind::periodic) return std::numeric_limits<double>::infinity();
  return 4 * p.K / p.wp;
}

Vec3 FreeRotation::angular_momentum() const { return impl_->L; }
double FreeRotation::kinetic_energy() const { return impl_->T; }

}  // namespace asperity
