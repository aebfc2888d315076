// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/core/restitution.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/format.hpp"

namespace asperity {

using detail::num;

namespace {

void check_speed(double v) {
  if (!(v >= 0) || !std::isfinite(v)) throw std::invalid_argument("restitution: contact speed must be finite and >= 0 m/s, got " + num(v));
}

class Constant final : public Restitution {
 public:
  explicit Constant(double e) : e_(e) {
    if (!(e >= 0 && e <= 1)) throw std::invalid_argument("constant restitution must be in [0, 1], got " + num(e));
  }
  double operator()(double v) const override {
    check_speed(v);
    return e_;
  }
  std::string name() const override { return "constant(" + num(e_) + ")"; }

 private:
  double e_;
};

class Pade14 final : public Restitution {
 public:
  explicit Pade14(double beta) : beta_(beta) {
    if (!(beta > 0) || !std::isfinite(beta))
      throw std::invalid_argument("viscoelastic beta must be finite and > 0, got " + num(beta));
  }
  double operator()(double v) const override {
    check_speed(v);
    const double x = pade_vstar(v, beta_);
    constexpr double c1 = 0.501086, b1 = 0.501086, b2 = 1.15345, b3 = 0.577977, b4 = 0.532178;
    // Horner form; for huge x divide through by x^4 so nothing overflows (x < 1e3 for v < 1e8
    // anyway, but the form keeps the limit exact).
    if (x > 1e60) return c1 / (b4 * x * x * x);
    return (1.0 + c1 * x) / (1.0 + x * (b1 + x * (b2 + x * (b3 + x * b4))));
  }
  std::string name() const override { return "viscoelastic-pade14(beta=" + num(beta_) + ")"; }

 private:
  double beta_;
};

class Function final : public Restitution {
 public:
  Function(std::function<double(double)> f, std::string n) : f_(std::move(f)), name_(std::move(n)) {
    if (!f_) throw std::invalid_argument("function restitution: empty function");
  }
  double operator()(double v) const override {
    check_speed(v);
    const double e = f_(v);
    if (!(e >= 0 && e <= 1)) throw std::domain_error(name_ + ": eps_n(" + num(v) + ") = " + num(e) + " is not in [0, 1]");
    return e;
  }
  std::string name() const override { return name_; }

 private:
  std::function<double(double)> f_;
  std::string name_;
};

}  // namespace

double pade_vstar(double v, double beta) { return std::sqrt(beta) * std::pow(v, 0.1); }

std::unique_ptr<Restitution> constant_restitution(double e) { return std::make_unique<Constant>(e); }
std::unique_ptr<Restitution> viscoelastic_pade14(double beta) { return std::make_unique<Pade14>(beta); }
std::unique_ptr<Restitution> function_restitution(std::function<double(double)> f, std::string name) {
  return std::make_unique<Function>(std::move(f), std::move(name));
}

}  // namespace asperity
