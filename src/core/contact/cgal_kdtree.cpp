// SPDX-License-Identifier: GPL-3.0-or-later
// kd-tree backend on CGAL 5.5 Spatial_searching (a baseline next to nanoflann).
//
// The tree holds (Point_3, Tag) pairs through Search_traits_adapter, so a leaf scan reads
// contiguous coordinates and the indices come with each neighbour. It is built in the
// constructor: CGAL builds lazily at the first query, and that lazy build is not thread-safe.
// After build() every query path used here (Orthogonal_k_neighbor_search, Kd_tree::search)
// only reads the tree, so `lowest` may run concurrently.
//
// Exact duplicates are folded before the build. CGAL's splitters cut by coordinate value and
// "slide" to split off at least one point, so a group of m identical centres becomes a chain of
// depth ~m: the recursive build overflowed the stack at m = 1e5. Identical centres have
// identical keys for every d, so only the two smallest indices of a group can ever appear in a
// canonical top two: each distinct position is stored once with its smallest index and the
// second smallest (its "twin", if any), and both are offered wherever the position is.
//
// Exactness. CGAL ranks by its own squared distance D (the same sum of squares as contact_key
// here, but nothing promises that, and its node bounds are updated incrementally:
// new = old + (b^2 - a^2)), and it breaks ties by traversal order. So CGAL only proposes; we decide:
//  1. The k = 3 nearest distinct positions by D. Offer their indices and twins, with canonical
//     keys, to a TopTwo: (k1, i1), (k2, i2). Let K3 be the largest key of the three positions.
//  2. Every position q outside those three was either rejected or evicted against the current
//     third-worst D (>= the final one, >= D of the key-K3 position) or sat in a subtree whose
//     lower bound was >= it. Those bounds are sums of at most a few dozen rounded terms, each no
//     larger than the result, so key(q) >= K3 (1 - 1e-13) (depth <= ~64 levels * 3 roundings of
//     2^-53 each). Hence if K3 - k2 > kTieTolerance * K3 (1e-12, ten times that error), every
//     outside centre has key > k2, and (i1, i2) are the canonical top two: certain.
//  3. Otherwise (ties or near-ties: symmetric pairs, clusters, keys so small they may have
//     underflowed) gather every position with key <= k2 (1 + 4 kTieTolerance) (+1e-300
//     absolute, for subnormal keys) by a Fuzzy_sphere range search with eps = 0, and take the
//     canonical top two of the gathered indices and twins. The true top two have key <= k2
//     (k2 is the key of a real centre), and Fuzzy_sphere decides membership and subtree overlap
//     by directly evaluated sums of squares (relative error ~1e-16): they are all gathered.
//     Extra points gathered do no harm.
// With at most three distinct positions, step 1 sees them all and is exact by itself.
// Random queries almost never reach step 3 (the relative gap K3 - k2 is ~1/N, not ~1e-12).
#include <CGAL/Fuzzy_sphere.h>
#include <CGAL/Kd_tree.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Search_traits_adapter.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/property_map.h>
#include <boost/iterator/function_output_iterator.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "core/contact/detail.hpp"

namespace asperity::detail {
namespace {

constexpr std::uint32_t kNoTwin = std::numeric_limits<std::uint32_t>::max();

/// The centres at one distinct position: the smallest index and the second smallest (or none).
struct Tag {
  std::uint32_t index;
  std::uint32_t twin;
};

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Item = std::pair<Point, Tag>;  // 32 bytes, like a bare (Point_3, uint32) pair
using ItemMap = CGAL::First_of_pair_property_map<Item>;
using BaseTraits = CGAL::Search_traits_3<Kernel>;
using Traits = CGAL::Search_traits_adapter<Item, ItemMap, BaseTraits>;
using Distance = CGAL::Distance_adapter<Item, ItemMap, CGAL::Euclidean_distance<BaseTraits>>;
using Splitter = CGAL::Sliding_midpoint<Traits>;
// Extended nodes (tighter bounds), no points cache (coordinates are already inline in Item).
using Tree = CGAL::Kd_tree<Traits, Splitter, CGAL::Tag_true, CGAL::Tag_false>;
using Knn = CGAL::Orthogonal_k_neighbor_search<Traits, Distance, Splitter, Tree>;
using Ball = CGAL::Fuzzy_sphere<Traits>;

// Leaf size: CGAL's default; 10-16 measured within noise of each other at N = 1e6.
constexpr unsigned kBucket = 10;

inline Vec3 to_vec(const Point& p) { return {p.x(), p.y(), p.z()}; }

inline void offer(TopTwo& top, const Item& it, const Vec3& d) {
  // The tree's coordinates are bit-exact copies of the caller's centres: canonical keys.
  const double k = contact_key(to_vec(it.first), d);
  top.offer(it.second.index, k);
  if (it.second.twin != kNoTwin) top.offer(it.second.twin, k);
}

// Output-iterator sink of the range search (assignable, unlike a capturing lambda).
struct Offer {
  TopTwo* top;
  const Vec3* d;
  void operator()(const Item& it) const { offer(*top, it, *d); }
};

/// One item per distinct position (exact coordinate equality; -0 == +0, which have equal keys).
std::vector<Item> distinct_positions(std::span<const Vec3> c) {
  std::vector<Item> all;
  all.reserve(c.size());
  for (std::uint32_t i = 0; i < c.size(); ++i)
    all.emplace_back(Point(c[i].x(), c[i].y(), c[i].z()), Tag{i, kNoTwin});
  auto same = [](const Item& a, const Item& b) {
    return a.first.x() == b.first.x() && a.first.y() == b.first.y() && a.first.z() == b.first.z();
  };
  std::sort(all.begin(), all.end(), [](const Item& a, const Item& b) {
    if (a.first.x() != b.first.x()) return a.first.x() < b.first.x();
    if (a.first.y() != b.first.y()) return a.first.y() < b.first.y();
    if (a.first.z() != b.first.z()) return a.first.z() < b.first.z();
    return a.second.index < b.second.index;
  });
  std::size_t out = 0;
  for (std::size_t i = 0; i < all.size();) {
    std::size_t j = i + 1;
    while (j < all.size() && same(all[i], all[j])) ++j;
    Item it = all[i];
    if (j - i > 1) it.second.twin = all[i + 1].second.index;
    all[out++] = it;
    i = j;
  }
  all.resize(out);
  return all;
}

class CgalKdTree final : public ContactQuery {
 public:
  explicit CgalKdTree(std::span<const Vec3> c) : tree_(Splitter(kBucket)) {
    std::vector<Item> items = distinct_positions(c);
    distinct_ = items.size();
    tree_.insert(items.begin(), items.end());
    tree_.build();  // never lazily from a query thread
    leaves_ = tree_.root()->num_nodes();
  }

  Backend backend() const override { return Backend::cgal; }
  using ContactQuery::lowest;

  Nearest lowest(const Vec3& d) const override {
    const Point q(d.x(), d.y(), d.z());
    TopTwo top;
    double k3 = 0;  // largest key among the (up to) three positions found
    {
      Knn search(tree_, q, 3, 0.0, true, Distance(), /*sorted=*/false);
      for (auto it = search.begin(); it != search.end(); ++it) {
        offer(top, it->first, d);
        k3 = std::max(k3, contact_key(to_vec(it->first.first), d));
      }
    }
    if (distinct_ <= 3) return top.result();  // every position was offered
    const double k2 = top.second_key();
    if (k3 >= kMinCertainKey && k3 - k2 > kTieTolerance * k3) return top.result();

    // Near-tie at the runner-up: gather everything that could tie or beat it.
    const double r = std::sqrt(k2 * (1.0 + 4.0 * kTieTolerance) + 1e-300);
    TopTwo all;
    tree_.search(boost::make_function_output_iterator(Offer{&all, &d}), Ball(q, r, 0.0));
    return all.result();
  }

  std::size_t memory_bytes() const override {
    // Items (one per distinct position), leaves and internal nodes (a binary tree: leaves - 1),
    // and the root bounding box.
    return distinct_ * sizeof(Item) + leaves_ * sizeof(Tree::Leaf_node) +
           (leaves_ - 1) * sizeof(Tree::Internal_node) +
           sizeof(CGAL::Kd_tree_rectangle<double, CGAL::Dimension_tag<3>>);
  }

 private:
  // Keys below this may have lost relative precision to underflow: no shortcut there.
  static constexpr double kMinCertainKey = 1e-290;

  Tree tree_;
  std::size_t distinct_ = 0;
  std::size_t leaves_ = 0;
};

}  // namespace

std::unique_ptr<ContactQuery> make_cgal(std::span<const Vec3> centres) {
  return std::make_unique<CgalKdTree>(centres);
}

}  // namespace asperity::detail
