// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A lazy exact rough sphere: N iid uniform asperity centres on the unit sphere, of which only the
// part a query touches is ever generated.
//
// Construction (exact in law): the sphere is split recursively into cells [z0,z1] x [phi0,phi1];
// by Archimedes a cell's area is (z1 - z0)(phi1 - phi0), and every split halves z or phi range at
// the equal-area midpoint, so a cell holding n centres passes Binomial(n, 1/2) of them to its first
// child. Cells with at most `leaf_size` centres are leaves; their centres are uniform in (z, phi).
// Every cell's count and every leaf's centres are pure functions of (seed, sphere id, cell id)
// (Stream(seed, Purpose::lazy_sphere, sphere, 2 id) and 2 id + 1), so the sphere is one fixed
// sample whatever order queries come in. Indices are global: the centres of a leaf follow those
// of all leaves left of it (offsets are the counts of left siblings along the path), so
// materialise() returns the same indexed set a query sees, and lowest() equals brute_lowest on it.
//
// Query: best-first descent over cells ordered by an exact lower bound of contact_key over the
// cell (the maximum of u.d over a (z, phi) cell in closed form, minus a margin of 1e-13 that
// dominates every rounding error), stopping when no open cell can beat the current runner-up.
// Generated cells are kept: later queries on the same sphere reuse them. reset() starts a new
// sphere keeping the memory.
//
// Binomial(n, 1/2) is drawn exactly without std::binomial_distribution (whose draws differ
// between library versions): popcount of n random bits for n <= 512, otherwise inversion that
// starts at the mode and walks outwards (pmf from lgamma, then exact ratios), O(sqrt n) steps.
// The mode's pmf (three lgamma and an exp) can come from a BinomialModeCache shared by the spheres
// of a run (the same value, computed once per n).
#include <atomic>
#include <cstdint>
#include <limits>
#include <vector>

#include "asperity/core/contact.hpp"
#include "asperity/core/geometry.hpp"

namespace asperity {

class Stream;

/// P(X = floor(n/2)) for X ~ Binomial(n, 1/2), n <= n_max, each value computed on first use and
/// kept: one cache serves the lazy spheres of all threads of a run (thread-safe; every thread
/// computes the same value, so whichever stores it first the draws are the same).
class BinomialModeCache {
 public:
  /// An empty cache for n = 0 .. n_max (8 bytes per entry, allocated now).
  explicit BinomialModeCache(std::uint64_t n_max) : p_(n_max + 1) {}
  /// P(X = floor(n/2)) for X ~ Binomial(n, 1/2): from the cache for n <= max_n() (computed and
  /// stored on first use), computed each time above. Thread-safe.
  double operator()(std::uint64_t n);
  /// The largest n the cache keeps (n_max of the constructor).
  std::uint64_t max_n() const { return p_.size() - 1; }

 private:
  std::vector<std::atomic<double>> p_;  // 0: not computed yet (the mode's pmf is > 0)
};

/// Binomial(n, 1/2) from the stream (exact: popcount for small n, mode-centred inversion above).
/// `cache` (optional, any n_max) only saves work: the draw is the same with or without it.
std::uint64_t binomial_half(std::uint64_t n, Stream& s, BinomialModeCache* cache = nullptr);

/// What LazySphere::lowest answers: the two lowest asperities and the lowest one's centre (which
/// a lazy sphere cannot hand out by index without generating the whole sphere).
struct LazyNearest {
  Nearest nearest;  ///< as brute_lowest on materialise()
  Vec3 u{0, 0, 0};  ///< unit centre of the lowest asperity (body frame)
};

/// A rough sphere of N uniform centres generated lazily (see the file's comment): the same sample
/// as materialise() would give, generating only the cells a query cannot rule out. One per thread.
class LazySphere {
 public:
  /// N >= 1 (< 2^32, indices are 32-bit) centres; throws std::invalid_argument otherwise.
  /// `modes` (optional, must outlive the sphere) is shared work, not state: same sphere without it.
  LazySphere(std::uint64_t n, std::uint64_t seed, std::uint64_t sphere_id, unsigned leaf_size = 8,
             BinomialModeCache* modes = nullptr);

  /// Start another sphere (same N): clears the cache, keeps the allocated memory.
  void reset(std::uint64_t seed, std::uint64_t sphere_id);

  /// The two lowest asperities for the unit body-frame down direction d. Generates and caches
  /// the cells it needs; not thread-safe (use one LazySphere per thread).
  LazyNearest lowest(const Vec3& d);

  /// All N centres in index order (generates the whole sphere: tests and small N only).
  std::vector<Vec3> materialise();

  std::uint64_t size() const { return n_; }  ///< N, the number of asperities
  /// Cells generated (and kept) so far for this sphere, leaves and inner cells: the work done.
  std::size_t cells_generated() const { return nodes_.size(); }
  /// Centres generated so far for this sphere (those of the leaves visited), out of N.
  std::size_t centres_generated() const { return points_.size(); }

 private:
  struct Node {
    double z0, z1, p0, p1;
    // Cached per cell because every query re-bounds the cached cells: acos of z0, z1 (the split
    // rule's polar extent, computed exactly as before so the sphere is the same sample) and
    // cos, sin of p0, p1 (the bound's phi part without a cos per call).
    double t0, t1, c0, s0, c1, s1;
    double r0, r1;  // sqrt(1 - z^2) at z0, z1 (the bound's and the split rule's, without a sqrt per call)
    std::uint64_t id;      // heap numbering: root 1, children 2 id and 2 id + 1
    std::uint64_t count;   // centres in the cell
    std::uint64_t offset;  // global index of its first centre
    std::int64_t child = -1;   // index of the first child in nodes_ (second = child + 1)
    std::int64_t points = -1;  // leaves: index of the first centre in points_
    // The cell's z and phi intervals in the trees of z and of phi halvings (root 1, halves 2 k
    // and 2 k + 1): an edge's value, and so its acos, sqrt, cos, sin, depends on nothing else.
    std::uint64_t zk = 1, pk = 1;
  };
  // acos and sqrt(1 - z^2) of the midpoint of z interval k, cos and sin of that of phi interval
  // k, for k < kEdgeTable: computed on first use and kept across reset() (the same values for
  // every sphere), so the splits of later spheres take no acos, sqrt, sin or cos.
  static constexpr std::uint64_t kEdgeTable = std::uint64_t{1} << 15;
  struct EdgePair {
    double first = std::numeric_limits<double>::quiet_NaN(), second = 0;
  };
  std::vector<EdgePair> z_edges_, phi_edges_;
  bool is_leaf(const Node& c) const { return c.count <= leaf_size_ || c.id >= (std::uint64_t{1} << 60); }
  void expand(std::size_t i);
  void fill(std::size_t i);
  struct Direction {  // a query's down direction d, with dxy = |(d_x, d_y)|, psi its azimuth
    Vec3 d;
    double dxy, psi, cpsi, spsi;
  };
  static double lower_key(const Node& c, const Direction& q);
  // A leaf's centres are stored as drawn, (NaN, z, phi), and converted to (x, y, z) on first use:
  // most centres of a visited leaf are ruled out by deferred_lower_key, a lower bound of their key
  // from (z, phi) alone (the same centres, the same values once converted).
  static constexpr double kDeferred = std::numeric_limits<double>::quiet_NaN();
  const Vec3& centre(std::size_t p);
  static double deferred_lower_key(const Vec3& zphi, const Direction& q);

  std::uint64_t n_, seed_, sphere_;
  unsigned leaf_size_;
  BinomialModeCache* modes_;
  std::vector<Node> nodes_;
  std::vector<Vec3> points_;
  std::vector<std::pair<double, std::size_t>> heap_;  // scratch of lowest()
};

}  // namespace asperity
