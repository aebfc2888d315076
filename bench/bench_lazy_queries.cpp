// SPDX-License-Identifier: GPL-3.0-or-later
// Lazy-sphere queries in random-orientation's pattern (bench/RESULTS.md "fig6, fourth pass"): per
// sequence a fresh sphere of N = 1e6 (reset), then 55 queries for Haar-random down directions,
// one thread. Prints the thread's CPU time and a checksum of the answers (equal across builds
// that generate the same spheres). Usage: bench_lazy_queries [sequences = 2000]
#include <cstdio>
#include <cstdlib>
#include <ctime>

#include "asperity/core/lazy_sphere.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/random.hpp"

int main(int argc, char** argv) {
  using namespace asperity;
  const long sequences = argc > 1 ? std::atol(argv[1]) : 2000;
  if (sequences < 1) {
    std::fprintf(stderr, "bench_lazy_queries: sequences must be >= 1, got '%s'\n", argv[1]);
    return 2;
  }
  BinomialModeCache modes(1000000);
  LazySphere sphere(1000000, 1, 0, 8, &modes);
  double check = 0;
  std::size_t cells = 0;
  timespec t0{}, t1{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
  for (long i = 0; i < sequences; ++i) {
    sphere.reset(1, static_cast<std::uint64_t>(i));
    Stream s(5, Purpose::test, static_cast<std::uint64_t>(i));
    for (int k = 0; k < 55; ++k) {
      const auto L = sphere.lowest(random_rotation(s) * Vec3(0, 0, -1));
      check += L.nearest.key + L.u.x();
    }
    cells += sphere.cells_generated();
  }
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
  const double cpu = static_cast<double>(t1.tv_sec - t0.tv_sec) + 1e-9 * static_cast<double>(t1.tv_nsec - t0.tv_nsec);
  std::printf("%ld sequences x 55 queries: %.3f s CPU, %.2f us per query, %.1f cells per sequence (check %.17g)\n",
              sequences, cpu, 1e6 * cpu / (55.0 * static_cast<double>(sequences)),
              static_cast<double>(cells) / static_cast<double>(sequences), check);
  return 0;
}
