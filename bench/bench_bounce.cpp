// SPDX-License-Identifier: GPL-3.0-or-later
// Bounce sequences per second for each variant of Sec. V (bounce.hpp), and what one explicit
// sphere would cost instead of the lazy one. Prints markdown for bench/RESULTS.md.
//   bench_bounce [--sequences S] [--repeats R] [--threads T] [--quick]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "asperity/experiments/bounce.hpp"
#include "asperity/core/contact.hpp"
#include "asperity/core/geometry.hpp"

using namespace asperity;
using Clock = std::chrono::steady_clock;

int main(int argc, char** argv) {
  std::uint64_t sequences = 2000;
  int repeats = 5, threads = 0;
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--sequences") && i + 1 < argc) sequences = std::stoull(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = std::stoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) threads = std::stoi(argv[++i]);
    else {
      std::fprintf(stderr, "bench_bounce: unknown argument '%s'\n", argv[i]);
      return 2;
    }
  }
  if (quick) sequences = 20, repeats = 1;
  const SphereParams sphere{1000000, 3e-3, 5e-7};  // Fig. 6
  BounceExperiment b;
  b.sequences = sequences;
  std::printf("| variant | sequences | threads | median s | sequences/s | impacts/sequence | lazy cells/sequence | lazy centres/sequence |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (auto v : {BounceVariant::paper, BounceVariant::random_orientation, BounceVariant::dynamic}) {
    std::vector<double> t;
    BounceSamples s;
    for (int r = 0; r < repeats; ++r) {
      s = run_bounces(sphere, b, v, 1 + static_cast<std::uint64_t>(r), threads);
      t.push_back(s.seconds);
    }
    std::sort(t.begin(), t.end());
    const double med = t[t.size() / 2];
    const double ns = static_cast<double>(s.sequences);
    std::printf("| %s | %llu | %d | %.3f | %.0f | %.1f | %.0f | %.0f |\n", std::string(to_string(v)).c_str(),
                static_cast<unsigned long long>(sequences), threads, med, ns / med, static_cast<double>(s.eps.size()) / ns,
                static_cast<double>(s.cells) / ns, static_cast<double>(s.centres) / ns);
  }
  if (!quick) {
    // The alternative: one explicit sphere of N = 1e6 and its grid index per sequence.
    std::vector<double> t;
    for (int r = 0; r < 3; ++r) {
      const auto t0 = Clock::now();
      const auto body = make_rough_sphere(sphere, 1, static_cast<std::uint64_t>(r));
      const auto index = make_contact_query(Backend::grid, body.centres);
      t.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    }
    std::sort(t.begin(), t.end());
    std::printf("\nExplicit sphere of N = 1e6 + grid index (what the lazy sphere avoids per sequence): median %.3f s\n", t[1]);
  }
  return 0;
}
