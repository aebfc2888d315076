// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Which asperity of a general rough body (body.hpp) touches the plate: the exact support query.
//
// For the body-frame down direction d (unit), the lowest point of the union of asperity balls is
// the support point of its convex hull: asperity i reaches h_i = c_i . d + rho_i below the centre
// of mass, and the touching asperity maximises h_i, touching at c_i + rho_i d. With unequal radii
// this is no nearest-centre query (the reduction used by contact.hpp needs equal radii).
//
// Exactness: h_i is ONE fixed expression (support_value; the library is built without FMA
// contraction) and every structure returns bit-for-bit what brute_support returns: the largest
// (h, then lowest index) and the runner-up.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "asperity/core/body.hpp"
#include "asperity/core/geometry.hpp"
#include "asperity/core/orientation.hpp"

namespace asperity {

/// h = c . d + rho, evaluated left to right, always the same way [m].
inline double support_value(const Vec3& c, double rho, const Vec3& d) noexcept {
  return ((c.x() * d.x() + c.y() * d.y()) + c.z() * d.z()) + rho;
}

/// Strict canonical order: larger h first, ties -> lower index.
inline bool support_better(double ha, std::uint32_t ia, double hb, std::uint32_t ib) noexcept {
  return ha > hb || (ha == hb && ia < ib);
}

/// The two lowest asperities (largest h) for one direction.
struct Support {
  std::uint32_t index = 0;       ///< touching asperity (ties -> lowest index)
  double h = 0;                  ///< its support value [m]
  std::uint32_t runner_up = 0;   ///< second (== index when N == 1)
  double runner_up_h = 0;        ///< its support value (-inf when N == 1) [m]

  /// Bit-for-bit equality: how the structures are checked against brute_support.
  friend bool operator==(const Support&, const Support&) = default;
};

/// Reference linear scan.
Support brute_support(std::span<const Vec3> centres, std::span<const double> radii, const Vec3& d);

/// An exact support index over one body's asperities. Immutable: `support` may be called from
/// any number of threads. The spans passed at construction must outlive it.
class SupportQuery {
 public:
  virtual ~SupportQuery() = default;
  /// The two lowest asperities (largest h) for the unit body-frame down direction d, bit for bit
  /// as brute_support.
  virtual Support support(const Vec3& d) const = 0;
  /// Indices i with |c_i - p| <= radius (any order; ascending index), exact for the computed distance.
  virtual std::vector<std::uint32_t> within(const Vec3& p, double radius) const = 0;
  /// Bytes held by the index, beyond the caller's centres and radii.
  virtual std::size_t memory_bytes() const = 0;
};

/// A bounding-volume hierarchy (median-split kd tree over the centres, a box and the largest
/// radius per node) searched best-first with support-function bounds
/// max_{c in box} c.d + max rho, padded by a rounding margin so that no node that could hold the
/// brute-force answer is ever pruned. O(log N) typical per query for bodies with smooth surfaces.
std::unique_ptr<SupportQuery> make_support_tree(std::span<const Vec3> centres, std::span<const double> radii);

/// The physical contact of a rough body rotated by q (body -> world), plate below (world z up).
struct BodyContact {
  std::uint32_t index = 0;  ///< touching asperity
  Vec3 r{0, 0, 0};          ///< contact point minus centre of mass, world frame [m]
  double gap = 0;           ///< h - runner_up_h: how much higher the runner-up's lowest point is [m]
};

/// World-frame contact from a support answer for d = body_down(q).
BodyContact make_body_contact(const Support& s, const RoughBody& b, const Rotation& q);

}  // namespace asperity
