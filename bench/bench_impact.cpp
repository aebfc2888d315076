// SPDX-License-Identifier: GPL-3.0-or-later
// Impulse solves per second: the general 3x3 LDLT solve against the closed form, on the contacts
// of Fig. 4 (random r from fresh caps, u = 1.3 m/s, Omega = (0.2, 0, 0) rad/s, Pade eps_n).
#include <benchmark/benchmark.h>

#include <vector>

#include "asperity/experiments/ensemble.hpp"
#include "asperity/core/impact.hpp"
#include "asperity/core/restitution.hpp"

using namespace asperity;

namespace {

constexpr double R = 3e-3, a = 6.5e-7, M = 8.878e-4;

std::vector<ImpactState> states(std::size_t n) {
  std::vector<ImpactState> s(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 u = fresh_cap(100000, i, 7, 1)[0];
    s[i].r = R * u + Vec3(0, 0, -a);
    s[i].V = Vec3(0, 0, -1.3);
    s[i].Omega = Vec3(0.2, 0, 0);
  }
  return s;
}

void BM_ImpactGeneral(benchmark::State& st) {
  const auto s = states(4096);
  const RigidBody body = RigidBody::sphere(M, R);
  const auto en = viscoelastic_pade14(0.0467);
  std::size_t i = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(solve_impact(body, s[i++ & 4095], *en, 1.0));
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_ImpactGeneral);

void BM_ImpactClosedForm(benchmark::State& st) {
  const auto s = states(4096);
  const auto en = viscoelastic_pade14(0.0467);
  const double J = 0.4 * M * R * R;
  std::size_t i = 0;
  for (auto _ : st) {
    const ImpactState& x = s[i++ & 4095];
    const double vn = (x.V + x.Omega.cross(x.r)).z();
    benchmark::DoNotOptimize(solve_impact_isotropic(M, J, x, (*en)(-vn), 1.0));
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_ImpactClosedForm);

void BM_PadeRestitution(benchmark::State& st) {
  const auto en = viscoelastic_pade14(0.0467);
  double v = 1.3;
  for (auto _ : st) {
    benchmark::DoNotOptimize((*en)(v));
    v += 1e-9;
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_PadeRestitution);

}  // namespace

BENCHMARK_MAIN();
