// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/core/lazy_sphere.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>
#include <string>

#include "asperity/core/random.hpp"
#include "core/contact/detail.hpp"

namespace asperity {

namespace {

// sqrt(1 - z^2) for z in [-1, 1], as the bound always computed it.
inline double rim(double z) { return std::sqrt(std::max(0.0, (1 - z) * (1 + z))); }

// Bits set in x. The baseline x86-64 target has no popcnt instruction, where std::popcount is a
// libgcc call per word; this is inline.
inline std::uint64_t popcount64(std::uint64_t x) {
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return (x * 0x0101010101010101ull) >> 56;
}

double mode_pmf(std::uint64_t n) {
  const double dn = static_cast<double>(n), km = static_cast<double>(n / 2);
  return std::exp(std::lgamma(dn + 1) - std::lgamma(km + 1) - std::lgamma(dn - km + 1) - dn * std::numbers::ln2);
}

// Inversion in the order mode, mode+1, mode-1, mode+2, ... (any fixed order of the support is a
// valid inversion); the pmf ratios are exact rationals. u = U - pmf(mode) >= 0 on entry.
std::uint64_t walk_from_mode(std::uint64_t n, double p_mode, double u) {
  const std::uint64_t mode = n / 2;
  double p_up = p_mode, p_dn = p_mode;
  std::uint64_t up = mode, dn_k = mode;
  // While both sides are open, each step's two ratios (n - up)/(up + 1) and dn/(n - dn + 1) come
  // from one two-lane division (lane-wise IEEE, the same quotients as two scalar divisions; the
  // divisions were the walk's cost). Numerators and denominators are integers < 2^53, kept as
  // doubles and stepped by 1 exactly. Every other operation is the scalar loop's, in its order.
  using v2 = double __attribute__((vector_size(16)));
  v2 num = {static_cast<double>(n - up), static_cast<double>(dn_k)};
  v2 den = {static_cast<double>(up + 1), static_cast<double>(n - dn_k + 1)};
  const v2 one = {1.0, 1.0};
  while (up < n && dn_k > 0) {
    const v2 q = num / den;
    num -= one, den += one;
    p_up *= q[0];
    ++up;
    u -= p_up;
    if (u < 0) return up;
    p_dn *= q[1];
    --dn_k;
    u -= p_dn;
    if (u < 0) return dn_k;
    if (p_up < 1e-300 && p_dn < 1e-300) return mode;
  }
  while (up < n || dn_k > 0) {  // one side closed (small n): the plain loop
    if (up < n) {
      p_up *= static_cast<double>(n - up) / static_cast<double>(up + 1);
      ++up;
      u -= p_up;
      if (u < 0) return up;
    }
    if (dn_k > 0) {
      p_dn *= static_cast<double>(dn_k) / static_cast<double>(n - dn_k + 1);
      --dn_k;
      u -= p_dn;
      if (u < 0) return dn_k;
    }
    if (p_up < 1e-300 && p_dn < 1e-300) break;
  }
  return mode;  // u left over by rounding (probability ~1e-16)
}

}  // namespace

double BinomialModeCache::operator()(std::uint64_t n) {
  if (n >= p_.size()) return mode_pmf(n);
  double p = p_[n].load(std::memory_order_relaxed);
  if (p == 0) p_[n].store(p = mode_pmf(n), std::memory_order_relaxed);
  return p;
}

std::uint64_t binomial_half(std::uint64_t n, Stream& s, BinomialModeCache* cache) {
  if (n <= 512) {
    std::uint64_t k = 0, left = n;
    while (left >= 64) k += popcount64(s.bits()), left -= 64;
    if (left) k += popcount64(s.bits() & ((std::uint64_t{1} << left) - 1));
    return k;
  }
  const double p_mode = cache ? (*cache)(n) : mode_pmf(n);
  const double u = s.uniform0() - p_mode;
  return u < 0 ? n / 2 : walk_from_mode(n, p_mode, u);
}

LazySphere::LazySphere(std::uint64_t n, std::uint64_t seed, std::uint64_t sphere_id, unsigned leaf_size,
                       BinomialModeCache* modes)
    : n_(n), seed_(seed), sphere_(sphere_id), leaf_size_(std::max(1u, leaf_size)), modes_(modes) {
  check_asperity_count(n, "lazy sphere: asperities");
  z_edges_.resize(kEdgeTable), phi_edges_.resize(kEdgeTable);
  reset(seed, sphere_id);
}

void LazySphere::reset(std::uint64_t seed, std::uint64_t sphere_id) {
  seed_ = seed, sphere_ = sphere_id;
  nodes_.clear();
  points_.clear();
  const double two_pi = 2.0 * std::numbers::pi;
  nodes_.push_back(Node{-1.0, 1.0, 0.0, two_pi, std::acos(-1.0), std::acos(1.0), 1.0, 0.0, std::cos(two_pi), std::sin(two_pi),
                        0.0, 0.0, 1, n_, 0});
}

void LazySphere::expand(std::size_t i) {
  // The children are copied whole from the parent into nodes_ and their fields set there: built
  // as locals and pushed, their field-by-field stores were read back as 16-byte moves, a store-
  // forwarding stall per move.
  const std::size_t first = nodes_.size();
  nodes_[i].child = static_cast<std::int64_t>(first);
  nodes_.push_back(nodes_[i]);
  nodes_.push_back(nodes_[i]);
  const Node& c = nodes_[i];
  Node& a = nodes_[first];
  Node& b = nodes_[first + 1];
  Stream s(seed_, Purpose::lazy_sphere, sphere_, 2 * c.id);
  const std::uint64_t left = binomial_half(c.count, s, modes_);
  // Split the longer side (arc lengths) at its equal-area midpoint.
  const double dtheta = c.t0 - c.t1;  // acos(z0) - acos(z1)
  const double smax = std::max(c.r0, c.r1);
  const double width = (c.p1 - c.p0) * ((c.z0 <= 0 && c.z1 >= 0) ? 1.0 : smax);  // along the widest circle
  if (width > dtheta) {
    const double pm = 0.5 * (c.p0 + c.p1);
    a.p1 = pm, b.p0 = pm;
    EdgePair e;
    if (c.pk < kEdgeTable && !std::isnan(phi_edges_[c.pk].first)) e = phi_edges_[c.pk];
    else e = {std::cos(pm), std::sin(pm)};
    if (c.pk < kEdgeTable) phi_edges_[c.pk] = e;
    a.c1 = b.c0 = e.first, a.s1 = b.s0 = e.second;
    a.pk = 2 * c.pk, b.pk = 2 * c.pk + 1;
  } else {
    const double zm = 0.5 * (c.z0 + c.z1);
    a.z1 = zm, b.z0 = zm;
    EdgePair e;
    if (c.zk < kEdgeTable && !std::isnan(z_edges_[c.zk].first)) e = z_edges_[c.zk];
    else e = {std::acos(std::clamp(zm, -1.0, 1.0)), rim(zm)};
    if (c.zk < kEdgeTable) z_edges_[c.zk] = e;
    a.t1 = b.t0 = e.first;
    a.r1 = b.r0 = e.second;
    a.zk = 2 * c.zk, b.zk = 2 * c.zk + 1;
  }
  a.id = 2 * c.id, b.id = 2 * c.id + 1;
  a.count = left, b.count = c.count - left;
  a.offset = c.offset, b.offset = c.offset + left;
  a.child = b.child = a.points = b.points = -1;
}

void LazySphere::fill(std::size_t i) {
  const Node& c = nodes_[i];
  Stream s(seed_, Purpose::lazy_sphere, sphere_, 2 * c.id + 1);
  nodes_[i].points = static_cast<std::int64_t>(points_.size());
  // Drawn now (the stream's order), converted to Cartesian when a query needs them (centre()).
  for (std::uint64_t j = 0; j < c.count; ++j) {
    const double z = c.z0 + (c.z1 - c.z0) * s.uniform0();
    const double phi = c.p0 + (c.p1 - c.p0) * s.uniform0();
    points_.emplace_back(kDeferred, z, phi);
  }
}

const Vec3& LazySphere::centre(std::size_t p) {
  Vec3& u = points_[p];
  if (std::isnan(u.x())) {
    const double z = u.y(), phi = u.z(), r = rim(z);
    u = Vec3(r * std::cos(phi), r * std::sin(phi), z);
  }
  return u;
}

double LazySphere::deferred_lower_key(const Vec3& zphi, const Direction& q) {
  // u.d = s(z) dxy cos(phi - psi) + z dz with s, dxy >= 0, and cos x <= 1 - x^2/2 + x^4/24 for
  // every real x (the difference is even, 0 at 0 and increasing for x > 0, as sin x >= x - x^3/6),
  // so no cos or sin is needed to bound the key. x = phi - psi is reduced to (-pi, pi] only to
  // keep the bound tight; its rounding (~1e-15) and the point's own (as in lower_key) are far
  // inside the 1e-13 margin.
  constexpr double pi = std::numbers::pi;
  const double z = zphi.y();
  double x = zphi.z() - q.psi;  // in (-pi, 3 pi)
  if (x > pi) x -= 2.0 * pi;
  const double x2 = x * x;
  const double cub = std::min(1.0, 1.0 - x2 * (0.5 - x2 * (1.0 / 24.0)));
  return 2.0 - 2.0 * (rim(z) * q.dxy * cub + z * q.d.z()) - 1e-13;
}

double LazySphere::lower_key(const Node& c, const Direction& q) {
  // max over the cell of u.d = s(z) dxy cos(phi - psi) + z dz, s = sqrt(1 - z^2) >= 0.
  // psi in [-pi, pi], p0 in [0, 2 pi): psi - p0 > -3 pi, so two shifts by 2 pi bring it to [0, 2 pi)
  // (rounding near the cell's edge only swaps cmax = 1 for a cosine within 1e-16 of it, inside
  // the margin, as are the products of cached cosines and sines).
  constexpr double two_pi = 2.0 * std::numbers::pi;
  double cmax;
  const double span = c.p1 - c.p0;
  double delta = q.psi - c.p0;
  if (delta < 0) delta += two_pi;
  if (delta < 0) delta += two_pi;
  if (delta <= span) cmax = 1.0;
  else cmax = std::max(c.c0 * q.cpsi + c.s0 * q.spsi, c.c1 * q.cpsi + c.s1 * q.spsi);  // cos(p - psi)
  const double A = q.dxy * cmax, dz = q.d.z();
  const double f0 = A * c.r0 + dz * c.z0, f1 = A * c.r1 + dz * c.z1;  // f(z) = A sqrt(1 - z^2) + dz z
  double ub;
  if (A > 0) {
    // |(A, dz)| <= 1: no overflow, so sqrt instead of the much slower std::hypot (its last-ulp
    // accuracy is far inside the 1e-13 margin).
    // The concave f peaks at zs = dz / norm with f(zs) = norm; compared as dz against z norm (no
    // division), the peak inside the cell bounds it by norm itself, else the nearer end does.
    const double norm = std::sqrt(A * A + dz * dz);
    ub = dz < c.z0 * norm ? f0 : dz > c.z1 * norm ? f1 : norm;
  } else {
    ub = std::max(f0, f1);  // convex: maximum at an end
  }
  return 2.0 - 2.0 * ub - 1e-13;
}

LazyNearest LazySphere::lowest(const Vec3& d) {
  Direction q;
  q.d = d;
  q.dxy = std::hypot(d.x(), d.y());
  q.psi = std::atan2(d.y(), d.x());
  q.cpsi = q.dxy > 0 ? d.x() / q.dxy : 1.0, q.spsi = q.dxy > 0 ? d.y() / q.dxy : 0.0;
  detail::TopTwo top;
  std::size_t winner = 0;  // points_ index of top's first (no descent to its leaf afterwards)
  auto& h = heap_;
  h.clear();
  // Cells are visited in increasing (bound, cell index), as a heap of every open cell pops them;
  // the better child of an expanded cell is kept in hand instead of pushed and popped again when
  // it comes before the heap's top (the same order, half the heap operations).
  using Open = std::pair<double, std::size_t>;
  auto cmp = std::greater<Open>();
  Open cur{lower_key(nodes_[0], q), 0};
  for (bool in_hand = true;;) {
    if (!in_hand) {
      if (h.empty()) break;
      std::pop_heap(h.begin(), h.end(), cmp);
      cur = h.back();
      h.pop_back();
    }
    in_hand = false;
    const auto [lb, i] = cur;
    if (lb > top.second_key()) break;  // no open cell can hold a better candidate
    if (is_leaf(nodes_[i])) {
      if (nodes_[i].points < 0) fill(i);
      const Node& c = nodes_[i];
      for (std::uint64_t j = 0; j < c.count; ++j) {
        const std::size_t p = static_cast<std::size_t>(c.points) + j;
        // A centre not converted yet whose key cannot beat the runner-up would leave `top` as it
        // is (offer ignores keys above the second): it stays unconverted (no cos, sin, sqrt).
        if (std::isnan(points_[p].x()) && deferred_lower_key(points_[p], q) > top.second_key()) continue;
        const auto idx = static_cast<std::uint32_t>(c.offset + j);
        top.offer(idx, contact_key(centre(p), d));
        if (top.result().index == idx) winner = p;  // each centre is offered once per query
      }
      continue;
    }
    if (nodes_[i].child < 0) expand(i);
    const std::size_t ch = static_cast<std::size_t>(nodes_[i].child);
    // Bounds and cells of the kids as scalars: an array of pairs written field by field and read
    // back whole stalled on store forwarding (the pushes were ~14 % of the query's time).
    double kb[2];
    std::size_t ki[2];
    int m = 0;
    for (std::size_t k = ch; k < ch + 2; ++k) {
      if (nodes_[k].count == 0) continue;
      const double lk = lower_key(nodes_[k], q);
      if (lk > top.second_key()) continue;
      kb[m] = lk, ki[m] = k, ++m;
    }
    if (m == 2 && Open(kb[1], ki[1]) < Open(kb[0], ki[0])) std::swap(kb[0], kb[1]), std::swap(ki[0], ki[1]);
    if (m == 2) h.emplace_back(kb[1], ki[1]), std::push_heap(h.begin(), h.end(), cmp);
    if (m >= 1) {
      if (h.empty() || Open(kb[0], ki[0]) < h.front()) cur = Open(kb[0], ki[0]), in_hand = true;
      else h.emplace_back(kb[0], ki[0]), std::push_heap(h.begin(), h.end(), cmp);
    }
  }
  LazyNearest r;
  r.nearest = top.result();
  r.u = points_[winner];  // converted when it was offered
  return r;
}

std::vector<Vec3> LazySphere::materialise() {
  std::vector<Vec3> out;
  out.reserve(n_);
  // Depth-first, first child first: leaves in index order.
  std::vector<std::size_t> stack{0};
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    if (nodes_[i].count == 0) continue;
    if (is_leaf(nodes_[i])) {
      if (nodes_[i].points < 0) fill(i);
      const auto p = static_cast<std::size_t>(nodes_[i].points);
      for (std::uint64_t j = 0; j < nodes_[i].count; ++j) out.push_back(centre(p + j));
      continue;
    }
    if (nodes_[i].child < 0) expand(i);
    const auto ch = static_cast<std::size_t>(nodes_[i].child);
    stack.push_back(ch + 1);
    stack.push_back(ch);
  }
  return out;
}

}  // namespace asperity
