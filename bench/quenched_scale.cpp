// SPDX-License-Identifier: GPL-3.0-or-later
// The quenched deviation of one explicit sphere's law of r_xy from the ensemble law (kQuenchedKs,
// experiments/ensemble.hpp; docs/science-default-run.md "The explicit design"; bench/RESULTS.md). K explicit spheres of
// N asperities (grid query), M Haar-random rotations each, against the exact finite-N law F:
//  - KS: D_k = sup |F_k - F| of sphere k's sample. With M large the statistical part (0.87/sqrt(M))
//    is small, and c = sqrt(<D_k^2> - 0.87^2/M) sqrt(N) estimates E sup |F_sphere - F| sqrt(N)
//    (the library's kQuenchedKs); the spread of D_k sqrt(N) over spheres (mean, median, q10, q90).
//  - pointwise: the largest standard deviation over spheres of F_k(t) - F(t) on a grid of t,
//    rotation noise F(1 - F)/M removed (the Boolean-model quenched_deviation_scale predicts it).
// Sphere k uses seed + k, so the KS lines of a given (N, M, K, seed) are those of earlier versions.
//   quenched_scale N M K [seed]      e.g. quenched_scale 1000 1000000 12;  quenched_scale 1000 200000 100
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "asperity/experiments/ensemble.hpp"
#include "asperity/laws/statistics.hpp"
#include "asperity/laws/theory.hpp"

using namespace asperity;

namespace {

constexpr double kRadius = 3e-3;
constexpr int kGrid = 200;  // points of the pointwise deviation, on (0, 4 sigma sqrt(2)]

// A whole number >= lo, or exit 2 naming the argument.
std::uint64_t count_arg(const char* name, const char* text, std::uint64_t lo) {
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text, &end, 10);
  if (*text == '\0' || *end != '\0' || *text == '-' || v < lo) {
    std::fprintf(stderr, "quenched_scale: %s = '%s' must be a whole number >= %llu\n", name, text, (unsigned long long)lo);
    std::exit(2);
  }
  return v;
}

// Running sums over spheres of F_k(t_j) - F(t_j).
struct Pointwise {
  std::vector<double> t, sum, sum2;
};

Pointwise pointwise_grid(std::uint64_t N) {
  Pointwise p;
  const double tmax = 4.0 * kRadius * std::sqrt(2.0 / double(N));  // ~4 sigma sqrt(2)
  for (int j = 0; j < kGrid; ++j) p.t.push_back(tmax * (j + 0.5) / kGrid);
  p.sum.assign(kGrid, 0.0), p.sum2.assign(kGrid, 0.0);
  return p;
}

void add_sphere(Pointwise& p, const std::vector<double>& sorted, const Law& law) {
  const double M = double(sorted.size());
  for (int j = 0; j < kGrid; ++j) {
    const double d = double(std::upper_bound(sorted.begin(), sorted.end(), p.t[j]) - sorted.begin()) / M - law.cdf(p.t[j]);
    p.sum[j] += d, p.sum2[j] += d * d;
  }
}

// max_t sd over spheres of F_k(t) - F(t), the rotation noise F(1 - F)/M removed.
double largest_sd(const Pointwise& p, const Law& law, std::uint64_t K, std::uint64_t M) {
  double sd = 0;
  for (int j = 0; j < kGrid; ++j) {
    const double f = law.cdf(p.t[j]), mean = p.sum[j] / double(K);
    const double v = p.sum2[j] / double(K) - mean * mean - f * (1 - f) / double(M);
    sd = std::max(sd, std::sqrt(std::max(0.0, v)));
  }
  return sd;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4 || argc > 5) {
    std::fprintf(stderr, "usage: quenched_scale N M K [seed]\n");
    return 2;
  }
  const std::uint64_t N = count_arg("N", argv[1], 1), M = count_arg("M", argv[2], 2), K = count_arg("K", argv[3], 1),
                      seed = argc > 4 ? count_arg("seed", argv[4], 0) : 100;
  const Law law = exact_sphere_rxy(N, kRadius);
  const double rootN = std::sqrt(double(N));
  double s2 = 0, s1 = 0;
  std::vector<double> Ds;
  Pointwise pw = pointwise_grid(N);
  for (std::uint64_t k = 0; k < K; ++k) {
    EnsembleConfig c;
    c.sphere = {N, kRadius, 6.5e-7};
    c.mode = Mode::explicit_spheres;
    c.spheres = 1;
    c.drops = M;
    c.seed = seed + k;
    c.backend = Backend::grid;
    auto x = run_contact_ensemble(c).r_xy;
    std::sort(x.begin(), x.end());
    const double D = ks_one_sample(x, law.cdf).D;
    s1 += D, s2 += D * D;
    Ds.push_back(D * rootN);
    add_sphere(pw, x, law);
    std::printf("sphere %llu: D = %.5f, D sqrt(N) = %.3f\n", (unsigned long long)k, D, D * rootN);
  }
  const double stat = 0.8687 / std::sqrt(double(M));
  const double q = std::sqrt(std::max(0.0, s2 / double(K) - stat * stat));
  std::printf("N = %llu, M = %llu, K = %llu: mean D = %.5f, rms D = %.5f, statistical %.5f -> quenched rms %.5f, "
              "c = %.3f\n",
              (unsigned long long)N, (unsigned long long)M, (unsigned long long)K, s1 / double(K), std::sqrt(s2 / double(K)),
              stat, q, q * rootN);
  std::sort(Ds.begin(), Ds.end());
  std::printf("D sqrt(N) over spheres: mean %.4f, median %.4f, q10 %.4f, q90 %.4f (rotation noise ~%.4f); "
              "max_t sd(F_sphere - F) sqrt(N) = %.4f (quenched_deviation_scale sqrt(N) = %.4f)\n",
              s1 / double(K) * rootN, Ds[K / 2], Ds[K / 10], Ds[9 * K / 10], stat * rootN,
              largest_sd(pw, law, K, M) * rootN, quenched_deviation_scale(N) * rootN);
  return 0;
}
