// SPDX-License-Identifier: GPL-3.0-or-later
// Throughput of the streaming explicit path (issue 14, item 3): explicit drops per second at
// N = 10^4 (sphere generation, index, queries, cross-check and streaming statistics all counted:
// the wall time of run_contact_stream), per backend, with the raw-sample path (grid) as a ratio in
// the same run. Median of --repeats runs; markdown on stdout (bench/RESULTS.md "Streaming").
//   bench_streaming [--asperities N] [--drops n] [--brute-drops n] [--repeats r] [--threads t] [--quick]
//                   [--grid-only | --raw-only]  (only the streaming grid / raw grid row: for profiling)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "asperity/config.hpp"
#include "asperity/experiments/streaming.hpp"
#include "timing.hpp"

using namespace asperity;

namespace {

using asperity::bench::median;

using asperity::bench::timed;

}  // namespace

int main(int argc, char** argv) {
  std::uint64_t n = 10000, drops = 4000000, brute_drops = 200000;
  int repeats = 3, threads = 2;
  bool grid_only = false, raw_only = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] { return i + 1 < argc ? std::strtoull(argv[++i], nullptr, 10) : 0ull; };
    if (a == "--asperities") n = next();
    else if (a == "--drops") drops = next();
    else if (a == "--brute-drops") brute_drops = next();
    else if (a == "--repeats") repeats = int(next());
    else if (a == "--threads") threads = int(next());
    else if (a == "--grid-only") grid_only = true;
    else if (a == "--raw-only") raw_only = true;
    else if (a == "--quick") n = 1000, drops = 100000, brute_drops = 20000, repeats = 1;
    else {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  EnsembleConfig c;
  c.sphere.asperities = n;
  c.drops = drops;
  c.spheres = auto_spheres(n, drops);
  c.threads = threads;
  c.statistics = Statistics::streaming;
  std::printf("## Streaming explicit path: N = %llu, K = %llu spheres x M = %llu rotations, %d threads, median of %d\n\n",
              (unsigned long long)n, (unsigned long long)c.spheres, (unsigned long long)(drops / c.spheres), threads,
              repeats);
  std::printf("| path | backend | drops | wall s | drops/s | ratio to streaming grid |\n|---|---|---|---|---|---|\n");
  struct Row {
    std::string path;
    Backend b;
    std::uint64_t drops;
  };
  std::vector<Row> rows{{"streaming", Backend::grid, drops}, {"raw samples", Backend::grid, drops},
                        {"streaming", Backend::kdtree, drops}, {"streaming", Backend::brute, brute_drops}};
  if (grid_only) rows.resize(1);
  if (raw_only) rows.erase(rows.begin()), rows.resize(1);
#if ASPERITY_WITH_FCL
  if (!grid_only && !raw_only) rows.push_back({"streaming", Backend::fcl, drops / 4});
#endif
  double ref = 0;
  for (const auto& r : rows) {
    EnsembleConfig x = c;
    x.backend = r.b;
    x.drops = r.drops;
    x.spheres = auto_spheres(n, r.drops);
    x.statistics = r.path == "raw samples" ? Statistics::raw : Statistics::streaming;
    std::vector<double> t;
    for (int k = 0; k < repeats; ++k)
      t.push_back(timed([&] {
        if (x.statistics == Statistics::raw) (void)run_contact_ensemble(x);
        else (void)run_contact_stream(x);
      }));
    const double rate = double(r.drops) / median(t);
    if (ref == 0) ref = rate;
    std::printf("| %s | %s | %llu | %.3f | %.3g | %.3f |\n", r.path.c_str(), std::string(to_string(r.b)).c_str(),
                (unsigned long long)r.drops, median(t), rate, rate / ref);
    std::fflush(stdout);
  }
  return 0;
}
