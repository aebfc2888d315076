// FreeRotation: torque-free motion of an asymmetric rigid body.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "asperity/bounce.hpp"
#include "asperity/free_rotation.hpp"
#include "asperity/orientation.hpp"
#include "asperity/random.hpp"
#include "free_rotation_reference.hpp"

using namespace asperity;

namespace {
double qdist(const Rotation& a, const Rotation& b) { return std::min((a.coeffs() - b.coeffs()).norm(), (a.coeffs() + b.coeffs()).norm()); }
Eigen::Matrix3d body_inertia(double J1, double J2, double J3, const Rotation& frame) {
  const Eigen::Matrix3d R = frame.toRotationMatrix();
  return R * Eigen::Vector3d(J1, J2, J3).asDiagonal() * R.transpose();
}
struct Body {
  Eigen::Matrix3d J;
  Rotation q0;
  Vec3 w0;
};
// Principal moments from random second moments x, y, z >= 0 of a mass distribution (J1 = y + z, ...),
// so the triangle inequality holds by construction; random principal frame, orientation and spin
// direction; |Omega| log-uniform in [1e-3, 1e3] rad/s.
Body random_body(std::uint64_t i) {
  Stream s(7, Purpose::test, i);
  const double x = s.uniform(), y = s.uniform(), z = s.uniform(), m = std::exp(std::log(10.0) * (4 * s.uniform() - 2));
  Body b;
  b.J = body_inertia(m * (y + z), m * (x + z), m * (x + y), random_rotation(s));
  b.q0 = random_rotation(s);
  b.w0 = std::exp(std::log(10.0) * (6 * s.uniform() - 3)) * uniform_on_sphere(s.uniform(), s.uniform());
  return b;
}
// Largest orientation distance and relative angular-velocity difference over the times.
template <class F>
double max_error(const Body& b, F&& state_at, const std::vector<double>& times) {
  double e = 0;
  for (double t : times) {
    const RotationState r = detail::reference_free_rotation(b.J, b.q0, b.w0, t);
    const RotationState s = state_at(t);
    e = std::max({e, qdist(r.q, s.q), (r.omega - s.omega).norm() / b.w0.norm()});
  }
  return e;
}
}  // namespace

TEST(FreeRotation, MatchesOdeintReference) {
  double worst = 0;
  for (std::uint64_t i = 0; i < 200; ++i) {
    const Body b = random_body(i);
    const FreeRotation f(b.J, b.q0, b.w0);
    const double P = std::isfinite(f.period()) ? f.period() : 1 / b.w0.norm();
    std::vector<double> times;
    for (double x : {0.0, 0.1, 0.37, 1.0, 2.5, -1.3, 7.9, 20.0}) times.push_back(x * P);
    const double e = max_error(b, [&](double t) { return f.at(t); }, times);
    worst = std::max(worst, e);
    EXPECT_LT(e, 1e-9) << i;
  }
  std::printf("worst %g\n", worst);
}

TEST(FreeRotation, ConservesMomentumAndEnergy) {
  const Eigen::Matrix3d J = body_inertia(1.0, 2.0, 2.7, Rotation(0.9, 0.1, -0.3, 0.2).normalized());
  const Rotation q0 = Rotation(0.2, 0.5, -0.4, 0.7).normalized();
  const FreeRotation f(J, q0, Vec3(1.3, -0.4, 2.2));
  for (double t : {0.0, 0.1, 1.0, -2.5, 10.0}) {
    const RotationState s = f.at(t);
    const Eigen::Matrix3d R = s.q.toRotationMatrix();
    const Vec3 L = R * J * R.transpose() * s.omega;
    EXPECT_LT((L - f.angular_momentum()).norm(), 1e-11 * f.angular_momentum().norm()) << t;
    EXPECT_NEAR(0.5 * s.omega.dot(L), f.kinetic_energy(), 1e-11 * f.kinetic_energy()) << t;
  }
}

TEST(FreeRotation, SphericalTopIsExpOmegaT) {
  const Eigen::Matrix3d J = 0.4 * Eigen::Matrix3d::Identity();
  const Rotation q0 = Rotation(0.3, -0.5, 0.2, 0.7).normalized();
  const Vec3 w(0.7, -1.3, 0.4);
  const FreeRotation f(J, q0, w);
  for (double t : {0.0, 0.37, -1.2, 5.0}) {
    const RotationState s = f.at(t);
    EXPECT_LT(qdist(s.q, advance_rotation(q0, w, t)), 1e-11) << t;
    EXPECT_LT((s.omega - w).norm(), 1e-12) << t;
  }
}

TEST(FreeRotation, CompositionOfFlights) {
  const Eigen::Matrix3d J = body_inertia(0.8, 1.1, 1.5, Rotation(0.1, 0.7, 0.3, -0.2).normalized());
  const FreeRotation f(J, Rotation(0.6, 0.1, 0.2, -0.3).normalized(), Vec3(-0.3, 2.0, 0.9));
  const double t1 = 1.7, t2 = 2.3;
  const RotationState s1 = f.at(t1);
  const FreeRotation g(J, s1.q, s1.omega);
  EXPECT_LT(qdist(g.at(t2).q, f.at(t1 + t2).q), 1e-10);
  EXPECT_LT((g.at(t2).omega - f.at(t1 + t2).omega).norm(), 1e-10);
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
  EXPECT_NE(msg([&] { FreeRotation(J, q, w); }).find("nan"), std::string::npos);
  J = Eigen::Matrix3d::Identity();
  J(0, 1) = 0.1;
  EXPECT_NE(msg([&] { FreeRotation(J, q, w); }).find("symmetric"), std::string::npos);
  EXPECT_NE(msg([&] { FreeRotation(Eigen::Vector3d(-1, 1, 1).asDiagonal().toDenseMatrix(), q, w); }).find("-1"),
            std::string::npos);
  EXPECT_NE(msg([&] { FreeRotation(Eigen::Vector3d(1, 1, 3).asDiagonal().toDenseMatrix(), q, w); }).find("triangle"),
            std::string::npos);
  EXPECT_NE(msg([&] { FreeRotation(Eigen::Matrix3d::Identity(), q, Vec3(INFINITY, 0, 0)); }).find("inf"),
            std::string::npos);
  EXPECT_NE(msg([&] { FreeRotation(Eigen::Matrix3d::Identity(), Rotation(2, 0, 0, 0), w); }).find("|q0| = 2"),
            std::string::npos);
  EXPECT_NO_THROW(FreeRotation(Eigen::Vector3d(1, 1, 2).asDiagonal().toDenseMatrix(), q, w));  // flat plate
}
