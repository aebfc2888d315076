// SPDX-License-Identifier: GPL-3.0-or-later
// bench_contact: the contact-backend benchmark of the issue "per backend and N: build time,
// queries/s with 1 and 2 threads, bytes per asperity, fresh drops/s; brute force, kd-tree and FCL as
// baselines in the same run, as ratios". A plain std::chrono driver that prints markdown tables of
// medians over --repeats runs (the text of bench/RESULTS.md).
//
// For each N (--sizes) and backend (--backends):
//  - gen s:     make_rough_sphere(N), all cores (per N, not per backend)
//  - build s:   make_contact_query, with --build-threads threads (default: all) and with 1 thread
//  - bytes/asperity: memory_bytes() / N (index only, the caller's centres are not counted)
//  - ns/query:  wall time / Q on Q uniformly random directions generated beforehand
//               (asperity::Stream + uniform_on_sphere): single-query lowest(d) in a loop and the
//               batch API lowest(span, span), each with 1 and 2 OpenMP threads (chunks of queries),
//               plus a "rotating" stream (consecutive directions 1e-3 rad apart along a slowly
//               turning great-circle path) through the 1-thread batch API. With 2 threads the figure
//               is wall time / Q, i.e. the inverse of the aggregate throughput.
//  - ratios:    of the 1-thread batch time, baseline / this (> 1: this backend is faster).
// Q is min(--queries, what fits --target-seconds per timed pass), at least 16: brute force at
// large N therefore runs on a few hundred queries instead of being skipped.
// Validation (always on, aborts with exit code 2): on a subsample (--validate, default 200) of the
// timed random and rotating queries every backend must equal brute_lowest exactly; single, batch,
// 1- and 2-thread answers must all be identical on every timed query.
// Fresh mode: asperity::run_contact_ensemble(Mode::sampled) for --fresh-drops drops with 1 and 2
// threads per N (wall time of the whole call).
//
// --quick: seconds-long smoke run (N = 1e3, 1e4; 1 repeat; few queries). It checks the harness,
// never a timing.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "asperity/core/contact.hpp"
#include "asperity/experiments/ensemble.hpp"
#include "asperity/core/geometry.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/random.hpp"
#include "directions.hpp"
#include "timing.hpp"

namespace {

using asperity::Backend;
using asperity::ContactQuery;
using asperity::Nearest;
using asperity::Vec3;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

using asperity::bench::median;

// ---- options ------------------------------------------------------------------------------------

struct Options {
  std::vector<std::uint64_t> sizes{1000, 10000, 100000, 1000000, 10000000};
  std::vector<Backend> backends;  // empty: all
  int repeats = 5;
  std::size_t queries = std::size_t{1} << 20;  // max random queries per timed pass
  double target_seconds = 0.25;                 // per timed pass; lowers Q for slow backends
  double build_budget = 12.0;                   // seconds of builds per (N, backend) before stopping repeats
  std::size_t validate = 200;
  std::uint64_t fresh_drops = 1000000;
  int build_threads = 0;  // 0: all
  double rotation_step = 1e-3;
  std::uint64_t seed = 2024;
  bool quick = false;
  bool fresh = true;
};

[[noreturn]] void usage(int code) {
  std::cout <<
      R"(usage: bench_contact [options]
  --sizes LIST          N values, e.g. 1e3,1e4,1e5,1e6,1e7 (default)
  --backends LIST       brute,kdtree,cgal,fcl,grid (default: all)
  --repeats R           repetitions, medians reported (default 5)
  --queries Q           random directions per timed pass, at most (default 1048576)
  --target-seconds S    per timed pass; slower backends get fewer queries (default 0.25, min 16 queries)
  --build-budget S      stop repeating a build once this many seconds were spent on it (default 12)
  --validate K          queries checked against brute_lowest per stream (default 200)
  --fresh-drops D       drops of the fresh-mode run per N and thread count (default 1e6; 0: skip)
  --build-threads T     threads for generation and the main build column (default 0: all)
  --rotation-step RAD   angle between consecutive rotating-stream directions (default 1e-3)
  --seed S              (default 2024)
  --quick               smoke run: N = 1e3,1e4, 1 repeat, 4096 queries, 1e4 fresh drops
)";
  std::exit(code);
}

std::vector<std::string> split(std::string_view s) {
  std::vector<std::string> out;
  std::size_t b = 0;
  while (b <= s.size()) {
    const std::size_t e = std::min(s.find(',', b), s.size());
    if (e > b) out.emplace_back(s.substr(b, e - b));
    b = e + 1;
  }
  return out;
}

double parse_double(const std::string& s, const char* what) {
  std::size_t pos = 0;
  double v = 0;
  try {
    v = std::stod(s, &pos);
  } catch (const std::exception&) {
    pos = 0;
  }
  if (pos != s.size() || !std::isfinite(v)) throw std::invalid_argument(std::string(what) + ": not a number: '" + s + "'");
  return v;
}

std::uint64_t parse_count(const std::string& s, const char* what) {
  const double v = parse_double(s, what);
  if (!(v >= 0) || v > 1e12 || v != std::floor(v))
    throw std::invalid_argument(std::string(what) + ": not a count: '" + s + "'");
  return static_cast<std::uint64_t>(v);
}

Options parse(int argc, char** argv) {
  Options o;
  bool sizes_set = false, repeats_set = false, queries_set = false, fresh_set = false, validate_set = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    if (a == "-h" || a == "--help") usage(0);
    else if (a == "--quick") o.quick = true;
    else if (a == "--sizes") {
      o.sizes.clear();
      for (const auto& s : split(value())) {
        const auto n = parse_count(s, "--sizes");
        if (n == 0) throw std::invalid_argument("--sizes: N must be >= 1");
        o.sizes.push_back(n);
      }
      if (o.sizes.empty()) throw std::invalid_argument("--sizes: empty list");
      sizes_set = true;
    } else if (a == "--backends") {
      for (const auto& s : split(value())) o.backends.push_back(asperity::parse_backend(s));
      if (o.backends.empty()) throw std::invalid_argument("--backends: empty list");
    } else if (a == "--repeats") {
      o.repeats = static_cast<int>(parse_count(value(), "--repeats"));
      if (o.repeats < 1) throw std::invalid_argument("--repeats must be >= 1");
      repeats_set = true;
    } else if (a == "--queries") {
      o.queries = parse_count(value(), "--queries");
      if (o.queries < 64) throw std::invalid_argument("--queries must be >= 64");
      queries_set = true;
    } else if (a == "--target-seconds") {
      o.target_seconds = parse_double(value(), "--target-seconds");
      if (!(o.target_seconds > 0)) throw std::invalid_argument("--target-seconds must be > 0");
    } else if (a == "--build-budget") {
      o.build_budget = parse_double(value(), "--build-budget");
    } else if (a == "--validate") {
      o.validate = parse_count(value(), "--validate");
      if (o.validate < 1) throw std::invalid_argument("--validate must be >= 1");
      validate_set = true;
    } else if (a == "--fresh-drops") {
      o.fresh_drops = parse_count(value(), "--fresh-drops");
      fresh_set = true;
    } else if (a == "--build-threads") {
      o.build_threads = static_cast<int>(parse_count(value(), "--build-threads"));
    } else if (a == "--rotation-step") {
      o.rotation_step = parse_double(value(), "--rotation-step");
      if (!(o.rotation_step > 0 && o.rotation_step < 1)) throw std::invalid_argument("--rotation-step must be in (0, 1)");
    } else if (a == "--seed") {
      o.seed = parse_count(value(), "--seed");
    } else {
      throw std::invalid_argument("unknown option '" + a + "' (try --help)");
    }
  }
  if (o.quick) {
    if (!sizes_set) o.sizes = {1000, 10000};
    if (!repeats_set) o.repeats = 1;
    if (!queries_set) o.queries = 4096;
    if (!fresh_set) o.fresh_drops = 10000;
    if (!validate_set) o.validate = 50;
    o.target_seconds = std::min(o.target_seconds, 0.05);
  }
  if (o.backends.empty()) {
    const auto all = asperity::all_backends();
    o.backends.assign(all.begin(), all.end());
  }
  o.fresh = o.fresh_drops > 0;
  return o;
}

// ---- environment --------------------------------------------------------------------------------

std::string trim(std::string s) {
  const auto b = s.find_first_not_of(" \t\n");
  const auto e = s.find_last_not_of(" \t\n");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::string cpu_model() {
  if (FILE* p = popen("lscpu 2>/dev/null", "r")) {
    char line[512];
    std::string model;
    while (std::fgets(line, sizeof line, p)) {
      const std::string l = line;
      if (l.rfind("Model name:", 0) == 0) model = trim(l.substr(11));
    }
    pclose(p);
    if (!model.empty()) return model;
  }
  std::ifstream f("/proc/cpuinfo");
  for (std::string l; std::getline(f, l);)
    if (l.rfind("model name", 0) == 0) return trim(l.substr(l.find(':') + 1));
  return "unknown";
}

std::string loadavg() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

std::string now_utc() {
  const std::time_t t = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&t));
  return buf;
}

// ---- query streams ------------------------------------------------------------------------------

using asperity::bench::random_directions;
using asperity::bench::rotating_directions;

// ---- timed passes -------------------------------------------------------------------------------

enum class Api { single, batch };

// Wall time of answering d[0..q) into out, with `threads` threads.
double timed_pass(const ContactQuery& idx, std::span<const Vec3> d, std::span<Nearest> out, Api api, int threads) {
  const std::size_t q = d.size();
  const auto t0 = Clock::now();
  if (threads <= 1) {
    if (api == Api::single)
      for (std::size_t i = 0; i < q; ++i) out[i] = idx.lowest(d[i]);
    else
      idx.lowest(d, out);
  } else {
    // Chunks of queries, handed out dynamically; each thread runs the API on its chunk.
    const std::size_t chunk = std::clamp<std::size_t>(q / (8 * static_cast<std::size_t>(threads)), 8, 4096);
    const auto chunks = static_cast<std::int64_t>((q + chunk - 1) / chunk);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (std::int64_t c = 0; c < chunks; ++c) {
      const std::size_t b = static_cast<std::size_t>(c) * chunk, e = std::min(q, b + chunk);
      if (api == Api::single)
        for (std::size_t i = b; i < e; ++i) out[i] = idx.lowest(d[i]);
      else
        idx.lowest(d.subspan(b, e - b), out.subspan(b, e - b));
    }
  }
  return since(t0);
}

[[noreturn]] void fail(const std::string& what) {
  std::cout.flush();
  std::cerr << "\n*** VALIDATION FAILED: " << what << "\n" << std::flush;
  std::exit(2);
}

std::string show(const Nearest& n) {
  std::ostringstream s;
  s << std::setprecision(17) << "{index " << n.index << ", key " << n.key << ", runner_up " << n.runner_up
    << ", runner_up_key " << n.runner_up_key << "}";
  return s.str();
}

void check_equal(std::span<const Nearest> got, std::span<const Nearest> ref, const std::string& what) {
  for (std::size_t i = 0; i < got.size(); ++i)
    if (!(got[i] == ref[i])) fail(what + ": query " + std::to_string(i) + " gave " + show(got[i]) + ", expected " + show(ref[i]));
}

// Validation positions among q queries: k in all, a third evenly spaced over the first 512, a third
// over the first 16384 and the rest over all q, so that a slow backend timed on only a few hundred
// queries is still checked at many positions and a fast one over its whole range. Sorted, unique.
std::vector<std::size_t> subsample(std::size_t q, std::size_t k) {
  std::vector<std::size_t> s;
  const std::size_t k1 = k / 3, k2 = k / 3, k3 = k - k1 - k2;
  for (const auto& [range, m] : {std::pair{std::min<std::size_t>(q, 512), k1}, std::pair{std::min<std::size_t>(q, 16384), k2},
                                 std::pair{q, k3}})
    for (std::size_t j = 0; j < m; ++j) s.push_back(j * range / m);
  std::sort(s.begin(), s.end());
  s.erase(std::unique(s.begin(), s.end()), s.end());
  return s;
}

// brute_lowest on d[idx[j]] for every j (both threads: this is the slow part at N = 1e7).
std::vector<Nearest> reference(std::span<const Vec3> centres, std::span<const Vec3> d, const std::vector<std::size_t>& idx) {
  std::vector<Nearest> r(idx.size());
  const auto k = static_cast<std::int64_t>(idx.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t j = 0; j < k; ++j)
    r[static_cast<std::size_t>(j)] = asperity::brute_lowest(centres, d[idx[static_cast<std::size_t>(j)]]);
  return r;
}

// ---- results ------------------------------------------------------------------------------------

struct Row {
  std::uint64_t n = 0;
  Backend backend{};
  std::string skipped;  // non-empty: not measured, why
  double gen = 0;       // median generation time of this N (same for all backends)
  double build = 0, build1 = std::nan("");
  int build_reps = 0, build1_reps = 0;
  double bytes_per = 0;
  std::size_t q = 0;
  double single1 = 0, single2 = 0, batch1 = 0, batch2 = 0, rotating = 0;  // ns per query
};

struct FreshRow {
  std::uint64_t n = 0;
  double rate1 = 0, rate2 = 0;  // drops/s
};

std::string fmt(double v, int prec) {
  if (!std::isfinite(v)) return "—";
  std::ostringstream s;
  s << std::fixed << std::setprecision(prec) << v;
  return s.str();
}

// 3 significant digits: fixed notation in [1e-3, 1e5), scientific (2.10e-6) outside.
std::string sig3(double v) {
  if (!std::isfinite(v)) return "—";
  if (v == 0) return "0";
  const int mag = static_cast<int>(std::floor(std::log10(std::fabs(v))));
  if (mag < -3 || mag >= 5) {
    std::ostringstream s;
    s << std::setprecision(2) << std::scientific << v;
    std::string t = s.str();  // 2.10e-06 -> 2.10e-6
    const auto e = t.find('e');
    std::string exp = t.substr(e + 1);
    const bool neg = exp[0] == '-';
    exp = exp.substr(1);
    while (exp.size() > 1 && exp[0] == '0') exp.erase(0, 1);
    return t.substr(0, e) + "e" + (neg ? "-" : "") + exp;
  }
  return fmt(v, std::max(0, 2 - mag));
}

std::string size_name(std::uint64_t n) {
  int e = 0;
  std::uint64_t m = n;
  while (m >= 10 && m % 10 == 0) m /= 10, ++e;
  if (e >= 3) return (m == 1 ? "" : std::to_string(m) + "·") + "10^" + std::to_string(e);
  return std::to_string(n);
}

// ---- one (N, backend) ----------------------------------------------------------------------------

Row measure(const Options& o, Backend b, std::span<const Vec3> centres, std::span<const Vec3> rnd,
            std::span<const Vec3> rot, const std::vector<Nearest>& ref_rnd, const std::vector<std::size_t>& sub_rnd,
            const std::vector<Nearest>& ref_rot, const std::vector<std::size_t>& sub_rot, int all_threads) {
  Row r;
  r.n = centres.size();
  r.backend = b;
  const std::string name(asperity::to_string(b));
  const std::string tag = name + " N=" + std::to_string(r.n);

  // Builds: with the build thread count, then with 1 thread, repeated while within the budget.
  std::unique_ptr<ContactQuery> idx;
  std::vector<double> tb, tb1;
  double spent = 0;
  const int build_threads = o.build_threads > 0 ? o.build_threads : all_threads;
  omp_set_num_threads(build_threads);
  for (int k = 0; k < o.repeats && (k == 0 || spent < o.build_budget); ++k) {
    idx.reset();
    const auto t0 = Clock::now();
    try {
      idx = asperity::make_contact_query(b, centres);
    } catch (const std::exception& e) {
      r.skipped = std::string("build threw: ") + e.what();
      std::cerr << "  " << tag << ": SKIPPED (" << r.skipped << ")\n";
      return r;
    }
    tb.push_back(since(t0));
    spent += tb.back();
  }
  r.build = median(tb);
  r.build_reps = static_cast<int>(tb.size());
  if (build_threads != 1 && spent < o.build_budget) {
    omp_set_num_threads(1);
    for (int k = 0; k < o.repeats && spent < o.build_budget; ++k) {
      const auto t0 = Clock::now();
      auto tmp = asperity::make_contact_query(b, centres);
      tb1.push_back(since(t0));
      spent += tb1.back();
    }
    r.build1 = median(tb1);
    r.build1_reps = static_cast<int>(tb1.size());
  } else if (build_threads == 1) {
    r.build1 = r.build;
    r.build1_reps = r.build_reps;
  }
  omp_set_num_threads(all_threads);
  r.bytes_per = static_cast<double>(idx->memory_bytes()) / static_cast<double>(r.n);

  // Query count: what fits the target time per pass, from a probe on the batch API that grows
  // until it takes 20 ms (brute force at N = 1e7 costs ~10 ms a query); at least 16.
  {
    std::size_t pq = std::min<std::size_t>(rnd.size(), 8);
    std::vector<Nearest> tmp(rnd.size() < 65536 ? rnd.size() : 65536);
    double tp = 0;
    for (;;) {
      tp = timed_pass(*idx, rnd.first(pq), std::span(tmp).first(pq), Api::batch, 1);
      if (tp >= 0.02 || pq >= tmp.size()) break;
      pq = std::min(tmp.size(), pq * 8);
    }
    const double per = std::max(tp / static_cast<double>(pq), 1e-10);
    r.q = std::clamp<std::size_t>(static_cast<std::size_t>(o.target_seconds / per), 16, rnd.size());
  }
  const std::size_t q = r.q;
  std::cerr << "  " << tag << ": build " << sig3(r.build) << " s (" << r.build_reps << "x), " << sig3(r.bytes_per)
            << " B/asperity, Q = " << q << "\n";

  const auto d = rnd.first(q);
  const auto dr = rot.first(std::min(q, rot.size()));
  std::vector<Nearest> out_s1(q), out_s2(q), out_b1(q), out_b2(q), out_rot(dr.size());
  std::vector<double> ts1, ts2, tb1q, tb2q, trot;
  for (int k = 0; k < o.repeats; ++k) {
    ts1.push_back(timed_pass(*idx, d, out_s1, Api::single, 1));
    ts2.push_back(timed_pass(*idx, d, out_s2, Api::single, 2));
    tb1q.push_back(timed_pass(*idx, d, out_b1, Api::batch, 1));
    tb2q.push_back(timed_pass(*idx, d, out_b2, Api::batch, 2));
    trot.push_back(timed_pass(*idx, dr, out_rot, Api::batch, 1));
  }
  const double nsq = 1e9 / static_cast<double>(q);
  r.single1 = median(ts1) * nsq;
  r.single2 = median(ts2) * nsq;
  r.batch1 = median(tb1q) * nsq;
  r.batch2 = median(tb2q) * nsq;
  r.rotating = median(trot) * 1e9 / static_cast<double>(dr.size());

  // Validation: every timed answer identical across APIs and thread counts; subsample == brute.
  check_equal(out_s2, out_s1, tag + " single 2T vs single 1T");
  check_equal(out_b1, out_s1, tag + " batch 1T vs single 1T");
  check_equal(out_b2, out_s1, tag + " batch 2T vs single 1T");
  std::size_t checked = 0;
  for (std::size_t j = 0; j < sub_rnd.size(); ++j)
    if (sub_rnd[j] < q) {
      ++checked;
      if (!(out_s1[sub_rnd[j]] == ref_rnd[j]))
        fail(tag + " random query " + std::to_string(sub_rnd[j]) + ": " + show(out_s1[sub_rnd[j]]) + " != brute_lowest " +
             show(ref_rnd[j]));
    }
  for (std::size_t j = 0; j < sub_rot.size(); ++j)
    if (sub_rot[j] < dr.size()) {
      ++checked;
      if (!(out_rot[sub_rot[j]] == ref_rot[j]))
        fail(tag + " rotating query " + std::to_string(sub_rot[j]) + ": " + show(out_rot[sub_rot[j]]) +
             " != brute_lowest " + show(ref_rot[j]));
    }
  if (checked == 0) fail(tag + ": no query was checked against brute_lowest");
  std::cerr << "    1T single " << sig3(r.single1) << " ns, 1T batch " << sig3(r.batch1) << " ns, 2T batch "
            << sig3(r.batch2) << " ns, rotating " << sig3(r.rotating) << " ns; " << checked
            << " answers == brute_lowest\n";
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  try {
    o = parse(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "bench_contact: " << e.what() << "\n";
    return 1;
  }
  std::string cmdline;
  for (int i = 0; i < argc; ++i) {
    if (i > 0) cmdline.push_back(' ');
    cmdline.append(argv[i]);
  }
  const int all_threads = omp_get_max_threads();
  const std::string load_before = loadavg();
  const std::string start = now_utc();
  const auto t_start = Clock::now();

  // Directions, generated once: the Q-th random query is the same for every N and backend.
  const std::vector<Vec3> rnd = random_directions(o.queries, o.seed);
  const std::vector<Vec3> rot = rotating_directions(o.queries, o.seed, o.rotation_step);
  const auto sub_rnd = subsample(o.queries, o.validate);

  std::vector<Row> rows;
  std::vector<FreshRow> fresh;
  std::map<std::uint64_t, double> gen_s, gen1_s;
  const asperity::SphereParams base{};  // R = 3 mm, a = 0.65 µm (the library default)

  for (const std::uint64_t n : o.sizes) {
    std::cerr << "N = " << n << "\n";
    asperity::SphereParams p = base;
    p.asperities = n;
    // Generation: all cores (the median), then 1 thread.
    std::vector<double> tg, tg1;
    asperity::RoughSphere body;
    const int build_threads = o.build_threads > 0 ? o.build_threads : all_threads;
    omp_set_num_threads(build_threads);
    for (int k = 0; k < o.repeats; ++k) {
      body = {};
      const auto t0 = Clock::now();
      body = asperity::make_rough_sphere(p, o.seed, 0);
      tg.push_back(since(t0));
    }
    omp_set_num_threads(1);
    for (int k = 0; k < o.repeats; ++k) {
      const auto t0 = Clock::now();
      auto tmp = asperity::make_rough_sphere(p, o.seed, 0);
      tg1.push_back(since(t0));
    }
    omp_set_num_threads(all_threads);
    gen_s[n] = median(tg);
    gen1_s[n] = median(tg1);
    const std::span<const Vec3> c = body.centres;

    // Reference answers at the validation positions (each backend checks those below its Q).
    const auto t_ref = Clock::now();
    const auto ref_rnd = reference(c, rnd, sub_rnd);
    const auto ref_rot = reference(c, rot, sub_rnd);
    std::cerr << "  generation " << sig3(gen_s[n]) << " s; brute_lowest reference for " << 2 * sub_rnd.size()
              << " queries in " << sig3(since(t_ref)) << " s\n";

    for (const Backend b : o.backends) {
      Row r = measure(o, b, c, rnd, rot, ref_rnd, sub_rnd, ref_rot, sub_rnd, all_threads);
      r.gen = gen_s[n];
      rows.push_back(r);
    }

    if (o.fresh) {
      FreshRow f;
      f.n = n;
      for (const int t : {1, 2}) {
        std::vector<double> tf;
        for (int k = 0; k < o.repeats; ++k) {
          asperity::EnsembleConfig cfg;
          cfg.sphere = p;
          cfg.mode = asperity::Mode::sampled;
          cfg.drops = o.fresh_drops;
          cfg.seed = o.seed;
          cfg.threads = t;
          const auto t0 = Clock::now();
          const auto s = asperity::run_contact_ensemble(cfg);
          tf.push_back(since(t0));
          if (s.r_x.size() != o.fresh_drops) fail("fresh ensemble returned a wrong number of drops");
        }
        (t == 1 ? f.rate1 : f.rate2) = static_cast<double>(o.fresh_drops) / median(tf);
      }
      omp_set_num_threads(all_threads);
      std::cerr << "  fresh: " << sig3(f.rate1) << " drops/s (1T), " << sig3(f.rate2) << " drops/s (2T)\n";
      fresh.push_back(f);
    }
  }

  // ---- report ----
  const double total = since(t_start);
  std::cout << "## Machine\n\n"
            << "- CPU: " << cpu_model() << "; " << std::thread::hardware_concurrency() << " logical CPUs, OpenMP max threads "
            << all_threads << "\n"
            << "- compiler: " <<
#if defined(__clang__)
      "clang "
#elif defined(__GNUC__)
      "g++ "
#endif
            << __VERSION__ <<
#ifdef NDEBUG
      " (NDEBUG)"
#else
      " (assertions ON: not a Release build)"
#endif
            << "\n"
            << "- started " << start << ", " << sig3(total) << " s wall in total\n"
            << "- load average (1/5/15 min) before: " << load_before << "; after: " << loadavg() << "\n\n"
            << "## Command\n\n```\n" << cmdline << "\n```\n\n"
            << "Medians of " << o.repeats << " repetitions (builds: fewer, shown as `(k×)`, when one build takes longer than "
            << "the " << fmt(o.build_budget, 0) << " s budget). Sphere: R = " << base.radius << " m, a = " << base.asperity_radius
            << " m, seed " << o.seed << ". ns/query = wall time / Q; 2T columns are wall time / Q with 2 threads "
            << "(aggregate throughput), so per-core cost is twice that. Rotating: consecutive directions "
            << o.rotation_step << " rad apart, 1-thread batch API. Ratios: 1T batch time of the baseline / this backend "
            << "(> 1: faster than the baseline). Every backend's answers equal brute_lowest on a subsample of up to "
            << o.validate << " random + " << o.validate << " rotating timed queries, and single/batch/1T/2T answers are "
            << "identical on all timed queries.\n\n";

  std::cout << "## Contact queries\n\n"
            << "| N | backend | Q | build s (" << (o.build_threads > 0 ? o.build_threads : all_threads)
            << "T) | build s (1T) | gen+build s (" << (o.build_threads > 0 ? o.build_threads : all_threads)
            << "T) | bytes/asperity | ns/query 1T single | ns/query 2T single | ns/query 1T batch | ns/query 2T batch | "
               "ns/query rotating | ratio vs brute | ratio vs kdtree | ratio vs fcl |\n"
            << "|---:|:---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  auto find = [&](std::uint64_t n, Backend b) -> const Row* {
    for (const auto& r : rows)
      if (r.n == n && r.backend == b && r.skipped.empty()) return &r;
    return nullptr;
  };
  auto ratio = [&](const Row& r, Backend base_b) -> std::string {
    const Row* base_r = find(r.n, base_b);
    if (!base_r) return "—";
    return sig3(base_r->batch1 / r.batch1);
  };
  for (const auto& r : rows) {
    std::cout << "| " << size_name(r.n) << " | " << asperity::to_string(r.backend) << " | ";
    if (!r.skipped.empty()) {
      std::cout << "skipped: " << r.skipped << " | | | | | | | | | | | | |\n";
      continue;
    }
    auto reps = [&](int k) { return k < o.repeats ? " (" + std::to_string(k) + "×)" : std::string(); };
    std::cout << r.q << " | " << sig3(r.build) << reps(r.build_reps) << " | "
              << (std::isfinite(r.build1) ? sig3(r.build1) + reps(r.build1_reps) : "—") << " | " << sig3(r.gen + r.build)
              << " | " << sig3(r.bytes_per) << " | " << sig3(r.single1) << " | " << sig3(r.single2) << " | " << sig3(r.batch1)
              << " | " << sig3(r.batch2) << " | " << sig3(r.rotating) << " | " << ratio(r, Backend::brute) << " | "
              << ratio(r, Backend::kdtree) << " | " << ratio(r, Backend::fcl) << " |\n";
  }

  std::cout << "\n## Sphere generation (make_rough_sphere)\n\n| N | gen s (" << (o.build_threads > 0 ? o.build_threads : all_threads)
            << "T) | gen s (1T) |\n|---:|---:|---:|\n";
  for (const auto n : o.sizes) std::cout << "| " << size_name(n) << " | " << sig3(gen_s[n]) << " | " << sig3(gen1_s[n]) << " |\n";

  if (o.fresh) {
    std::cout << "\n## Fresh mode (run_contact_ensemble, Mode::sampled, " << o.fresh_drops
              << " drops, wall time of the call)\n\n| N | drops/s 1T | drops/s 2T | 2T/1T |\n|---:|---:|---:|---:|\n";
    for (const auto& f : fresh)
      std::cout << "| " << size_name(f.n) << " | " << sig3(f.rate1) << " | " << sig3(f.rate2) << " | "
                << sig3(f.rate2 / f.rate1) << " |\n";
  }
  std::cout << std::flush;
  return 0;
}
