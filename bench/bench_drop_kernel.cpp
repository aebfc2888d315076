// SPDX-License-Identifier: GPL-3.0-or-later
// The batched drop kernel (issue 26): explicit drops per second of the streaming path with the
// scalar reference and the SIMD kernel (everything counted: sphere generation, index, queries,
// cross-check, statistics -- the wall time of run_contact_stream), at N = 10^4 and 10^5, runs of
// the two kernels alternated; the kernel's stages alone (one thread, ns per drop); and the grid's
// batched query at N = 10^6 (one thread, ns per query, directions from the kernel, build excluded).
// Medians of --repeats; markdown on stdout (bench/RESULTS.md "Drop kernel"). Every run checks that
// scalar and simd give the same statistics; a disagreement exits 1 (the smoke test's only check).
//   bench_drop_kernel [--drops n] [--repeats r] [--threads t] [--quick]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "asperity/core/drop_kernel.hpp"
#include "asperity/experiments/streaming.hpp"
#include "core/drop_kernel_detail.hpp"
#include "timing.hpp"

using namespace asperity;

namespace {

using asperity::bench::median;

using asperity::bench::timed;

struct Args {
  std::uint64_t drops = 8000000, queries = 2000000;
  int repeats = 3, threads = 2;
  std::vector<std::uint64_t> sizes{10000, 100000};
  std::uint64_t grid_n = 1000000;
};

// Streaming explicit drops/s, scalar and simd alternated; false when their statistics differ.
bool streaming_rows(const Args& a) {
  std::printf("## Streaming explicit drops/s, %d threads, median of %d (scalar and simd alternated)\n\n", a.threads,
              a.repeats);
  std::printf("| N | K x M | scalar drops/s | simd drops/s | simd / scalar |\n|---|---|---|---|---|\n");
  bool same = true;
  for (std::uint64_t n : a.sizes) {
    EnsembleConfig c;
    c.sphere.asperities = n;
    c.drops = a.drops;
    c.spheres = auto_spheres(n, a.drops);
    c.threads = a.threads;
    c.statistics = Statistics::streaming;
    std::vector<double> t[2];
    StreamState st[2];
    for (int r = 0; r < a.repeats; ++r)
      for (int k = 0; k < 2; ++k) {
        c.kernel = k == 0 ? Kernel::scalar : Kernel::simd;
        t[k].push_back(timed([&] { st[k] = run_contact_stream(c).state; }));
      }
    same = same && st[0] == st[1];
    const double r0 = double(c.drops) / median(t[0]), r1 = double(c.drops) / median(t[1]);
    std::printf("| %llu | %llu x %llu | %.3g | %.3g | %.2f |\n", (unsigned long long)n, (unsigned long long)c.spheres,
                (unsigned long long)(c.drops / c.spheres), r0, r1, r1 / r0);
    std::fflush(stdout);
  }
  return same;
}

// The kernel's two stages alone, one thread: ns per drop of draw_drops and drop_contacts by variant.
void stage_rows(const Args& a) {
  constexpr std::size_t B = 256;
  const std::uint64_t batches = std::max<std::uint64_t>(1, a.queries / B);
  const auto centres = make_rough_sphere(SphereParams{10000, 3e-3, 6.5e-7}, 1, 0).centres;
  std::vector<Vec3> d(B);
  std::vector<double> c(B), s(B);
  std::vector<Nearest> nn(B);
  std::vector<Contact> out(B);
  for (std::size_t i = 0; i < B; ++i) nn[i] = Nearest{std::uint32_t(i * 37 % centres.size()), 1e-4, 0, 2e-4};
  std::printf("\n## Kernel stages alone, 1 thread, batches of %zu, %llu drops, median of %d\n\n", B,
              (unsigned long long)(batches * B), a.repeats);
  std::printf("| variant | draw ns/drop | contacts ns/drop | draw ratio to scalar |\n|---|---|---|---|\n");
  double ref = 0;
  for (auto isa : {detail::SimdIsa::none, detail::SimdIsa::sse2, detail::SimdIsa::avx2, detail::SimdIsa::avx512f}) {
    if (!detail::isa_available(isa)) continue;
    std::vector<double> td, tc;
    for (int r = 0; r < a.repeats; ++r) {
      td.push_back(timed([&] {
        for (std::uint64_t b = 0; b < batches; ++b) detail::draw_drops_isa(isa, 7, b * B, d, c, s);
      }));
      tc.push_back(timed([&] {
        for (std::uint64_t b = 0; b < batches; ++b) detail::drop_contacts_isa(isa, d, c, s, nn, centres, 3e-3, 6.5e-7, out);
      }));
    }
    const double nd = 1e9 * median(td) / double(batches * B), nc = 1e9 * median(tc) / double(batches * B);
    if (ref == 0) ref = nd;
    const char* name[] = {"scalar", "sse2", "avx2", "avx512f"};
    std::printf("| %s | %.1f | %.1f | %.2f |\n", name[int(isa)], nd, nc, ref / nd);
  }
}

// The grid's batched query at N = grid_n, one thread, kernel directions (build excluded).
void grid_row(const Args& a) {
  const auto centres = make_rough_sphere(SphereParams{a.grid_n, 3e-3, 6.5e-7}, 2, 0).centres;
  const auto grid = make_contact_query(Backend::grid, centres);
  constexpr std::size_t B = 256;
  const std::uint64_t batches = std::max<std::uint64_t>(1, a.queries / B);
  std::vector<Vec3> d(batches * B);
  std::vector<double> c(d.size()), s(d.size());
  draw_drops(Kernel::simd, 3, 0, d, c, s);
  std::vector<Nearest> nn(B);
  std::vector<double> t;
  for (int r = 0; r < a.repeats; ++r)
    t.push_back(timed([&] {
      for (std::uint64_t b = 0; b < batches; ++b)
        grid->lowest(std::span<const Vec3>(d.data() + b * B, B), std::span<Nearest>(nn));
    }));
  std::printf("\n## Grid query, N = %llu, 1 thread, batches of %zu, %llu queries, median of %d: %.1f ns/query\n",
              (unsigned long long)a.grid_n, B, (unsigned long long)d.size(), a.repeats, 1e9 * median(t) / double(d.size()));
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    auto next = [&] { return i + 1 < argc ? std::strtoull(argv[++i], nullptr, 10) : 0ull; };
    if (s == "--drops") a.drops = next();
    else if (s == "--repeats") a.repeats = int(next());
    else if (s == "--threads") a.threads = int(next());
    else if (s == "--quick") a.drops = 200000, a.queries = 20000, a.repeats = 1, a.sizes = {2000}, a.grid_n = 20000;
    else {
      std::fprintf(stderr, "unknown argument %s\n", s.c_str());
      return 2;
    }
  }
  const bool same = streaming_rows(a);
  stage_rows(a);
  grid_row(a);
  if (!same) std::fprintf(stderr, "scalar and simd kernels gave different statistics\n");
  return same ? 0 : 1;
}
