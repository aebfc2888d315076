// Quenched deviation of one sphere's law of r_xy (many rotations) from the ensemble law (README
// "validate-geometry", fixed mode). Standalone (no asperity library): K spheres of N uniform centres,
// M uniform down directions each, brute-force lowest centre; prints the largest pointwise sd over
// spheres of F_sphere(t) - F(t) (rotation noise removed) and the KS distance sup|F_M - F| per sphere.
//   g++ -O2 -o quenched_ks scripts/quenched_ks.cpp && ./quenched_ks 1000 100 200000 && ./quenched_ks 4000 60 200000
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>
int main(int argc, char** argv) {
  const int N = std::atoi(argv[1]), K = std::atoi(argv[2]), M = std::atoi(argv[3]);
  const double R = 1.0;
  std::mt19937_64 g(12345 + N);
  std::uniform_real_distribution<double> U(0, 1);
  auto F = [&](double t) {  // exact finite-N law of r_xy
    const double c = std::sqrt(std::max(0.0, 1 - t * t / (R * R)));
    return 1 - std::pow((1 + c) / 2, N) + std::pow((1 - c) / 2, N);
  };
  const int G = 200;
  const double tmax = 4.0 * std::sqrt(2.0 / N);  // ~4 sigma / sqrt(2)
  std::vector<double> sum(G, 0), sum2(G, 0), Ds, Dp;
  for (int k = 0; k < K; ++k) {
    std::vector<double> x(N), y(N), z(N);
    for (int i = 0; i < N; ++i) {
      const double zz = 2 * U(g) - 1, ph = 2 * M_PI * U(g), s = std::sqrt(1 - zz * zz);
      x[i] = s * std::cos(ph), y[i] = s * std::sin(ph), z[i] = zz;
    }
    std::vector<double> r(M);
    for (int m = 0; m < M; ++m) {
      const double zz = 2 * U(g) - 1, ph = 2 * M_PI * U(g), s = std::sqrt(1 - zz * zz);
      const double dx = s * std::cos(ph), dy = s * std::sin(ph), dz = zz;
      double best = -2;
      for (int i = 0; i < N; ++i) best = std::max(best, x[i] * dx + y[i] * dy + z[i] * dz);
      r[m] = R * std::sqrt(std::max(0.0, 1 - best * best)) * (best < 0 ? -1 : 1);
    }
    std::sort(r.begin(), r.end());
    double D = 0;
    for (int m = 0; m < M; ++m) {
      const double f = F(r[m]);
      D = std::max({D, std::abs((m + 1.0) / M - f), std::abs(double(m) / M - f)});
    }
    Ds.push_back(D);
    for (int j = 0; j < G; ++j) {
      const double t = tmax * (j + 0.5) / G;
      const double Fm = double(std::upper_bound(r.begin(), r.end(), t) - r.begin()) / M - F(t);
      sum[j] += Fm, sum2[j] += Fm * Fm;
    }
  }
  double sdmax = 0;
  for (int j = 0; j < G; ++j) {
    const double t = tmax * (j + 0.5) / G, f = F(t);
    const double v = sum2[j] / K - (sum[j] / K) * (sum[j] / K) - f * (1 - f) / M;  // remove rotation noise
    sdmax = std::max(sdmax, std::sqrt(std::max(0.0, v)));
  }
  std::sort(Ds.begin(), Ds.end());
  double mean = 0;
  for (double d : Ds) mean += d;
  mean /= K;
  std::printf("N=%d K=%d M=%d: max_t sd(F_sphere - F) = %.4f/sqrt(N); KS sup: mean %.4f/sqrt(N), median %.4f/sqrt(N), q10 %.4f, q90 %.4f /sqrt(N); rotation noise ~%.4f/sqrt(N)\n",
              N, K, M, sdmax * std::sqrt(N), mean * std::sqrt(N), Ds[K / 2] * std::sqrt(N), Ds[K / 10] * std::sqrt(N),
              Ds[9 * K / 10] * std::sqrt(N), 0.87 / std::sqrt(M) * std::sqrt(N));
}
