// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The streaming path of a contact ensemble (issue 14): the same drops as run_contact_ensemble (same
// spheres, rotations and streams), but each drop's r_xy, r_x, r_y goes straight into integer
// histograms and running moments (laws/binned.hpp); nothing per drop is kept, so memory does not
// grow with the number of drops.
//
// Determinism: drops are cut into units of fixed drop-index ranges (one sphere's rotations
// [j 4096, (j+1) 4096)); a unit's moments are accumulated in drop order by one thread and units are
// merged in index order after each wave of units; counts are integers. So the statistics are the
// same bits for any thread count and schedule, and a run resumed from a checkpoint (taken between
// waves) ends with the same bits as one that was never interrupted.
//
// Blocks: the 2^coarse per-block histograms and moments group whole spheres (at most kStreamBlocks
// groups of consecutive spheres; sampled runs: groups of consecutive drops), so the decisive tests
// take their error from the spread between spheres.
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "asperity/experiments/ensemble.hpp"
#include "asperity/laws/binned.hpp"

namespace asperity {

/// Most blocks of spheres (sampled: of drops) a streaming run keeps apart: the sphere-block
/// bootstrap of its decisive tests resamples them.
inline constexpr std::size_t kStreamBlocks = 256;
/// Each block counts its drops in 2^kStreamCoarseLog2 cells of the reference law's u = F(x): the
/// grid of the blocks' KS distances (resolution 2^-10).
inline constexpr unsigned kStreamCoarseLog2 = 10;
/// The streamed quantities, in this order.
inline const std::vector<std::string> kStreamQuantities{"r_xy", "r_x", "r_y"};

/// Everything a checkpoint holds: the statistics so far and where to continue.
struct StreamState {
  std::uint64_t next_unit = 0;  ///< units [0, next_unit) are done: 4096 rotations of one sphere (sampled: one drop)
  std::vector<BinnedStats> stats;     ///< one per kStreamQuantities
  std::uint64_t core_contacts = 0;    ///< drops so far where the central sphere touches first
  std::uint64_t check_queries = 0;    ///< cross-checked queries so far (CrossCheck)
  std::uint64_t check_agreed = 0;     ///< of them, answered alike by every backend
  std::uint64_t index_bytes = 0;      ///< largest spatial index built so far
  /// Field by field (a resumed run's state against the one it was written from).
  friend bool operator==(const StreamState&, const StreamState&) = default;
};

/// The empty state of a run: references Eq. 14's Rayleigh (r_xy) and Eq. 18's normal (r_x, r_y)
/// with sigma^2 = 1 / (2 pi lambda); 2^c.bins_log2 fine bins.
StreamState initial_stream_state(const EnsembleConfig& c);

/// Between waves (every ~10^5..10^6 drops) the driver asks stop(): true ends the run with
/// complete = false after a checkpoint; checkpoint_due(): true writes one and goes on.
struct StreamHooks {
  std::function<bool()> stop;                             ///< true: checkpoint and end (empty: never)
  std::function<bool()> checkpoint_due;                   ///< true: write a checkpoint now (empty: never)
  std::function<void(const StreamState&)> checkpoint;     ///< writes one (empty: none is written)
};

/// What run_contact_stream returns: the statistics, whether every drop ran, the design and timings.
struct ContactStream {
  StreamState state;            ///< the statistics (also what a checkpoint holds)
  bool complete = false;        ///< false: stopped by StreamHooks::stop after a checkpoint
  std::uint64_t spheres = 0;    ///< K (sampled: the drops)
  std::uint64_t rotations = 0;  ///< M rotations per sphere (sampled: 1)
  double seconds_generate = 0;  ///< wall time building the spheres [s]
  double seconds_index = 0;     ///< wall time building their spatial indices [s]
  double seconds_query = 0;     ///< wall time of the queries and the histograms [s]
  std::size_t index_bytes = 0;  ///< largest index of the whole run (resumed runs included)
  CrossCheck cross_check;       ///< queries answered again by other backends (as ContactSamples)
  std::size_t memory_bytes = 0;  ///< of the statistics (all threads' histograms), independent of the drops
};

/// One process's share of a run split across `ranks` processes (validate-geometry under mpirun):
/// whole blocks of spheres, rank r the blocks [r G / ranks, (r + 1) G / ranks). Every block's
/// moments are accumulated by one process in drop order, so merging the shares (merge_shares)
/// gives the same bits as one process running everything.
struct StreamShare {
  int rank = 0;   ///< this process, in [0, ranks)
  int ranks = 1;  ///< the processes the run is split across
  /// Field by field.
  friend bool operator==(const StreamShare&, const StreamShare&) = default;
};

/// The units [first, second) of `share` (units as StreamState::next_unit counts them).
/// Throws std::invalid_argument unless 0 <= rank < ranks.
std::pair<std::uint64_t, std::uint64_t> share_units(const EnsembleConfig& c, const StreamShare& share);

/// The drops of `share`.
std::uint64_t share_drops(const EnsembleConfig& c, const StreamShare& share);

/// Adds the share `o` to `into` (counts added, block moments merged, largest index kept). Shares of
/// one run own disjoint blocks, so the order of the calls does not change a bit.
void merge_shares(StreamState& into, const StreamState& o);

/// Why `st` cannot be the state of `c`'s run (its `share`) between waves, "" when it can: the
/// layout of initial_stream_state(c); next_unit inside the share; every block's coarse cells and
/// moments count exactly the drops of the units done, its moments finite and within a contact
/// point's reach; the fine histograms count all of them; the counters no more than possible. A
/// checkpoint (app/checkpoint.hpp) passes it before it is used.
std::string stream_state_problem(const EnsembleConfig& c, const StreamShare& share, const StreamState& st);

/// Runs (or continues from `resume`, a state of the same config and share) the ensemble of `c`, or
/// its `share`, on the streaming path. Throws std::invalid_argument for an invalid config (validate)
/// or an impact experiment, std::runtime_error when the cross-check disagrees (as
/// run_contact_ensemble).
ContactStream run_contact_stream(const EnsembleConfig& c, const Progress& progress = {}, const StreamHooks& hooks = {},
                                 const StreamState* resume = nullptr, const StreamShare& share = {});

}  // namespace asperity
