// SPDX-License-Identifier: GPL-3.0-or-later
// ns per FreeRotation::at(t) (closed form) against the Odeint reference (integrating Euler's
// equations from 0 to t on every call, src/free_rotation_reference.hpp), for t spread over
// 0..10 periods; the counter max_err is each method's largest difference from the other over
// the same times (orientation distance or |dOmega| / |Omega0|), so "equal error" can be read off.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "asperity/core/free_rotation.hpp"
#include "core/free_rotation_reference.hpp"

using namespace asperity;

namespace {
struct Case {
  Eigen::Matrix3d J;
  Rotation q0;
  Vec3 w0;
};
// 0: a generic asymmetric top; 1: 1e-6 off the separatrix (k' ~ 1e-3: K(k) ~ 8, the slow end).
Case make_case(int which) {
  const Rotation frame(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  const Eigen::Matrix3d R = frame.toRotationMatrix();
  Case c;
  c.q0 = Rotation(0.2, 0.5, -0.4, 0.7).normalized();
  if (which == 0) {
    c.J = R * Eigen::Vector3d(1.0, 2.0, 2.5).asDiagonal() * R.transpose();
    c.w0 = Vec3(3.0, -1.2, 2.0);
  } else {
    c.J = R * Eigen::Vector3d(3.0, 4.0, 6.0).asDiagonal() * R.transpose();
    c.w0 = c.q0 * (frame * Vec3(2 * (1 + 1e-6), 0.7, 1));
  }
  return c;
}
std::vector<double> times_for(const FreeRotation& f) {
  std::vector<double> t;
  for (int i = 0; i < 64; ++i) t.push_back(10 * f.period() * (i + 0.5) / 64);
  return t;
}
double dist(const RotationState& a, const RotationState& b, double w) {
  const double dq = std::min((a.q.coeffs() - b.q.coeffs()).norm(), (a.q.coeffs() + b.q.coeffs()).norm());
  return std::max(dq, (a.omega - b.omega).norm() / w);
}

void BM_FreeRotation_construct(benchmark::State& st) {
  const Case c = make_case(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    FreeRotation f(c.J, c.q0, c.w0);
    benchmark::DoNotOptimize(f);
  }
}
BENCHMARK(BM_FreeRotation_construct)->Arg(0)->Arg(1);

void BM_FreeRotation_exact(benchmark::State& st) {
  const Case c = make_case(static_cast<int>(st.range(0)));
  const FreeRotation f(c.J, c.q0, c.w0);
  const auto t = times_for(f);
  std::size_t i = 0;
  for (auto _ : st) benchmark::DoNotOptimize(f.at(t[i++ % t.size()]));
  double e = 0;
  for (double x : t)
    e = std::max(e, dist(f.at(x), detail::reference_free_rotation(c.J, c.q0, c.w0, x, 1e-13), c.w0.norm()));
  st.counters["max_err"] = e;
}
BENCHMARK(BM_FreeRotation_exact)->Arg(0)->Arg(1);

// range(1) = -log10 of the integrator tolerance.
void BM_FreeRotation_odeint(benchmark::State& st) {
  const Case c = make_case(static_cast<int>(st.range(0)));
  const double tol = std::pow(10.0, -static_cast<double>(st.range(1)));
  const FreeRotation f(c.J, c.q0, c.w0);
  const auto t = times_for(f);
  std::size_t i = 0;
  for (auto _ : st) benchmark::DoNotOptimize(detail::reference_free_rotation(c.J, c.q0, c.w0, t[i++ % t.size()], tol));
  double e = 0;
  for (double x : t)
    e = std::max(e, dist(f.at(x), detail::reference_free_rotation(c.J, c.q0, c.w0, x, tol), c.w0.norm()));
  st.counters["max_err"] = e;
}
BENCHMARK(BM_FreeRotation_odeint)
    ->Args({0, 8})->Args({0, 10})->Args({0, 13})
    ->Args({1, 8})->Args({1, 10})->Args({1, 13});
}  // namespace

BENCHMARK_MAIN();
