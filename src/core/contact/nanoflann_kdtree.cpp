// SPDX-License-Identifier: GPL-3.0-or-later
// kd-tree backend on nanoflann (Debian's 1.4.3, old API: squared distances, SearchParams).
//
// Exactness: instead of nanoflann's KNN result set (which breaks ties by traversal order) we pass
// our own result set that recomputes the canonical contact_key of every offered point and keeps
// the canonical top two. Its pruning radius is the runner-up key inflated by kTieTolerance, so a
// subtree is skipped only when its lower bound exceeds the runner-up by far more than the rounding
// of nanoflann's incremental box distances: tied points are always offered.
#include <nanoflann.hpp>

#include <limits>

#include "core/contact/detail.hpp"

namespace asperity::detail {
namespace {

struct Cloud {
  std::span<const Vec3> c;
  std::size_t kdtree_get_point_count() const { return c.size(); }
  double kdtree_get_pt(std::uint32_t i, std::size_t dim) const { return c[i][static_cast<Eigen::Index>(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const { return false; }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud, double, std::uint32_t>,
                                                 Cloud, 3, std::uint32_t>;

class CanonicalTopTwo {
 public:
  using DistanceType = double;
  using IndexType = std::uint32_t;
  CanonicalTopTwo(std::span<const Vec3> c, const Vec3& d) : c_(c), d_(d) {}
  std::size_t size() const { return 2; }
  bool full() const { return true; }
  bool addPoint(double, std::uint32_t i) {
    top_.offer(c_, d_, i);
    const double k2 = top_.second_key();
    worst_ = k2 == std::numeric_limits<double>::infinity() ? k2 : k2 * (1.0 + kTieTolerance) + 1e-300;
    return true;
  }
  double worstDist() const { return worst_; }
  Nearest result() const { return top_.result(); }

 private:
  std::span<const Vec3> c_;
  const Vec3& d_;
  TopTwo top_;
  double worst_ = std::numeric_limits<double>::max();
};

class NanoflannKdTree final : public ContactQuery {
 public:
  // Leaf size 16: measured best between 10 and 20 (see ../shared/PACKAGE-NOTES.md).
  explicit NanoflannKdTree(std::span<const Vec3> c)
      : cloud_{c}, tree_(3, cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
    tree_.buildIndex();
  }
  Backend backend() const override { return Backend::kdtree; }
  Nearest lowest(const Vec3& d) const override {
    CanonicalTopTwo rs(cloud_.c, d);
    tree_.findNeighbors(rs, d.data(), nanoflann::SearchParams());
    return rs.result();
  }
  using ContactQuery::lowest;
  std::size_t memory_bytes() const override {
    auto& t = const_cast<Tree&>(tree_);  // nanoflann 1.4 lacks a const usedMemory
    return t.usedMemory(t);
  }

 private:
  Cloud cloud_;
  Tree tree_;
};

}  // namespace

std::unique_ptr<ContactQuery> make_nanoflann(std::span<const Vec3> centres) {
  return std::make_unique<NanoflannKdTree>(centres);
}

}  // namespace asperity::detail
