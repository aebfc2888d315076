// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Which asperity touches the plate: one query interface over interchangeable spatial structures.
//
// With all centres on the central sphere and equal asperity radii, the asperity that touches
// first is the one whose centre is lowest, i.e. that maximises u.d for the body-frame down
// direction d -- equivalently the centre nearest to d (smallest contact_key = |u - d|^2).
// Every backend answers exactly this question and must agree bit-for-bit with `brute`:
// the same lowest index (ties -> lowest index) and the same runner-up key.
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "asperity/core/geometry.hpp"
#include "asperity/core/orientation.hpp"

namespace asperity {

/// The two lowest asperities for one down direction.
struct Nearest {
  std::uint32_t index = 0;         ///< lowest asperity (ties -> lowest index)
  double key = 0;                  ///< its contact_key |u - d|^2
  std::uint32_t runner_up = 0;     ///< second lowest (== index when N == 1)
  double runner_up_key = 0;        ///< its contact_key (+inf when N == 1)

  /// Bit-for-bit equality: how the backends are checked against brute_lowest.
  friend bool operator==(const Nearest&, const Nearest&) = default;
};

/// Strict canonical order of candidates: by key, then by index.
inline bool key_less(double ka, std::uint32_t ia, double kb, std::uint32_t ib) noexcept {
  return ka < kb || (ka == kb && ia < ib);
}

/// The spatial structure behind a ContactQuery. Every backend gives the same answers bit for bit;
/// they differ in build time, memory and query speed (bench/ measures them).
enum class Backend {
  brute,   ///< linear scan over all centres (the reference)
  kdtree,  ///< nanoflann kd-tree
  cgal,    ///< CGAL's kd-tree (Spatial_searching)
  fcl,     ///< FCL's dynamic AABB tree, a baseline (only when built with ASPERITY_WITH_FCL)
  grid     ///< cube-map grid: centres bucketed on the six faces of a cube (gnomonic projection)
};

/// The name parse_backend reads: "brute", "kdtree", "cgal", "fcl" or "grid".
std::string_view to_string(Backend b);
/// Parses "brute", "kdtree" (nanoflann), "cgal" (CGAL kd-tree), "fcl", "grid".
/// Throws std::invalid_argument naming the value otherwise.
Backend parse_backend(std::string_view name);
/// All backends built into this library (fcl only with ASPERITY_WITH_FCL), reference first.
std::span<const Backend> all_backends();

/// A spatial index over the unit centres of one body. Immutable after construction, so `lowest`
/// may be called concurrently from any number of threads.
class ContactQuery {
 public:
  virtual ~ContactQuery() = default;
  /// Which structure this is.
  virtual Backend backend() const = 0;
  /// The two lowest asperities for the unit body-frame down direction d.
  virtual Nearest lowest(const Vec3& d) const = 0;
  /// Many queries at once; backends may overlap their memory latency across the batch.
  virtual void lowest(std::span<const Vec3> d, std::span<Nearest> out) const;
  /// The lowest asperity only, for many queries (streaming statistics need no runner-up):
  /// out[i].index and out[i].key are lowest(d[i])'s bit for bit; the runner-up is not computed,
  /// out[i].runner_up = out[i].index and out[i].runner_up_key = +inf, whichever backend answers.
  /// A backend may certify the winner alone, which is cheaper than certifying the runner-up.
  virtual void lowest_winners(std::span<const Vec3> d, std::span<Nearest> out) const;
  /// Bytes held by the index, beyond the caller's centres.
  virtual std::size_t memory_bytes() const = 0;
};

/// Builds the index of `backend` over `centres` (unit vectors). The span must outlive the index.
std::unique_ptr<ContactQuery> make_contact_query(Backend backend, std::span<const Vec3> centres);

/// Reference scan: the two smallest (key, index) pairs over all centres.
Nearest brute_lowest(std::span<const Vec3> centres, const Vec3& d);

/// A full answer reduced to what lowest_winners reports: the winner, no runner-up (+inf).
inline Nearest winner_only(const Nearest& n) noexcept {
  return Nearest{n.index, n.key, n.index, std::numeric_limits<double>::infinity()};
}

/// The physical contact of a body with the plate, in the WORLD frame (z up, plate below).
struct Contact {
  std::uint32_t index = 0;  ///< lowest asperity
  Vec3 r{0, 0, 0};          ///< contact vector from the body centre to the contact point [m]
  double r_xy = 0;          ///< |(r_x, r_y)| of the lowest asperity's contact point [m]
  double gap = 0;           ///< height of the runner-up's lowest point above the lowest one's [m]
  bool core = false;        ///< the bare central sphere reaches the plate before any asperity
};

/// True when the central sphere touches before an asperity whose centre has key k:
/// R (1 - u.d) > a  <=>  R k / 2 > a.
inline bool core_touches_first(double key, double R, double a) noexcept { return 0.5 * R * key > a; }

/// Turns a query answer into the world-frame contact of a body rotated by q, radius R, asperity
/// radius a. r is the lowest asperity's contact point, even when `core` is set (then the central
/// sphere's south pole, (0,0,-R), touches first; the caller decides what to do with that).
/// Inline: per drop of the streaming path, where the compiler shares body_down(q) with the query.
inline Contact make_contact(const Nearest& n, const Vec3& u, const Rotation& q, double R, double a) {
  Contact c;
  c.index = n.index;
  const Vec3 d = body_down(q);
  // World position of the centre; the contact point is a further a straight down.
  const Vec3 centre = q * (R * u);
  // Height of the centre below the body centre: R u.d = R (1 - key/2), exact near the pole.
  const double depth = R * (1.0 - 0.5 * n.key);
  c.r = Vec3(centre.x(), centre.y(), -(depth + a));
  // |u x d| is sin(theta) without the cancellation of sqrt(1 - cos^2).
  c.r_xy = R * u.cross(d).norm();
  c.gap = std::isfinite(n.runner_up_key) ? 0.5 * R * (n.runner_up_key - n.key) : std::numeric_limits<double>::infinity();
  c.core = core_touches_first(n.key, R, a);
  return c;
}

}  // namespace asperity
