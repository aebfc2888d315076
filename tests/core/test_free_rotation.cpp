// SPDX-License-Identifier: GPL-3.0-or-later
// FreeRotation: torque-free motion of an asymmetric rigid body. The closed form is checked against
// an independent Odeint integration of Euler's equations (src/free_rotation_reference.hpp), against
// the closed forms of its degenerate cases, and against the symmetries of the motion.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <boost/math/special_functions/ellint_1.hpp>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "asperity/experiments/bounce.hpp"
#include "asperity/core/free_rotation.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/random.hpp"
#include "core/free_rotation_reference.hpp"
#include "sanitized.hpp"

using namespace asperity;

namespace {
double qdist(const Rotation& a, const Rotation& b) {
  return std::min((a.coeffs() - b.coeffs()).norm(), (a.coeffs() + b.coeffs()).norm());
}
Eigen::Matrix3d body_inertia(double J1, double J2, double J3, const Rotation& frame) {
  const Eigen::Matrix3d R = frame.toRotationMatrix();
  return R * Eigen::Vector3d(J1, J2, J3).asDiagonal() * R.transpose();
}
Eigen::Matrix3d diag(double a, double b, double c) { return Eigen::Vector3d(a, b, c).asDiagonal(); }
double state_error(const RotationState& r, const RotationState& s, double wscale) {
  return std::max(qdist(r.q, s.q), (r.omega - s.omega).norm() / wscale);
}

struct Body {
  Eigen::Matrix3d J;
  Rotation q0;
  Vec3 w0;
};
// Principal moments from random second moments x, y, z of a mass distribution (J1 = y + z, ...),
// so the triangle inequality holds by construction; random principal frame, orientation and spin
// direction; moment scale log-uniform in 1e-12..1e2 kg m^2 (a 3 mm grain has ~4e-10), |Omega|
// log-uniform in [1e-3, 1e3] rad/s.
Body random_body(std::uint64_t i) {
  Stream s(7, Purpose::test, i);
  const double x = s.uniform(), y = s.uniform(), z = s.uniform();
  const double m = std::pow(10.0, 14 * s.uniform() - 12);
  Body b;
  b.J = body_inertia(m * (y + z), m * (x + z), m * (x + y), random_rotation(s));
  b.q0 = random_rotation(s);
  b.w0 = std::pow(10.0, 6 * s.uniform() - 3) * uniform_on_sphere(s.uniform(), s.uniform());
  return b;
}
// Times for one body: fractions and multiples of the period, both signs, with |Omega| t <= 400 rad
// so that the reference integration stays cheap and its own error small.
std::vector<double> test_times(const FreeRotation& f, const Vec3& w0) {
  const double P = std::isfinite(f.period()) ? f.period() : 10 / w0.norm();
  std::vector<double> out;
  for (double x : {0.0, 0.1, 0.37, 0.5, 1.0, 2.5, -1.3, 7.9, -20.0}) {
    const double t = x * P;
    if (std::abs(t) * w0.norm() <= 400) out.push_back(t);
  }
  out.push_back(100 / w0.norm());
  return out;
}
// The comparison helper: largest orientation distance and relative angular-velocity difference of
// `state_at` against the Odeint reference over the times.
template <class F>
double max_error(const Body& b, F&& state_at, const std::vector<double>& times) {
  double e = 0;
  for (double t : times)
    e = std::max(e, state_error(detail::reference_free_rotation(b.J, b.q0, b.w0, t), state_at(t), b.w0.norm()));
  return e;
}
// Tolerance against the reference: RKF78 at 1e-13 per step accumulates ~1e-13 per radian of spin
// over <= 400 rad (measured worst below ~1e-11); the closed form's own error is ~1e-14. 1e-10 leaves
// a factor 10 and is 1e4 below the smallest deliberate error the wrong implementations make.
constexpr double kRefTol = 1e-10;
}  // namespace

TEST(FreeRotation, MatchesOdeintReferenceForRandomBodies) {
  // 150 bodies in Release; 30 under the sanitizers, where the test took 34 s (its Odeint reference
  // is test code, built at -O0 there): the memory checks see the same code paths on fewer bodies.
  const std::uint64_t bodies = asperity::testing::kSanitized ? 30 : 150;
  double worst = 0;
  for (std::uint64_t i = 0; i < bodies; ++i) {
    const Body b = random_body(i);
    const FreeRotation f(b.J, b.q0, b.w0);
    const double e = max_error(b, [&](double t) { return f.at(t); }, test_times(f, b.w0));
    worst = std::max(worst, e);
    EXPECT_LT(e, kRefTol) << "body " << i;
  }
  std::printf("worst error against Odeint over %llu bodies: %.3g\n", static_cast<unsigned long long>(bodies), worst);
}

TEST(FreeRotation, ComparisonRejectsWrongImplementations) {
  // The same helper and tolerance must fail (a) a body with two principal moments swapped, (b) the
  // naive q(t) = exp(Omega0 t) q0 (what a sphere does), (c) the right motion with the angle about L
  // off by a relative 1e-6 of its mean rate (a small error in the psi rate).
  for (std::uint64_t i = 0; i < 20; ++i) {
    const Body b = random_body(i);
    const FreeRotation f(b.J, b.q0, b.w0);
    const auto times = test_times(f, b.w0);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(b.J);
    const Eigen::Vector3d ev = es.eigenvalues();
    const Eigen::Matrix3d P = es.eigenvectors();
    const Eigen::Matrix3d Jswap = P * Eigen::Vector3d(ev(1), ev(0), ev(2)).asDiagonal() * P.transpose();
    const FreeRotation swapped(Jswap, b.q0, b.w0);
    EXPECT_GT(max_error(b, [&](double t) { return swapped.at(t); }, times), 1e3 * kRefTol) << i;
    EXPECT_GT(max_error(b, [&](double t) { return RotationState{advance_rotation(b.q0, b.w0, t), b.w0}; }, times),
              1e3 * kRefTol)
        << i;
    const Vec3 Lhat = f.angular_momentum().normalized();
    const double rate = 2 * f.kinetic_energy() / f.angular_momentum().norm();
    auto off = [&](double t) {
      RotationState s = f.at(t);
      const Rotation d(Eigen::AngleAxisd(1e-6 * rate * t, Lhat));
      return RotationState{d * s.q, d * s.omega};
    };
    EXPECT_GT(max_error(b, off, times), 1e3 * kRefTol) << i;
  }
}

TEST(FreeRotation, ConservesMomentumAndEnergyAtEveryTime) {
  double worst = 0;
  for (std::uint64_t i = 0; i < 100; ++i) {
    const Body b = random_body(i);
    const FreeRotation f(b.J, b.q0, b.w0);
    const double P = std::isfinite(f.period()) ? f.period() : 1 / b.w0.norm();
    for (double x : {0.0, 0.123, 0.77, -3.3, 41.5, 1234.5, -98765.4}) {
      const RotationState s = f.at(x * P);
      const Eigen::Matrix3d R = s.q.toRotationMatrix();
      const Vec3 L = R * b.J * R.transpose() * s.omega;
      const double eL = (L - f.angular_momentum()).norm() / f.angular_momentum().norm();
      const double eT = std::abs(0.5 * s.omega.dot(L) - f.kinetic_energy()) / f.kinetic_energy();
      worst = std::max({worst, eL, eT});
      EXPECT_LT(eL, 1e-13) << i << " t/P = " << x;
      EXPECT_LT(eT, 1e-13) << i << " t/P = " << x;
    }
  }
  std::printf("worst relative drift of L, T: %.3g\n", worst);
}

TEST(FreeRotation, CompositionAndTimeReversal) {
  // A flight started from the state at t1 continues it: at(t1 + t2); reversing the spin at t
  // returns to (q0, -Omega0) after t; at(-t) runs the same motion backwards.
  double worst = 0;
  for (std::uint64_t i = 0; i < 100; ++i) {
    const Body b = random_body(i);
    const FreeRotation f(b.J, b.q0, b.w0);
    const double P = std::isfinite(f.period()) ? f.period() : 1 / b.w0.norm();
    const double t1 = 0.731 * P, t2 = 2.19 * P;
    const RotationState s1 = f.at(t1);
    const FreeRotation g(b.J, s1.q, s1.omega);
    const double e1 = state_error(g.at(t2), f.at(t1 + t2), b.w0.norm());
    const FreeRotation back(b.J, s1.q, -s1.omega);
    const double e2 = state_error(back.at(t1), {b.q0, -b.w0}, b.w0.norm());
    const FreeRotation rev(b.J, b.q0, -b.w0);
    const RotationState r = rev.at(t1), m = f.at(-t1);
    const double e3 = state_error({r.q, -r.omega}, m, b.w0.norm());
    worst = std::max({worst, e1, e2, e3});
    EXPECT_LT(e1, 1e-12) << i;
    EXPECT_LT(e2, 1e-12) << i;
    EXPECT_LT(e3, 1e-12) << i;
  }
  std::printf("worst composition / reversal error: %.3g\n", worst);
}

TEST(FreeRotation, InvariantUnderRelabellingTheBodyAxes) {
  // Describing the same body in another body frame (J' = S^T J S, q0' = q0 S, S a rotation: a
  // cyclic permutation of the axes, a permutation with a sign, a random rotation) changes nothing
  // in the world: q'(t) = q(t) S, Omega'(t) = Omega(t).
  double worst = 0;
  for (std::uint64_t i = 0; i < 50; ++i) {
    const Body b = random_body(i);
    const FreeRotation f(b.J, b.q0, b.w0);
    Eigen::Matrix3d cyc, swp;
    cyc << 0, 0, 1, 1, 0, 0, 0, 1, 0;
    swp << 0, 1, 0, 1, 0, 0, 0, 0, -1;
    Stream s(11, Purpose::test, i);
    for (const Rotation& S : {Rotation(cyc), Rotation(swp), random_rotation(s)}) {
      const Eigen::Matrix3d Sm = S.toRotationMatrix();
      const FreeRotation g(Sm.transpose() * b.J * Sm, b.q0 * S, b.w0);
      for (double t : test_times(f, b.w0)) {
        const RotationState a = f.at(t), c = g.at(t);
        const double e = state_error({a.q * S, a.omega}, c, b.w0.norm());
        worst = std::max(worst, e);
        EXPECT_LT(e, 1e-11) << i << " t = " << t;
      }
    }
  }
  std::printf("worst relabelling error: %.3g\n", worst);
}

TEST(FreeRotation, RestAndSphericalTop) {
  const Rotation q0 = Rotation(0.3, -0.5, 0.2, 0.7).normalized();
  const FreeRotation rest(body_inertia(1, 2, 2.5, Rotation(0.5, 0.5, 0.5, 0.5)), q0, Vec3::Zero());
  EXPECT_EQ(rest.at(123.0).q.coeffs(), q0.coeffs());
  EXPECT_EQ(rest.at(-5.0).omega, Vec3::Zero());
  EXPECT_FALSE(std::isfinite(rest.period()));
  const Vec3 w(0.7, -1.3, 0.4);
  const FreeRotation sph(0.4 * Eigen::Matrix3d::Identity(), q0, w);
  for (double t : {0.0, 0.37, -1.2, 5.0, 1e4}) {
    const RotationState s = sph.at(t);
    EXPECT_LT(qdist(s.q, advance_rotation(q0, w, t)), 1e-15 * (1 + std::abs(t))) << t;
    EXPECT_EQ(s.omega, w) << t;
  }
}

TEST(FreeRotation, SymmetricTopsPrecessRegularly) {
  // Closed form: q(t) = exp(Omega_p t Lhat) q0 exp(w_s t e), precession Omega_p = |L| / J_perp
  // about L, spin w_s = w_e (1 - J_e / J_perp) about the symmetry axis e (body frame).
  Stream s(3, Purpose::test, 0);
  for (const auto& [Jp, Je] : {std::pair{2.0, 1.0}, std::pair{1.0, 1.8}, std::pair{1.0, 1e-3 + 1.0}}) {
    for (int rep = 0; rep < 5; ++rep) {
      const Rotation frame = random_rotation(s), q0 = random_rotation(s);
      const Eigen::Matrix3d J = body_inertia(Jp, Jp, Je, frame);
      const Vec3 w0 = 3.0 * uniform_on_sphere(s.uniform(), s.uniform());
      const FreeRotation f(J, q0, w0);
      const Vec3 e = frame * Vec3::UnitZ();
      const double we = (q0.conjugate() * w0).dot(e);
      const Vec3 L = f.angular_momentum();
      for (double t : {0.0, 0.3, -2.0, 17.0, 500.0}) {
        const Rotation q = Rotation(Eigen::AngleAxisd(L.norm() / Jp * t, L.normalized())) * q0 *
                           Rotation(Eigen::AngleAxisd(we * (1 - Je / Jp) * t, e));
        const RotationState st = f.at(t);
        EXPECT_LT(qdist(st.q, q), 1e-13 * (1 + std::abs(t) * w0.norm())) << Jp << " " << Je << " t = " << t;
        const Eigen::Matrix3d R = q.toRotationMatrix();
        const Vec3 W = R * J.inverse() * R.transpose() * L;
        EXPECT_LT((st.omega - W).norm(), 1e-13 * (1 + std::abs(t) * w0.norm()) * w0.norm()) << t;
      }
    }
  }
}

TEST(FreeRotation, SteadyRotationAboutEachPrincipalAxis) {
  // Including the unstable intermediate axis: exactly along it the body stays (Omega constant).
  const Rotation frame(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  const Eigen::Matrix3d J = body_inertia(1.0, 2.0, 2.5, frame);
  const Rotation q0 = Rotation(0.6, 0.1, 0.2, -0.3).normalized();
  for (int axis = 0; axis < 3; ++axis) {
    const Vec3 w0 = 2.0 * (q0 * (frame * Vec3::Unit(axis)));
    const FreeRotation f(J, q0, w0);
    for (double t : {0.25, -3.0, 40.0}) {
      const RotationState s = f.at(t);
      EXPECT_LT(qdist(s.q, advance_rotation(q0, w0, t)), 1e-14 * (1 + std::abs(t))) << axis << " " << t;
      EXPECT_LT((s.omega - w0).norm(), 1e-13) << axis << " " << t;
    }
  }
}

namespace {
// J = diag(3, 4, 6), w = (2, w2, 1): L^2 - 2 T J2 = 6 (6 - 4) 1 - 3 (4 - 3) 4 = 0 exactly.
const Eigen::Matrix3d kSepJ = diag(3, 4, 6);
}  // namespace

TEST(FreeRotation, SeparatrixAndItsNeighbourhood) {
  // On the separatrix sn -> tanh, cn, dn -> sech; nearby (w1 scaled by 1 +- delta, both regimes)
  // the periodic solution must agree with it, and everything with Odeint, while the motion is
  // still well conditioned (it leaves the separatrix like exp(wp t), so times wp t <= 6 here).
  // q0 = identity: any other rotation of omega0 into the body would round c away from 0.
  const Vec3 wsep(2, 0.7, 1);
  const Body bs{kSepJ, Rotation::Identity(), wsep};
  const FreeRotation sep(bs.J, bs.q0, bs.w0);
  EXPECT_FALSE(std::isfinite(sep.period()));
  const std::vector<double> times{0.0, 0.5, 1.5, -2.0, 3.0};
  EXPECT_LT(max_error(bs, [&](double t) { return sep.at(t); }, times), 1e-11);
  for (double delta : {1e-15, 1e-12, 1e-9, 1e-6}) {
    for (double sgn : {1.0, -1.0}) {
      const Body b{kSepJ, Rotation::Identity(), Vec3(2 * (1 + sgn * delta), 0.7, 1)};
      const FreeRotation f(b.J, b.q0, b.w0);
      EXPECT_TRUE(std::isfinite(f.period())) << delta;
      EXPECT_LT(max_error(b, [&](double t) { return f.at(t); }, times), 1e-11) << delta << " " << sgn;
      for (double t : times)  // continuity: the difference is of the order of the perturbation
        EXPECT_LT(state_error(f.at(t), sep.at(t), 2.3), 1e3 * delta + 1e-12) << delta << " " << sgn << " " << t;
    }
  }
}

TEST(FreeRotation, TennisRacketFlip) {
  // Spun nearly about the intermediate axis, the body flips: w2 changes sign every half period,
  // and the period equals Landau's 4 K(k) / omega_p computed here from L and T alone.
  const double J1 = 1, J2 = 2, J3 = 2.5;
  const Vec3 wb(1e-3, 5.0, 2e-3);
  const FreeRotation f(diag(J1, J2, J3), Rotation::Identity(), wb);
  const double L2 = f.angular_momentum().squaredNorm(), T2 = 2 * f.kinetic_energy();
  ASSERT_GT(L2, T2 * J2);  // about axis 3
  // 2 T J3 - L^2 and L^2 - 2 T J1 written as sums of positive terms: near the intermediate axis
  // the textbook differences would lose 8 digits to cancellation (and 1e-9 of the period).
  const double a = J1 * (J3 - J1) * wb.x() * wb.x() + J2 * (J3 - J2) * wb.y() * wb.y();
  const double b = J2 * (J2 - J1) * wb.y() * wb.y() + J3 * (J3 - J1) * wb.z() * wb.z();
  EXPECT_NEAR(a, T2 * J3 - L2, 1e-12 * L2);
  EXPECT_NEAR(b, L2 - T2 * J1, 1e-12 * L2);
  const double wp = std::sqrt((J3 - J2) * b / (J1 * J2 * J3));
  const double k = std::sqrt((J2 - J1) * a / ((J3 - J2) * b));
  const double P = 4 * boost::math::ellint_1(k) / wp;
  EXPECT_NEAR(f.period(), P, 1e-12 * P);
  auto body_w = [](const RotationState& s) { return Vec3(s.q.conjugate() * s.omega); };
  EXPECT_LT(std::abs(body_w(f.at(0.5 * P)).y() + wb.y()), 1e-3);  // flipped
  EXPECT_LT((body_w(f.at(P)) - wb).norm(), 1e-12);                 // back
  // ... and the integrator, which knows nothing of K(k), is back there too.
  EXPECT_LT((body_w(detail::reference_free_rotation(diag(J1, J2, J3), Rotation::Identity(), wb, P)) - wb).norm(),
            1e-9);
  const Body body{diag(J1, J2, J3), Rotation::Identity(), wb};
  EXPECT_LT(max_error(body, [&](double t) { return f.at(t); }, {0.25 * P, 0.5 * P, P}), kRefTol);
}

TEST(FreeRotation, NearDegenerateMomentsAreContinuous) {
  // J1 = J2 (1 + delta) and the nearly spherical J = (1, 1 + delta, 1 + 2 delta): no threshold
  // switches formulas, so the error against Odeint stays small for every delta and the motion
  // depends continuously on delta (difference ~ delta |Omega| t).
  Stream s(5, Purpose::test, 0);
  const Rotation frame = random_rotation(s), q0 = random_rotation(s);
  for (const Vec3& w0 : {Vec3(0.3, 1.1, -0.8), Vec3(1.0, 0.2, 0.01), Vec3(0.01, 0.02, 1.3)}) {
    for (bool sphere : {false, true}) {
      auto J_of = [&](double d) {
        return sphere ? body_inertia(1, 1 + d, 1 + 2 * d, frame) : body_inertia(2 * (1 + d), 2, 3, frame);
      };
      const FreeRotation f0(J_of(0), q0, w0);
      for (double d : {1e-16, 1e-14, 1e-12, 1e-9, 1e-6, 1e-3}) {
        const Body b{J_of(d), q0, w0};
        const FreeRotation f(b.J, b.q0, b.w0);
        const std::vector<double> times{0.5, -3.0, 40.0};
        EXPECT_LT(max_error(b, [&](double t) { return f.at(t); }, times), kRefTol) << d << " " << sphere;
        for (double t : times)
          EXPECT_LT(state_error(f.at(t), f0.at(t), w0.norm()), 10 * d * (1 + w0.norm() * std::abs(t)) + 1e-13)
              << d << " " << sphere << " " << t;
      }
    }
  }
}

TEST(FreeRotation, PrecessionRateIsLandaus) {
  // Landau's Euler angles with Z along L: the line of nodes N = Z x e3 turns at
  // dphi/dt = |L| (J1 w1^2 + J2 w2^2) / (J1^2 w1^2 + J2^2 w2^2). at() uses another gauge (the
  // minimal rotation of l onto e3), so this checks the orientation by an independent formula.
  // Central differences with h = 1e-4 s: truncation ~h^2 |d3phi/dt3| ~ 1e-8, tolerance 1e-7.
  const double J1 = 1, J2 = 2, J3 = 2.5;
  const Rotation q0 = Rotation(0.2, 0.5, -0.4, 0.7).normalized();
  const FreeRotation f(diag(J1, J2, J3), q0, q0 * Vec3(0.3, 0.2, 1.0));
  const Vec3 Z = f.angular_momentum().normalized();
  const Vec3 X = Z.unitOrthogonal(), Y = Z.cross(X);
  auto phi = [&](double t) {
    const Vec3 N = Z.cross(f.at(t).q * Vec3::UnitZ());
    return std::atan2(N.dot(Y), N.dot(X));
  };
  const double h = 1e-4;
  for (double t : {0.0, 0.7, 2.9, 6.1, -4.4}) {
    const RotationState s = f.at(t);
    const Vec3 w = s.q.conjugate() * s.omega;
    const double rate = f.angular_momentum().norm() * (J1 * w.x() * w.x() + J2 * w.y() * w.y()) /
                        (J1 * J1 * w.x() * w.x() + J2 * J2 * w.y() * w.y());
    double d = phi(t + h) - phi(t - h);
    d -= 2 * std::numbers::pi * std::round(d / (2 * std::numbers::pi));
    EXPECT_NEAR(d / (2 * h), rate, 1e-7 * rate) << t;
  }
}

TEST(FreeRotation, BadInputThrowsNamingTheValue) {
  const Rotation q = Rotation::Identity();
  const Vec3 w(1, 0, 0);
  auto msg = [](auto&& fn) {
    try {
      fn();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no throw");
  };
  Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
  J(0, 1) = NAN;
  EXPECT_NE(msg([&] { FreeRotation(J, q, w); }).find("inertia_body(0,1) must be finite, got nan"), std::string::npos);
  J = Eigen::Matrix3d::Identity();
  J(0, 1) = 0.1;
  EXPECT_NE(msg([&] { FreeRotation(J, q, w); }).find("symmetric"), std::string::npos);
  EXPECT_NE(msg([&] { FreeRotation(diag(-1, 1, 1), q, w); }).find("smallest principal moment -1"), std::string::npos);
  EXPECT_NE(msg([&] { FreeRotation(diag(1, 1, 3), q, w); }).find("1, 1, 3 kg m^2 violate the triangle"),
            std::string::npos);
  EXPECT_NE(msg([&] { FreeRotation(Eigen::Matrix3d::Identity(), q, Vec3(0, INFINITY, 0)); })
                .find("omega0(1) must be finite, got inf"),
            std::string::npos);
  EXPECT_NE(msg([&] { FreeRotation(Eigen::Matrix3d::Identity(), Rotation(2, 0, 0, 0), w); }).find("|q0| = 2"),
            std::string::npos);
  EXPECT_NO_THROW(FreeRotation(diag(1, 1, 2), q, w));  // a flat plate: J1 + J2 = J3
}
