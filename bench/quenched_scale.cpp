// The KS-scale constant of the quenched deviation (kQuenchedKs, experiments/ensemble.hpp): for K
// explicit spheres of N asperities, M rotations each, D_k = sup |F_k - F_exact| of sphere k's r_xy
// sample against the exact finite-N law. With M large the statistical part (0.87/sqrt(M)) is small,
// and c = sqrt(<D_k^2> - 0.87^2/M) sqrt(N) estimates E sup |F_sphere - F| sqrt(N).
//   quenched_scale N M K [seed]      e.g. quenched_scale 1000 1000000 12
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "asperity/experiments/ensemble.hpp"
#include "asperity/laws/statistics.hpp"
#include "asperity/laws/theory.hpp"

using namespace asperity;

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: quenched_scale N M K [seed]\n");
    return 2;
  }
  const std::uint64_t N = std::strtoull(argv[1], nullptr, 10), M = std::strtoull(argv[2], nullptr, 10),
                      K = std::strtoull(argv[3], nullptr, 10), seed = argc > 4 ? std::strtoull(argv[4], nullptr, 10) : 100;
  const Law law = exact_sphere_rxy(N, 3e-3);
  double s2 = 0, s1 = 0;
  for (std::uint64_t k = 0; k < K; ++k) {
    EnsembleConfig c;
    c.sphere = {N, 3e-3, 6.5e-7};
    c.mode = Mode::explicit_spheres;
    c.spheres = 1;
    c.drops = M;
    c.seed = seed + k;
    c.backend = Backend::grid;
    auto x = run_contact_ensemble(c).r_xy;
    std::sort(x.begin(), x.end());
    const double D = ks_one_sample(x, law.cdf).D;
    s1 += D, s2 += D * D;
    std::printf("sphere %llu: D = %.5f, D sqrt(N) = %.3f\n", (unsigned long long)k, D, D * std::sqrt(double(N)));
  }
  const double stat = 0.8687 / std::sqrt(double(M));
  const double q = std::sqrt(std::max(0.0, s2 / double(K) - stat * stat));
  std::printf("N = %llu, M = %llu, K = %llu: mean D = %.5f, rms D = %.5f, statistical %.5f -> quenched rms %.5f, "
              "c = %.3f\n",
              (unsigned long long)N, (unsigned long long)M, (unsigned long long)K, s1 / double(K), std::sqrt(s2 / double(K)),
              stat, q, q * std::sqrt(double(N)));
  return 0;
}
