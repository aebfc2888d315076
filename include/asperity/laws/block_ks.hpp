// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The decisive goodness-of-fit test of an explicit ensemble: a KS statistic on ALL drops of K
// spheres x M rotations, with a null distribution that accounts for the spread between spheres.
//
// Drops of one sphere are correlated (they sample that sphere's own, quenched, law); spheres are
// independent. So the pooled empirical cdf F^ is compared with a law F on a fine grid of points
// e_1 < ... < e_J (quantiles of a subsample of the pooled data, law-free), D = max_j |F^(e_j) - F(e_j)|,
// and the distribution of D under H0 (E[F^] = F) is estimated by a block bootstrap over spheres:
// resample the blocks with replacement, D* = max_j |F*(e_j) - F^(e_j)| (centred), scaled by
// sqrt(G/(G-1)) for the G blocks (the bootstrap variance is (G-1)/G of the true one). The grid is
// the same for every law of a quantity, so one set of replicates serves them all; a replicate
// costs O(G J), never O(drops). p = (1 + #{D* >= D}) / (B + 1).
//
// B adapts: replicates are drawn in rounds until every law is decided (p clearly above or below
// alpha) or B reaches max_replicates; a law whose smallest attainable p, 1/(B+1), is not below
// alpha is "undecided" -- never "accept".
//
// Blocks: spheres, or groups of consecutive spheres when there are more than max_blocks of them
// (groups of whole spheres are independent too).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "asperity/laws/statistics.hpp"
#include "asperity/laws/verdict.hpp"

namespace asperity {

/// Samples binned per block on a common grid: what the block bootstrap resamples (O(G J) per
/// replicate for G blocks and J grid points, whatever the number of samples).
struct BlockBins {
  std::vector<double> edges;               ///< grid e_j, ascending, distinct
  std::vector<std::uint32_t> counts;       ///< blocks x (edges + 1): counts of x <= e_0, (e_0, e_1], ..., > e_last
  std::vector<std::uint64_t> block_size;   ///< samples per block
  std::size_t blocks = 0;                  ///< G, the number of blocks
  std::size_t n = 0;                       ///< all samples
  std::vector<double> pooled;              ///< F^(e_j): fraction of all samples <= e_j
  std::size_t cells() const { return edges.size() + 1; }  ///< counts per block: the edges + 1
};

/// Bins `x` (drops in sphere order: sphere k holds x[k m, (k+1) m), m = x.size()/spheres) on a grid
/// of about `grid` points at quantiles of a strided subsample (<= 65536 values) of x, plus `extra`
/// points (e.g. the location of an atom of the law). Blocks: the spheres, or `max_blocks` groups of
/// consecutive spheres. Throws std::invalid_argument for non-finite x, spheres = 0 or not dividing
/// x.size(), or grid < 2.
BlockBins bin_by_block(std::span<const double> x, std::size_t spheres, std::size_t grid = 1024,
                       std::size_t max_blocks = 256, std::span<const double> extra = {});

/// max_j |F^(e_j) - F(e_j)| (F must be right-continuous: F(e) = P(X <= e), atoms included).
double binned_ks_distance(const BlockBins& b, const Cdf& cdf);

/// Replicates [first, first + count) of the centred block bootstrap of D, appended to `out`
/// (replicate r is a pure function of (seed, stream, r): any thread count gives the same values).
void block_bootstrap_ks(const BlockBins& b, std::uint64_t seed, std::uint64_t stream, std::size_t first,
                        std::size_t count, std::vector<double>& out);

/// The block-bootstrap KS test of one law.
struct BlockKsResult {
  double D = 0;               ///< binned KS distance of the pooled sample
  double p = 1;               ///< (1 + #{D* >= D}) / (B + 1)
  std::size_t replicates = 0; ///< B
  Verdict verdict = Verdict::undecided;  ///< accept, reject, or undecided (1/(B+1) not below alpha)
};

/// Tests every law in `laws` against the pooled sample on one set of replicates (adaptive B, from
/// min_replicates up to max_replicates). `stream` keeps the replicates of different quantities apart.
/// Law i is decided early once its p is clearly above alpha or clearly below resolve[i] (p <=
/// resolve[i]/5; empty: alpha for every law). A run's family (laws/family.hpp, Holm) compares the
/// smallest p with alpha/m: a decisive law of a run of m tests gets resolve = alpha/m or less, so
/// that its rejection is not left at a floor (1/(B + 1) = 0.001 at B = 999) alpha/m cannot reach.
std::vector<BlockKsResult> block_ks_tests(const BlockBins& b, std::span<const Cdf> laws, double alpha, std::uint64_t seed,
                                          std::uint64_t stream, std::size_t min_replicates = 199,
                                          std::size_t max_replicates = 9999, std::span<const double> resolve = {});

}  // namespace asperity
