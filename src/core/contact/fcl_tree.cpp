// SPDX-License-Identifier: GPL-3.0-or-later
// FCL 0.7 backend (a baseline): the asperity centres as tiny spheres in a dynamic AABB tree,
// queried by a broad-phase distance traversal with our own callback.
//
// Design. One fcl::CollisionObjectd per asperity, all sharing one small Sphere geometry, placed
// at the unit centre u_i with the index in the user data, registered in a
// DynamicAABBTreeCollisionManager (registerObjects on an empty manager builds the tree top-down;
// setup() is then a no-op but called anyway). A query places a tiny sphere at d and runs
// manager.distance(&query, &state, callback). FCL's narrowphase (fcl::distance) is never called:
// the callback recomputes the canonical contact_key of the offered object, feeds a TopTwo, and
// returns the pruning bound. So FCL's overlap trap (distance <= 0 reported for overlapping
// spheres, and the default callback stopping at the first such) cannot occur, and nothing
// forces the query point off the surface: it sits at p = d (s = 1), where the centre distance
// is |u - d| = sqrt(contact_key) and the bound is tightest.
//
// Pruning (read in include/fcl/broadphase/broadphase_dynamic_AABB_tree-inl.h, FCL 0.7):
//   distanceRecurse(node, query, cdata, callback, min_dist): a leaf calls
//   callback(leaf_object, query, cdata, min_dist) and stops the WHOLE search iff it returns true;
//   an internal node computes d_i = query->getAABB().distance(child_i->bv) for both children and
//   descends into child i only if d_i < min_dist (strict), re-reading min_dist before the second
//   child. min_dist starts at numeric_limits<double>::max() and is only ever changed by the
//   callback. The manager never stops on min_dist <= 0 by itself (that is the default callback,
//   which we do not use); but min_dist = 0 would prune everything, since no d_i is < 0.
// Bound. Every box in the tree contains its objects' centres (fl(u - r) <= u <= fl(u + r) for
// r >= 0; parents are exact min/max unions), and the query box contains d. Each per-axis gap of
// the AABB distance is then at most |u_k - d_k| (times 1 + 2^-53), so the computed AABB distance
// of any node holding u is <= |u - d| (1 + 4 * 2^-53) <= sqrt(key(u)) (1 + 1e-15). We return
// min_dist = sqrt(k2) (1 + 1e-9) + 1e-150 for the current runner-up key k2: a node holding a
// point that ties or beats the runner-up (key <= k2) always has d_i < min_dist and is visited;
// the absolute 1e-150 keeps the bound positive when k2 == 0 (a query on duplicated centres)
// and covers coordinate differences that underflow when squared. k2 only decreases, so the
// final top two are never pruned at any earlier moment. The sphere radii never enter the bound
// (subtracting them would be sharper by 2r but could drive min_dist to 0 on overlaps); they
// only inflate the boxes, so they are kept far below the asperity spacing.
//
// Threads. DynamicAABBTreeCollisionManager::distance(obj, cdata, cb) is const and its recursion
// only reads the tree (nodes, boxes, leaf data); it keeps no per-call state in the manager (the
// mutable tested_set of the base class is used only by SaP and interval-tree managers). So
// concurrent queries are safe. But CollisionObject's constructor calls
// geometry->computeLocalAABB(), which WRITES to the geometry: the query object therefore gets
// its own Sphere on the caller's stack, wrapped in a non-owning shared_ptr (aliasing
// constructor with an empty owner: no allocation, no shared reference count).
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision_object.h>

#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <vector>

#include "core/contact/detail.hpp"

namespace asperity::detail {
namespace {

// Box half-width of every asperity object and of the query object, in unit-sphere units.
// Irrelevant to exactness (see above); 1e-9 is ~1e-6 of the spacing at N = 1e7.
constexpr double kRadius = 1e-9;

struct QueryState {
  const fcl::CollisionObjectd* query;
  Vec3 d;
  TopTwo top;
};

bool offer(fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data, double& min_dist) {
  auto& s = *static_cast<QueryState*>(data);
  const fcl::CollisionObjectd* obj = a == s.query ? b : a;
  const auto i = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(obj->getUserData()));
  // The object's translation is a bit-exact copy of centres[i] (and already in cache).
  s.top.offer(i, contact_key(obj->getTranslation(), s.d));
  const double k2 = s.top.second_key();
  if (k2 != std::numeric_limits<double>::infinity()) min_dist = std::sqrt(k2) * (1.0 + 1e-9) + 1e-150;
  return false;  // never stop early
}

class FclTree final : public ContactQuery {
 public:
  explicit FclTree(std::span<const Vec3> c) : geom_(std::make_shared<fcl::Sphered>(kRadius)) {
    std::vector<fcl::CollisionObjectd*> ptrs;
    ptrs.reserve(c.size());
    for (std::uint32_t i = 0; i < c.size(); ++i) {
      fcl::Transform3d tf = fcl::Transform3d::Identity();
      tf.translation() = c[i];
      auto& o = objects_.emplace_back(geom_, tf);  // deque: addresses stay put
      o.setUserData(reinterpret_cast<void*>(static_cast<std::uintptr_t>(i)));
      ptrs.push_back(&o);
    }
    manager_.registerObjects(ptrs);
    manager_.setup();
  }

  Backend backend() const override { return Backend::fcl; }
  using ContactQuery::lowest;

  Nearest lowest(const Vec3& d) const override {
    fcl::Sphered g(kRadius);  // per call: the object constructor writes to its geometry
    const std::shared_ptr<fcl::CollisionGeometryd> gp(std::shared_ptr<void>(), &g);
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.translation() = d;
    fcl::CollisionObjectd q(gp, tf);
    QueryState s{&q, d, {}};
    manager_.distance(&q, &s, &offer);
    return s.top.result();
  }

  std::size_t memory_bytes() const override {
    const std::size_t n = objects_.size();
    using Node = fcl::DynamicAABBTreeCollisionManagerd::DynamicAABBNode;
    // glibc malloc chunk of an individually allocated block: size + 8-byte header, 16-aligned.
    constexpr auto chunk = [](std::size_t b) { return (b + 8 + 15) / 16 * 16; };
    // Objects (in deque blocks), 2n-1 individually allocated tree nodes, and the manager's
    // object->leaf hash table (a node of next pointer + key + value, one bucket pointer each).
    return n * sizeof(fcl::CollisionObjectd) + (2 * n - 1) * chunk(sizeof(Node)) +
           n * (chunk(3 * sizeof(void*)) + sizeof(void*)) + sizeof(fcl::Sphered);
  }

 private:
  std::shared_ptr<fcl::Sphered> geom_;
  std::deque<fcl::CollisionObjectd> objects_;
  fcl::DynamicAABBTreeCollisionManagerd manager_;
};

}  // namespace

std::unique_ptr<ContactQuery> make_fcl(std::span<const Vec3> centres) {
  return std::make_unique<FclTree>(centres);
}

}  // namespace asperity::detail
