// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/laws/laplace.hpp"

#include <omp.h>

#include <Eigen/Dense>
#include <boost/random/binomial_distribution.hpp>
#include <boost/random/exponential_distribution.hpp>
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <utility>
#include <stdexcept>
#include <string>

#include "asperity/core/random.hpp"
#include "core/format.hpp"

namespace asperity {

using detail::num;

double AsymmetricLaplace::a() const { return std::exp(log_a); }
double AsymmetricLaplace::c() const { return std::exp(log_c); }

double AsymmetricLaplace::log_pdf(double t) const {
  const double A = a(), C = c();
  // log h = log a + log c - log(a + c), evaluated without forming a + c when one rate dominates.
  const double log_h = log_a + log_c - (std::max(log_a, log_c) + std::log1p(std::exp(-std::abs(log_a - log_c))));
  return t < m ? log_h + A * (t - m) : log_h - C * (t - m);
}

double AsymmetricLaplace::pdf(double t) const { return std::exp(log_pdf(t)); }

double AsymmetricLaplace::cdf(double t) const {
  const double A = a(), C = c();
  const double pl = C / (A + C), pr = A / (A + C);  // masses left and right of the mode
  return t < m ? pl * std::exp(A * (t - m)) : 1.0 - pr * std::exp(-C * (t - m));
}

double AsymmetricLaplace::quantile(double p) const {
  if (!(p > 0 && p < 1)) throw std::invalid_argument("AsymmetricLaplace::quantile: p must be in (0,1), got " + num(p));
  const double A = a(), C = c();
  const double pl = C / (A + C), pr = A / (A + C);
  return p < pl ? m + std::log(p / pl) / A : m - std::log((1.0 - p) / pr) / C;
}

double AsymmetricLaplace::mean() const { return m + 1.0 / c() - 1.0 / a(); }

double AsymmetricLaplace::sample(Stream& s) const {
  const double e1 = -std::log(s.uniform()), e2 = -std::log(s.uniform());
  return m + e1 / c() - e2 / a();
}

LaplaceFit fit_asymmetric_laplace_sorted(std::span<const double> t) {
  const std::size_t n = t.size();
  if (n < 3) throw std::invalid_argument("asymmetric Laplace fit needs >= 3 values, got " + std::to_string(n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(t[i])) throw std::invalid_argument("asymmetric Laplace fit: value " + std::to_string(i) + " is " + num(t[i]));
    if (i && t[i] < t[i - 1]) throw std::invalid_argument("asymmetric Laplace fit: data not sorted at index " + std::to_string(i));
  }
  // L_j = sum_{i<j} (t_j - t_i) and R_j = sum_{i>j} (t_i - t_j), accumulated from sums of
  // non-negative terms: no cancellation even when the spread is 1e-6 of the values.
  std::vector<double> R(n, 0.0);
  for (std::size_t j = n - 1; j > 0; --j) R[j - 1] = R[j] + static_cast<double>(n - j) * (t[j] - t[j - 1]);
  double L = 0, best = std::numeric_limits<double>::infinity(), bestL = 0, bestR = 0;
  std::size_t best_j = n;
  for (std::size_t j = 0; j < n; ++j) {
    if (j) L += static_cast<double>(j) * (t[j] - t[j - 1]);
    if (L > 0 && R[j] > 0) {
      const double g = std::sqrt(L) + std::sqrt(R[j]);
      if (g < best) best = g, best_j = j, bestL = L, bestR = R[j];
    }
  }
  if (best_j == n) throw std::invalid_argument("asymmetric Laplace fit: all " + std::to_string(n) + " values are equal");
  const double dn = static_cast<double>(n);
  const double s = std::sqrt(bestL * bestR);
  LaplaceFit f;
  f.n = n;
  f.mode_rank = best_j;
  f.law.m = t[best_j];
  f.law.log_a = std::log(dn) - std::log(bestL + s);
  f.law.log_c = std::log(dn) - std::log(bestR + s);
  f.log_likelihood = dn * std::log(dn) - dn - 2.0 * dn * std::log(best);
  const double a = f.law.a(), c = f.law.c(), ac = a + c;
  Eigen::Matrix3d I;
  I << a * c, -a * c / ac, a * c / ac,
      -a * c / ac, c * (2 * a + c) / (ac * ac), -a * c / (ac * ac),
      a * c / ac, -a * c / (ac * ac), a * (2 * c + a) / (ac * ac);
  const Eigen::Matrix3d cov = I.inverse() / dn;
  f.m = {f.law.m, std::sqrt(cov(0, 0))};
  f.log_a = {f.law.log_a, std::sqrt(cov(1, 1))};
  f.log_c = {f.law.log_c, std::sqrt(cov(2, 2))};
  f.a = {a, a * f.log_a.se};
  f.c = {c, c * f.log_c.se};
  return f;
}

LaplaceFit fit_asymmetric_laplace(std::span<const double> x) {
  std::vector<double> t(x.begin(), x.end());
  for (std::size_t i = 0; i < t.size(); ++i)
    if (!std::isfinite(t[i])) throw std::invalid_argument("asymmetric Laplace fit: value " + std::to_string(i) + " is " + num(t[i]));
  std::sort(t.begin(), t.end());
  return fit_asymmetric_laplace_sorted(t);
}

namespace {
// KS distance only (the p-value comes from the bootstrap).
double ks_distance(std::span<const double> sorted, const AsymmetricLaplace& law) {
  const double n = static_cast<double>(sorted.size());
  double D = 0;
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    const double F = law.cdf(sorted[i]);
    D = std::max({D, (static_cast<double>(i) + 1.0) / n - F, F - static_cast<double>(i) / n});
  }
  return D;
}
// Whether the KS distance of `sorted` to L reaches D, deciding exactly as
// ks_distance(sorted, L) >= D would, with far fewer cdf evaluations (the bootstrap's replicates
// only need this yes/no). Within a block [i0, i1] of sorted values F is monotone, so every term
// (i+1)/n - F(y_i) and F(y_i) - i/n is at most (i1+1)/n - F(y_i0) or F(y_i1) - i0/n: a block whose
// bound stays below D by more than the rounding (1e-12 covers an ulp of non-monotonicity of the
// computed F at the mode) cannot reach D and is skipped; otherwise its terms are computed exactly
// as ks_distance does, stopping at the first that reaches D. Blocks span ~D n / 8 points, so the
// bound is loose by ~D/4 and most blocks of a null replicate are skipped.
bool ks_distance_reaches(std::span<const double> sorted, const AsymmetricLaplace& law, double D) {
  const std::size_t n = sorted.size();
  const double dn = static_cast<double>(n);
  const double A = law.a(), C = law.c(), pl = C / (A + C), pr = A / (A + C);
  auto F = [&](double t) { return t < law.m ? pl * std::exp(A * (t - law.m)) : 1.0 - pr * std::exp(-C * (t - law.m)); };
  const std::size_t block = std::max<std::size_t>(1, static_cast<std::size_t>(D * dn / 8));
  for (std::size_t i0 = 0; i0 < n; i0 += block) {
    const std::size_t i1 = std::min(n, i0 + block) - 1;
    const double F0 = F(sorted[i0]), F1 = i1 == i0 ? F0 : F(sorted[i1]);
    const double bound = std::max((static_cast<double>(i1) + 1.0) / dn - F0, F1 - static_cast<double>(i0) / dn);
    if (bound < D - 1e-12) continue;
    for (std::size_t i = i0; i <= i1; ++i) {
      const double Fi = i == i0 ? F0 : i == i1 ? F1 : F(sorted[i]);
      if (std::max({0.0, (static_cast<double>(i) + 1.0) / dn - Fi, Fi - static_cast<double>(i) / dn}) >= D) return true;
    }
  }
  return D <= 0;
}
}  // namespace

namespace {
// A Stream as a Boost.Random engine: 64 random bits per call.
struct StreamBits {
  using result_type = std::uint64_t;
  Stream* s;
  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return ~result_type{0}; }
  result_type operator()() { return s->bits(); }
};

}  // namespace

// Exact in law: K ~ Binomial(n, pl), pl = P(t < m), of the draws lie left of the mode, each
// m - E/a, the other n - K at m + E/c, E ~ Exp(1) iid; the k exponentials of one side in ascending
// order are Renyi's sums X_(j) = X_(j-1) + Z_j/(k - j + 1) of iid standard exponentials Z. The
// inversion of n + 1 exponentials used before took two logarithms per value, the bootstrap's main
// cost; here K comes from Boost's binomial (BTRD) and the Z from Boost's ziggurat (one 64-bit word
// per draw but for ~1 % rejections, a logarithm only in its rare tail), Boost 1.74 as packaged
// (tests pin a sample's values). The left side is written from the mode outwards. Sorted by
// construction: X only grows and every rounded step is monotone; no 1 - U cancels (each side is a
// sum from the mode).
void sorted_sample(const AsymmetricLaplace& L, Stream& s, std::span<double> y) {
  const double pl = L.c() / (L.a() + L.c());
  StreamBits eng{&s};
  const std::size_t n = y.size();
  const auto k = static_cast<std::size_t>(boost::random::binomial_distribution<std::int64_t>(static_cast<std::int64_t>(n), pl)(eng));
  const boost::random::exponential_distribution<double> E;
  const double ia = 1.0 / L.a(), ic = 1.0 / L.c();
  double x = 0;
  for (std::size_t j = 0; j < k; ++j) {  // X_(j+1) of the k left draws: y[k - 1 - j]
    x += E(eng) / static_cast<double>(k - j);
    y[k - 1 - j] = L.m - x * ia;
  }
  x = 0;
  for (std::size_t j = k; j < n; ++j) {
    x += E(eng) / static_cast<double>(n - j);
    y[j] = L.m + x * ic;
  }
}

namespace {
// The law fit_asymmetric_laplace_sorted finds for a bootstrap replicate (drawn sorted and finite,
// so unchecked), the same values from the same sums, with `R`, `L` reused as scratch. The scan
// for the first minimum of g_j = sqrt(L_j) + sqrt(R_j) skips blocks that cannot hold it: L rises
// and R falls with j (as computed: sums of non-negative terms), and sqrt and + round monotonically,
// so on [j0, j1] every g_j >= sqrt(L_j0) + sqrt(R_j1); a block whose bound exceeds the best g so
// far (started at the generating law's mode, where the minimum lies) is skipped. False when all
// values are equal (no minimum).
bool replicate_law(std::span<const double> t, double pl, std::span<double> R, std::span<double> L,
                   AsymmetricLaplace& law) {
  const std::size_t n = t.size();
  R[n - 1] = 0, L[0] = 0;  // every other entry is written below
  for (std::size_t j = n - 1; j > 0; --j) R[j - 1] = R[j] + static_cast<double>(n - j) * (t[j] - t[j - 1]);
  for (std::size_t j = 1; j < n; ++j) L[j] = L[j - 1] + static_cast<double>(j) * (t[j] - t[j - 1]);
  double best = std::numeric_limits<double>::infinity();
  std::size_t best_j = n;
  auto consider = [&](std::size_t j) {
    if (L[j] > 0 && R[j] > 0) {
      const double g = std::sqrt(L[j]) + std::sqrt(R[j]);
      if (g < best || (g == best && j < best_j)) best = g, best_j = j;
    }
  };
  consider(std::min(n - 1, static_cast<std::size_t>(pl * static_cast<double>(n))));
  constexpr std::size_t kBlock = 64;
  for (std::size_t j0 = 0; j0 < n; j0 += kBlock) {
    const std::size_t j1 = std::min(n, j0 + kBlock) - 1;
    if (std::sqrt(L[j0]) + std::sqrt(R[j1]) > best) continue;
    for (std::size_t j = j0; j <= j1; ++j) consider(j);
  }
  if (best_j == n) return false;
  const double dn = static_cast<double>(n), bestL = L[best_j], bestR = R[best_j];
  const double s = std::sqrt(bestL * bestR);
  law.m = t[best_j];
  law.log_a = std::log(dn) - std::log(bestL + s);
  law.log_c = std::log(dn) - std::log(bestR + s);
  return true;
}
}  // namespace

namespace {
// Only grows: a thread moves between tests of different n, and regrowing a vector would zero it
// (the replicate writes every entry it reads).
struct ReplicateScratch {
  std::vector<double> y, R, L;
  void fit(std::size_t n) {
    if (y.size() < n) y.resize(n), R.resize(n), L.resize(n);
  }
};

// Whether replicate b of the bootstrap reaches the data's distance D.
bool replicate_exceeds(const LaplaceFit& fit, double pl, double D, std::size_t n, std::uint64_t seed,
                       std::uint64_t stream_index, std::size_t b, ReplicateScratch& w) {
  w.fit(n);
  const std::span<double> y(w.y.data(), n);
  Stream s(seed, Purpose::analysis, stream_index, static_cast<std::uint64_t>(b) + 1);
  sorted_sample(fit.law, s, y);
  AsymmetricLaplace law;
  return replicate_law(y, pl, std::span<double>(w.R.data(), n), std::span<double>(w.L.data(), n), law) &&
         ks_distance_reaches(y, law, D);
}
}  // namespace

namespace {
// A job's replicates as they finish, folded into K and L in replicate order.
struct JobState {
  std::mutex m;
  std::vector<std::int8_t> exceed;  // per replicate: -1 not known yet, else 0 / 1
  std::size_t next = 0, k = 0;      // replicates [0, next) folded in, k of them >= D
  bool stopped = false;             // the stop rule held after replicate next - 1
};

bool stop_holds(const SequentialStop& stop, std::size_t k, std::size_t done, std::size_t B) {
  const double kd = static_cast<double>(k);
  return stop.exceedances > 0 && k >= stop.exceedances && kd / static_cast<double>(done) >= stop.alpha &&
         (kd + 1.0) / (static_cast<double>(B) + 1.0) >= stop.alpha;
}

// Records replicate b and folds in every replicate now known in order, as a sequential loop
// would: the stop happens at the same replicate whatever order the threads finish in.
void record(JobState& st, const GofJob& job, std::size_t b, bool exceeds) {
  std::lock_guard<std::mutex> lock(st.m);
  st.exceed[b] = exceeds ? 1 : 0;
  while (!st.stopped && st.next < job.bootstrap && st.exceed[st.next] >= 0) {
    st.k += static_cast<std::size_t>(st.exceed[st.next++]);
    st.stopped = stop_holds(job.stop, st.k, st.next, job.bootstrap);
  }
}

bool finished(JobState& st) {
  std::lock_guard<std::mutex> lock(st.m);
  return st.stopped;
}

LaplaceGof result_of(const GofJob& job, const JobState& st, double D) {
  LaplaceGof g;
  g.D = D;
  g.bootstrap = job.bootstrap;
  g.replicates = st.next, g.exceedances = st.k;
  g.stopped_early = st.stopped && st.next < job.bootstrap;
  g.p = g.stopped_early ? static_cast<double>(st.k) / static_cast<double>(st.next)
                        : (1.0 + static_cast<double>(st.k)) / (1.0 + static_cast<double>(job.bootstrap));
  return g;
}
}  // namespace

std::vector<LaplaceGof> laplace_gof_batch(std::span<const GofJob> jobs, std::uint64_t seed,
                                          std::span<const std::function<void()>> beside) {
  const std::size_t nj = jobs.size();
  std::vector<double> D(nj), pl(nj);
  std::vector<JobState> state(nj);
  std::vector<std::size_t> order(nj);
#pragma omp parallel for schedule(dynamic, 1) if (nj > 1)
  for (std::int64_t jj = 0; jj < static_cast<std::int64_t>(nj); ++jj) {
    const auto j = static_cast<std::size_t>(jj);
    D[j] = ks_distance(jobs[j].sorted, jobs[j].fit->law);
    const auto& law = jobs[j].fit->law;
    pl[j] = law.c() / (law.a() + law.c());  // P(t < m) of the generating law
    state[j].exceed.assign(jobs[j].bootstrap, -1);
    order[j] = j;
  }
  // Largest work first: the big tests' replicates are shared by all threads from the start.
  auto work = [&](std::size_t j) { return static_cast<double>(jobs[j].sorted.size()) * static_cast<double>(jobs[j].bootstrap); };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return work(x) > work(y); });
  // (job, replicate) in that order, after the caller's tasks (job = nj: task `replicate`)
  std::vector<std::pair<std::size_t, std::size_t>> items;
  for (std::size_t t = 0; t < beside.size(); ++t) items.emplace_back(nj, t);
  for (std::size_t j : order)
    for (std::size_t b = 0; b < jobs[j].bootstrap; ++b) items.emplace_back(j, b);
  const int threads = omp_in_parallel() ? 1 : omp_get_max_threads();
  std::vector<ReplicateScratch> scratch(static_cast<std::size_t>(threads));
  std::vector<std::exception_ptr> errors(beside.size());
  const auto m = static_cast<std::int64_t>(items.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (m > 1)
  for (std::int64_t i = 0; i < m; ++i) {
    const auto [j, b] = items[static_cast<std::size_t>(i)];
    if (j == nj) {
      try {
        beside[b]();
      } catch (...) {
        errors[b] = std::current_exception();  // must not leave the parallel region
      }
      continue;
    }
    if (finished(state[j])) continue;  // past the stop: would be discarded
    const bool e = replicate_exceeds(*jobs[j].fit, pl[j], D[j], jobs[j].sorted.size(), seed, jobs[j].stream_index, b,
                                     scratch[static_cast<std::size_t>(omp_get_thread_num())]);
    record(state[j], jobs[j], b, e);
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
  std::vector<LaplaceGof> out;
  out.reserve(nj);
  for (std::size_t j = 0; j < nj; ++j) out.push_back(result_of(jobs[j], state[j], D[j]));
  return out;
}

LaplaceGof laplace_gof(std::span<const double> sorted, const LaplaceFit& fit, std::size_t bootstrap, std::uint64_t seed,
                       std::uint64_t stream_index, SequentialStop stop) {
  const GofJob job{sorted, &fit, bootstrap, stream_index, stop};
  return laplace_gof_batch(std::span<const GofJob>(&job, 1), seed).front();
}

}  // namespace asperity
