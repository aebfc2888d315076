// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/laws/block_ks.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "asperity/core/random.hpp"
#include "core/format.hpp"

namespace asperity {

BlockBins bin_by_block(std::span<const double> x, std::size_t spheres, std::size_t grid, std::size_t max_blocks,
                       std::span<const double> extra) {
  const std::size_t n = x.size();
  if (spheres == 0 || n == 0 || n % spheres != 0)
    throw std::invalid_argument("bin_by_block: " + std::to_string(n) + " samples are not a positive multiple of " +
                                std::to_string(spheres) + " spheres");
  if (grid < 2) throw std::invalid_argument("bin_by_block: grid must be >= 2, got " + std::to_string(grid));
  if (max_blocks < 1) throw std::invalid_argument("bin_by_block: max_blocks must be >= 1");
  for (double v : x)
    if (!std::isfinite(v)) throw std::invalid_argument("bin_by_block: non-finite sample " + std::to_string(v));
  BlockBins b;
  b.n = n;
  // Grid: quantiles of a strided subsample (law-free, the same for every law of the quantity).
  const std::size_t stride = (n + 65535) / 65536;
  std::vector<double> sub;
  sub.reserve(n / stride + 1);
  for (std::size_t i = 0; i < n; i += stride) sub.push_back(x[i]);
  std::sort(sub.begin(), sub.end());
  for (std::size_t j = 1; j < grid; ++j) b.edges.push_back(sub[std::min(sub.size() - 1, j * sub.size() / grid)]);
  for (double e : extra)
    if (std::isfinite(e)) b.edges.push_back(e);
  std::sort(b.edges.begin(), b.edges.end());
  b.edges.erase(std::unique(b.edges.begin(), b.edges.end()), b.edges.end());

  // Blocks: spheres, or groups of consecutive spheres (whole spheres: still independent).
  b.blocks = std::min(spheres, max_blocks);
  const std::size_t m = n / spheres, cells = b.cells();
  b.counts.assign(b.blocks * cells, 0);
  b.block_size.assign(b.blocks, 0);
  // Cell of x: lower_bound over the edges, started from a table of 4 slots per edge, uniform in x
  // (the slot's first and last candidate bracket the answer, which is then exact).
  const std::size_t slots = 4 * b.edges.size();
  const double e0 = b.edges.front(), span = b.edges.back() - e0;
  const double per = span > 0 ? double(slots) / span : 0.0;
  std::vector<std::uint32_t> first(slots + 2);
  for (std::size_t s = 0; s <= slots + 1; ++s) {
    const double at = e0 + double(s) / per;
    first[s] = static_cast<std::uint32_t>(
        per > 0 ? std::lower_bound(b.edges.begin(), b.edges.end(), at) - b.edges.begin() : 0);
  }
  auto cell = [&](double v) -> std::size_t {
    if (!(v > e0)) return 0;  // v <= e_0
    if (v > b.edges.back()) return b.edges.size();
    const auto s = std::min(slots, static_cast<std::size_t>((v - e0) * per));
    // Edges below slot s's left end are < v; from slot s + 1's left end on they are >= v... up to
    // rounding of the slot arithmetic: widen by one slot on each side.
    const std::size_t lo = first[s > 0 ? s - 1 : 0], hi = std::min<std::size_t>(first[s + 1 < slots + 1 ? s + 2 : slots + 1] + 1, b.edges.size());
    return static_cast<std::size_t>(std::lower_bound(b.edges.begin() + static_cast<std::ptrdiff_t>(lo),
                                                     b.edges.begin() + static_cast<std::ptrdiff_t>(hi), v) -
                                    b.edges.begin());
  };
  const std::int64_t nb = static_cast<std::int64_t>(b.blocks);
#pragma omp parallel for schedule(static)
  for (std::int64_t g = 0; g < nb; ++g) {
    const std::size_t k0 = static_cast<std::size_t>(g) * spheres / b.blocks;
    const std::size_t k1 = static_cast<std::size_t>(g + 1) * spheres / b.blocks;
    std::uint32_t* row = &b.counts[static_cast<std::size_t>(g) * cells];
    for (std::size_t i = k0 * m; i < k1 * m; ++i) ++row[cell(x[i])];
    b.block_size[static_cast<std::size_t>(g)] = (k1 - k0) * m;
  }
  b.pooled.assign(b.edges.size(), 0.0);
  std::vector<std::uint64_t> total(cells, 0);
  for (std::size_t g = 0; g < b.blocks; ++g)
    for (std::size_t c = 0; c < cells; ++c) total[c] += b.counts[g * cells + c];
  std::uint64_t cum = 0;
  for (std::size_t j = 0; j < b.edges.size(); ++j) {
    cum += total[j];
    b.pooled[j] = double(cum) / double(n);
  }
  return b;
}

double binned_ks_distance(const BlockBins& b, const Cdf& cdf) {
  double d = 0;
  for (std::size_t j = 0; j < b.edges.size(); ++j) {
    const double f = cdf(b.edges[j]);
    if (!(f >= 0 && f <= 1))
      throw std::invalid_argument("binned_ks_distance: cdf(" + detail::num(b.edges[j]) + ") = " + detail::num(f) + " is not in [0, 1]");
    d = std::max(d, std::abs(b.pooled[j] - f));
  }
  return d;
}

void block_bootstrap_ks(const BlockBins& b, std::uint64_t seed, std::uint64_t stream, std::size_t first,
                        std::size_t count, std::vector<double>& out) {
  const std::size_t cells = b.cells(), G = b.blocks, E = b.edges.size();
  // The bootstrap variance of a mean of G blocks is (G - 1)/G of the true one.
  const double inflate = G > 1 ? std::sqrt(double(G) / double(G - 1)) : 1.0;
  const std::size_t base = out.size();
  out.resize(base + count);
  const std::int64_t nr = static_cast<std::int64_t>(count);
#pragma omp parallel
  {
    std::vector<double> acc(cells);
    std::vector<std::uint32_t> mult(G);
#pragma omp for schedule(static)
    for (std::int64_t r = 0; r < nr; ++r) {
      Stream s(seed, Purpose::bootstrap, stream, first + static_cast<std::size_t>(r));
      std::fill(mult.begin(), mult.end(), 0u);
      for (std::size_t i = 0; i < G; ++i) ++mult[static_cast<std::size_t>(s.bits() % G)];
      std::fill(acc.begin(), acc.end(), 0.0);
      double size = 0;
      for (std::size_t g = 0; g < G; ++g) {
        if (!mult[g]) continue;
        const double w = mult[g];
        const std::uint32_t* row = &b.counts[g * cells];
        for (std::size_t c = 0; c < cells; ++c) acc[c] += w * row[c];
        size += w * double(b.block_size[g]);
      }
      double cum = 0, d = 0;
      for (std::size_t j = 0; j < E; ++j) {
        cum += acc[j];
        d = std::max(d, std::abs(cum / size - b.pooled[j]));
      }
      out[base + static_cast<std::size_t>(r)] = d * inflate;
    }
  }
}

std::vector<BlockKsResult> block_ks_tests(const BlockBins& b, std::span<const Cdf> laws, double alpha, std::uint64_t seed,
                                          std::uint64_t stream, std::size_t min_replicates, std::size_t max_replicates,
                                          std::span<const double> resolve) {
  if (!(alpha > 0 && alpha < 1)) throw std::invalid_argument("block_ks_tests: alpha must be in (0, 1)");
  if (!resolve.empty() && resolve.size() != laws.size())
    throw std::invalid_argument("block_ks_tests: one resolve level per law, or none");
  for (double r : resolve)
    if (!(r > 0 && r <= alpha)) throw std::invalid_argument("block_ks_tests: resolve must be in (0, alpha]");
  std::vector<BlockKsResult> res(laws.size());
  for (std::size_t i = 0; i < laws.size(); ++i) res[i].D = binned_ks_distance(b, laws[i]);
  std::vector<double> dstar;
  // Rounds of replicates: B + 1 = 200, 1000, 5000, 10000 (then max_replicates). A law is decided early when
  // its p is clearly above (c/B > 5 alpha) or below ((1 + c)/(B + 1) <= resolve/5) the level.
  std::vector<std::size_t> rounds;
  for (std::size_t B : {min_replicates, std::size_t{999}, std::size_t{4999}, std::size_t{9999}, max_replicates})
    if (B >= min_replicates && B <= max_replicates && (rounds.empty() || B > rounds.back())) rounds.push_back(B);
  for (std::size_t round = 0; round < rounds.size(); ++round) {
    const std::size_t B = rounds[round];
    block_bootstrap_ks(b, seed, stream, dstar.size(), B - dstar.size(), dstar);
    bool all_decided = true;
    for (std::size_t i = 0; i < res.size(); ++i) {
      auto& r = res[i];
      const double level = resolve.empty() ? alpha : resolve[i];
      const auto c = static_cast<std::size_t>(std::count_if(dstar.begin(), dstar.end(), [&](double d) { return d >= r.D; }));
      r.replicates = B;
      r.p = double(1 + c) / double(B + 1);
      const bool clear = double(c) / double(B) > 5 * alpha || r.p <= level / 5;
      if (!clear) all_decided = false;
    }
    if (all_decided) break;
  }
  for (auto& r : res) {
    if (r.p <= alpha)
      r.verdict = Verdict::reject;
    else if (1.0 / double(r.replicates + 1) >= alpha)
      r.verdict = Verdict::undecided;
    else
      r.verdict = Verdict::accept;
  }
  return res;
}

}  // namespace asperity
