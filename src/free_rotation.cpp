#include "asperity/free_rotation.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "format.hpp"
#include "free_rotation_reference.hpp"

namespace asperity {

using detail::num;

namespace {

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

struct FreeRotation::Impl {
  Eigen::Matrix3d J;
  Rotation q0;
  Vec3 omega0;
  Vec3 L;
  double T;
};

FreeRotation::FreeRotation(const Eigen::Matrix3d& inertia_body, const Rotation& q0, const Vec3& omega0) {
  validate(inertia_body, q0, omega0);
  auto p = std::make_shared<Impl>();
  p->J = 0.5 * (inertia_body + inertia_body.transpose());
  p->q0 = q0.normalized();
  p->omega0 = omega0;
  const Eigen::Matrix3d R = p->q0.toRotationMatrix();
  p->L = R * (p->J * (R.transpose() * omega0));
  p->T = 0.5 * omega0.dot(p->L);
  impl_ = std::move(p);
}

RotationState FreeRotation::at(double t) const {
  return detail::reference_free_rotation(impl_->J, impl_->q0, impl_->omega0, t);
}

Vec3 FreeRotation::angular_momentum() const { return impl_->L; }
double FreeRotation::kinetic_energy() const { return impl_->T; }

}  // namespace asperity
