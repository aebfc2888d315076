// SPDX-License-Identifier: GPL-3.0-or-later
// Micro-benchmarks (Google Benchmark) of every stage of a drop, N = 10^3 ... 10^7:
//   - sphere generation (make_rough_sphere) with 1 and 2 OpenMP threads;
//   - each contact backend's build, with its index memory and the PEAK resident memory of the
//     build per asperity (VmHWM of the process, reset before the build: temporaries included);
//   - each backend's queries on uniformly random and on slowly rotating directions (a body turning
//     1e-3 rad per query), 1 and 2 benchmark threads sharing one index (aggregate throughput);
//   - fresh drops (exact cap of a fresh sphere + contact), whose cost must not depend on N;
//   - the analysis updates: histogram filling and a one-sample KS test against Eq. 14, per sample.
// Impulse solves are in bench_impact, the ratio tables against brute force, kd-tree and FCL in
// bench_contact (same machine, same run of scripts/bench).
//
// --quick: N = 10^3 only, minimal times; exits non-zero unless every benchmark ran and reported a
// finite positive time (the ctest smoke test: it checks the harness, never a timing).
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "asperity/core/contact.hpp"
#include "asperity/experiments/ensemble.hpp"
#include "asperity/core/geometry.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/laws/statistics.hpp"
#include "asperity/laws/theory.hpp"
#include "directions.hpp"

namespace {

using namespace asperity;

constexpr double kR = 3e-3, kA = 6.5e-7;
constexpr std::uint64_t kSeed = 2024;
constexpr std::size_t kQueries = 1 << 16;  // power of two: the query loop wraps with a mask

// ---- shared, read-only inputs ------------------------------------------------------------------
// One sphere and one index at a time: benchmarks run in registration order (backend-major, then N),
// so a single slot bounds the memory (FCL holds ~460 B per asperity) without rebuilding per
// benchmark. Guarded because benchmark threads enter the function concurrently.
std::mutex slot_mutex;
std::int64_t sphere_n = -1;
std::vector<Vec3> sphere;
std::pair<Backend, std::int64_t> index_key{Backend::brute, -1};
std::unique_ptr<ContactQuery> index_slot;

const std::vector<Vec3>& centres(std::int64_t n) {
  std::lock_guard lock(slot_mutex);
  if (sphere_n != n) {
    index_slot.reset(), index_key.second = -1;
    sphere = make_rough_sphere(SphereParams{static_cast<std::uint64_t>(n), kR, kA}, kSeed, 0).centres;
    sphere_n = n;
  }
  return sphere;
}

const ContactQuery& index_for(Backend b, std::int64_t n) {
  const auto& c = centres(n);
  std::lock_guard lock(slot_mutex);
  if (index_key != std::pair{b, n}) {
    index_slot.reset();
    index_slot = make_contact_query(b, c);
    index_key = {b, n};
  }
  return *index_slot;
}

const std::vector<Vec3>& random_queries() {
  static const std::vector<Vec3> d = bench::random_directions(kQueries, kSeed);
  return d;
}
const std::vector<Vec3>& rotating_queries() {
  static const std::vector<Vec3> d = bench::rotating_directions(kQueries, kSeed, 1e-3);
  return d;
}

// ---- peak memory -----------------------------------------------------------------------------------
// Linux: writing 5 to /proc/self/clear_refs resets the peak RSS (VmHWM) to the current RSS.
long status_kib(const char* field) {
  std::ifstream f("/proc/self/status");
  std::string line;
  const std::size_t len = std::strlen(field);
  while (std::getline(f, line))
    if (line.compare(0, len, field) == 0) return std::stol(line.substr(len + 1));
  return -1;
}
bool reset_peak() {
  malloc_trim(0);  // return freed heap to the system so that a new build's pages show up in RSS
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
  return static_cast<bool>(f);
}

// ---- benchmarks ---------------------------------------------------------------------------------

void BM_SphereGeneration(benchmark::State& st) {
  const SphereParams p{static_cast<std::uint64_t>(st.range(0)), kR, kA};
  omp_set_num_threads(static_cast<int>(st.range(1)));
  for (auto _ : st) benchmark::DoNotOptimize(make_rough_sphere(p, kSeed, 0).centres.data());
  omp_set_num_threads(omp_get_num_procs());
  st.SetItemsProcessed(st.iterations() * st.range(0));  // asperities per second
  st.counters["threads"] = static_cast<double>(st.range(1));
}

void BM_Build(benchmark::State& st, Backend b) {
  const std::int64_t n = st.range(0);
  const auto& c = centres(n);
  std::size_t bytes = 0;
  for (auto _ : st) {
    auto q = make_contact_query(b, c);
    bytes = q->memory_bytes();
    benchmark::DoNotOptimize(q.get());
  }
  // One more build, untimed, for the peak resident memory it needs (temporaries included).
  if (reset_peak()) {
    const long before = status_kib("VmRSS:");
    long peak = 0;
    {
      auto q = make_contact_query(b, c);
      peak = status_kib("VmHWM:");
      benchmark::DoNotOptimize(q.get());
    }
    if (before >= 0 && peak >= before)
      st.counters["peak_B_per_asperity"] = 1024.0 * static_cast<double>(peak - before) / static_cast<double>(n);
  }
  st.counters["index_B_per_asperity"] = static_cast<double>(bytes) / static_cast<double>(n);
  st.SetItemsProcessed(st.iterations() * n);
}

void run_queries(benchmark::State& st, Backend b, const std::vector<Vec3>& d) {
  const ContactQuery& q = index_for(b, st.range(0));
  // Threads start at different offsets so that two threads do not walk the same cache lines.
  std::size_t k = static_cast<std::size_t>(st.thread_index()) * (kQueries / 2);
  std::uint64_t sum = 0;
  for (auto _ : st) {
    sum += q.lowest(d[k]).index;
    k = (k + 1) & (kQueries - 1);
  }
  benchmark::DoNotOptimize(sum);
  st.SetItemsProcessed(st.iterations());
}
void BM_QueryRandom(benchmark::State& st, Backend b) { run_queries(st, b, random_queries()); }
void BM_QueryRotating(benchmark::State& st, Backend b) { run_queries(st, b, rotating_queries()); }

// A whole fresh drop: the exact lowest two asperities of a new random sphere, and its contact.
void BM_FreshDrop(benchmark::State& st) {
  const auto n = static_cast<std::uint64_t>(st.range(0));
  std::uint64_t drop = static_cast<std::uint64_t>(st.thread_index()) << 40;
  double sum = 0;
  const Rotation identity = Rotation::Identity();
  for (auto _ : st) {
    const auto cap = fresh_cap(n, drop++, kSeed);
    const Nearest nn = brute_lowest(cap, Vec3(0, 0, -1));
    sum += make_contact(nn, cap[nn.index], identity, kR, kA).r_xy;
  }
  benchmark::DoNotOptimize(sum);
  st.SetItemsProcessed(st.iterations());
}

std::vector<double> eq14_samples(std::size_t n) {
  std::vector<double> x(n);
  const double lam_pi = areal_density(100000, kR) * 3.141592653589793;
  for (std::size_t i = 0; i < n; ++i) {
    Stream s(kSeed, Purpose::test, i, 3);
    x[i] = std::sqrt(-std::log(s.uniform()) / lam_pi);
  }
  return x;
}

void BM_Histogram(benchmark::State& st) {
  const auto x = eq14_samples(static_cast<std::size_t>(st.range(0)));
  for (auto _ : st) benchmark::DoNotOptimize(make_histogram(x, 0.0, 6e-5, 100).counts.data());
  st.SetItemsProcessed(st.iterations() * st.range(0));
}

void BM_KsEq14(benchmark::State& st) {
  auto x = eq14_samples(static_cast<std::size_t>(st.range(0)));
  std::sort(x.begin(), x.end());
  const Law law = eq14_rxy(100000, kR);
  for (auto _ : st) benchmark::DoNotOptimize(ks_one_sample(x, law.cdf).D);
  st.SetItemsProcessed(st.iterations() * st.range(0));
}

// Copy + sort: what the analysis pays per quantity before its KS tests and quantiles.
void BM_CopySort(benchmark::State& st) {
  const auto x = eq14_samples(static_cast<std::size_t>(st.range(0)));
  for (auto _ : st) {
    auto y = x;
    std::sort(y.begin(), y.end());
    benchmark::DoNotOptimize(y.data());
  }
  st.SetItemsProcessed(st.iterations() * st.range(0));
}

// ---- registration ---------------------------------------------------------------------------------

std::vector<std::int64_t> sizes(bool quick) {
  if (quick) return {1000};
  return {1000, 10000, 100000, 1000000, 10000000};
}

void register_all(bool quick) {
  const auto ns = sizes(quick);
  for (const std::int64_t n : ns)
    for (const int t : {1, 2})
      benchmark::RegisterBenchmark("SphereGeneration", BM_SphereGeneration)
          ->Args({n, t})
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  for (const Backend b : all_backends()) {
    const std::string name(to_string(b));
    for (const std::int64_t n : ns) {
      // FCL's build at 10^7 takes ~35 s and 4.5 GB; bench_contact times it (once) instead.
      if (b == Backend::fcl && n > 1000000) continue;
      benchmark::RegisterBenchmark(("Build/" + name).c_str(), BM_Build, b)
          ->Arg(n)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
      benchmark::RegisterBenchmark(("QueryRandom/" + name).c_str(), BM_QueryRandom, b)
          ->Arg(n)
          ->Threads(1)
          ->Threads(2)
          ->UseRealTime();
      benchmark::RegisterBenchmark(("QueryRotating/" + name).c_str(), BM_QueryRotating, b)
          ->Arg(n)
          ->Threads(1)
          ->Threads(2)
          ->UseRealTime();
    }
  }
  for (const std::int64_t n : ns)
    benchmark::RegisterBenchmark("FreshDrop", BM_FreshDrop)->Arg(n)->Threads(1)->Threads(2)->UseRealTime();
  const std::int64_t samples = quick ? 10000 : 1000000;
  benchmark::RegisterBenchmark("Histogram", BM_Histogram)->Arg(samples)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("KsEq14", BM_KsEq14)->Arg(samples)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("CopySort", BM_CopySort)->Arg(samples)->Unit(benchmark::kMillisecond);
}

// Console output as usual, and a record of whether every run produced a finite positive time.
class CheckingReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      ++runs_;
      const double t = r.GetAdjustedRealTime();
      if (r.error_occurred || r.iterations < 1 || !std::isfinite(t) || !(t > 0)) {
        ++bad_;
        std::cerr << "bench_micro: malformed result for " << r.benchmark_name() << "\n";
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }
  int runs() const { return runs_; }
  int bad() const { return bad_; }

 private:
  int runs_ = 0, bad_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> args;
  bool quick = false;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0)
      quick = true;
    else
      args.push_back(argv[i]);
  }
  static char min_time[] = "--benchmark_min_time=0.001";
  if (quick) args.push_back(min_time);
  int n = static_cast<int>(args.size());
  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 2;
  register_all(quick);
  CheckingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  if (quick && (reporter.runs() == 0 || reporter.bad() > 0)) return 1;
  return reporter.bad() > 0 ? 1 : 0;
}
