// SPDX-License-Identifier: GPL-3.0-or-later
// Micro benchmarks of the grid contact backend against the nanoflann kd-tree: build time, single
// queries and batched queries on uniformly random directions. Run single-threaded for per-core
// numbers: OMP_NUM_THREADS=1 ./bench_grid
//
// Args: N (centres). The "side" sweep (BM_GridSide) takes cells per face edge as second arg.
// BM_BatchWinner (the winner-only path, lowest_winners, that streaming runs use) and
// BM_BatchChunked (the full path) take the batch size as second arg: the 2^16 queries are asked
// in batches of that many (256 = the drop loop's kQueryBatch). Each is registered twice around the
// other (full first, then winner first), so one run measures both orders; with
// --benchmark_repetitions=5 the medians compare. The winner benchmark checks its winners against
// the full path's before timing.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <vector>

#include "asperity/core/contact.hpp"
#include "asperity/core/geometry.hpp"
#include "asperity/core/random.hpp"
#include "core/contact/detail.hpp"

namespace {

using asperity::Backend;
using asperity::Nearest;
using asperity::Vec3;

const std::vector<Vec3>& centres(std::int64_t n) {
  static std::map<std::int64_t, std::vector<Vec3>> cache;
  auto& c = cache[n];
  if (c.empty())
    c = asperity::make_rough_sphere(asperity::SphereParams{static_cast<std::uint64_t>(n), 3e-3, 6.5e-7}, 2024, 0)
            .centres;
  return c;
}

const std::vector<Vec3>& queries() {
  static const std::vector<Vec3> d = [] {
    std::vector<Vec3> v(1 << 16);
    for (std::size_t i = 0; i < v.size(); ++i) {
      asperity::Stream s(7, asperity::Purpose::test, i);
      const double a = s.uniform0(), b = s.uniform0();
      v[i] = asperity::uniform_on_sphere(a, b);
    }
    return v;
  }();
  return d;
}

void BM_Build(benchmark::State& st, Backend b) {
  const auto& c = centres(st.range(0));
  std::size_t mem = 0;
  for (auto _ : st) {
    auto q = asperity::make_contact_query(b, c);
    mem = q->memory_bytes();
    benchmark::DoNotOptimize(q.get());
  }
  st.counters["MB"] = static_cast<double>(mem) / 1e6;
}

void run_single(benchmark::State& st, const asperity::ContactQuery& q) {
  const auto& d = queries();
  std::size_t k = 0;
  std::uint64_t sum = 0;
  for (auto _ : st) {
    const Nearest n = q.lowest(d[k]);
    sum += n.index;
    k = (k + 1) & (d.size() - 1);
  }
  benchmark::DoNotOptimize(sum);
  st.SetItemsProcessed(st.iterations());
}

void run_batch(benchmark::State& st, const asperity::ContactQuery& q) {
  const auto& d = queries();
  std::vector<Nearest> out(d.size());
  for (auto _ : st) {
    q.lowest(d, out);
    benchmark::DoNotOptimize(out.data());
  }
  st.SetItemsProcessed(st.iterations() * static_cast<std::int64_t>(d.size()));
}

void BM_Single(benchmark::State& st, Backend b) {
  const auto q = asperity::make_contact_query(b, centres(st.range(0)));
  run_single(st, *q);
}

void BM_Batch(benchmark::State& st, Backend b) {
  const auto q = asperity::make_contact_query(b, centres(st.range(0)));
  run_batch(st, *q);
}

void run_chunked(benchmark::State& st, const asperity::ContactQuery& q, bool winners) {
  const auto& d = queries();
  const auto chunk = static_cast<std::size_t>(st.range(1));
  std::vector<Nearest> out(d.size());
  auto ask = [&] {
    for (std::size_t b = 0; b < d.size(); b += chunk) {
      const std::size_t n = std::min(chunk, d.size() - b);
      const std::span<const Vec3> in(d.data() + b, n);
      const std::span<Nearest> o(out.data() + b, n);
      if (winners) q.lowest_winners(in, o);
      else q.lowest(in, o);
    }
  };
  if (winners) {  // the winners must be the full path's (exact: test_contact_grid checks it against brute force)
    std::vector<Nearest> full(d.size());
    q.lowest(d, full);
    ask();
    for (std::size_t i = 0; i < d.size(); ++i)
      if (out[i].index != full[i].index || out[i].key != full[i].key) {
        st.SkipWithError("lowest_winners differs from lowest");
        return;
      }
  }
  for (auto _ : st) {
    ask();
    benchmark::DoNotOptimize(out.data());
  }
  st.SetItemsProcessed(st.iterations() * static_cast<std::int64_t>(d.size()));
}

void BM_BatchChunked(benchmark::State& st, Backend b) {
  const auto q = asperity::make_contact_query(b, centres(st.range(0)));
  run_chunked(st, *q, false);
}

void BM_BatchWinner(benchmark::State& st, Backend b) {
  const auto q = asperity::make_contact_query(b, centres(st.range(0)));
  run_chunked(st, *q, true);
}

void BM_GridSide(benchmark::State& st) {
  const auto q = asperity::detail::make_grid_with(centres(st.range(0)), static_cast<int>(st.range(1)), 0);
  run_batch(st, *q);
}

BENCHMARK_CAPTURE(BM_Build, grid, Backend::grid)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Build, kdtree, Backend::kdtree)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Single, grid, Backend::grid)->Arg(100000)->Arg(1000000)->Arg(10000000);
BENCHMARK_CAPTURE(BM_Single, kdtree, Backend::kdtree)->Arg(100000)->Arg(1000000);
BENCHMARK_CAPTURE(BM_Batch, grid, Backend::grid)->Arg(100000)->Arg(1000000)->Arg(10000000);
BENCHMARK_CAPTURE(BM_Batch, kdtree, Backend::kdtree)->Arg(100000)->Arg(1000000);
// Winner against full path, in both orders (see the top of the file).
BENCHMARK_CAPTURE(BM_BatchChunked, grid_full_first, Backend::grid)->ArgsProduct({{100000, 1000000}, {256, 65536}});
BENCHMARK_CAPTURE(BM_BatchWinner, grid_after_full, Backend::grid)->ArgsProduct({{100000, 1000000}, {256, 65536}});
BENCHMARK_CAPTURE(BM_BatchWinner, grid_winner_first, Backend::grid)->ArgsProduct({{100000, 1000000}, {256, 65536}});
BENCHMARK_CAPTURE(BM_BatchChunked, grid_after_winner, Backend::grid)->ArgsProduct({{100000, 1000000}, {256, 65536}});
BENCHMARK(BM_GridSide)->ArgsProduct({{1000000}, {150, 200, 250, 300, 350, 400, 500}});

}  // namespace

BENCHMARK_MAIN();
