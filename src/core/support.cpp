// SPDX-License-Identifier: GPL-3.0-or-later
// Exact support queries over asperity balls: brute force and a bounding-volume hierarchy.
#include "asperity/core/support.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace asperity {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct TopTwo {
  std::uint32_t i1 = 0, i2 = 0;
  double h1 = -kInf, h2 = -kInf;
  bool any = false, two = false;
  void offer(std::uint32_t i, double h) {
    if (!any || support_better(h, i, h1, i1)) {
      if (any) {
        i2 = i1;
        h2 = h1;
        two = true;
      }
      i1 = i;
      h1 = h;
      any = true;
    } else if (!two || support_better(h, i, h2, i2)) {
      i2 = i;
      h2 = h;
      two = true;
    }
  }
  // A node whose padded bound is below the runner-up cannot change the answer.
  double threshold() const { return two ? h2 : -kInf; }
  Support result() const {
    Support s;
    s.index = i1;
    s.h = h1;
    s.runner_up = two ? i2 : i1;
    s.runner_up_h = two ? h2 : -kInf;
    return s;
  }
};

void check_spans(std::span<const Vec3> c, std::span<const double> r) {
  if (c.size() != r.size())
    throw std::invalid_argument("support query: " + std::to_string(c.size()) + " centres but " +
                                std::to_string(r.size()) + " radii");
  if (c.empty()) throw std::invalid_argument("support query: a body needs at least one asperity, got 0");
  check_asperity_count(c.size(), "support query: asperities");
}

class Tree final : public SupportQuery {
 public:
  Tree(std::span<const Vec3> c, std::span<const double> r) {
    check_spans(c, r);
    const auto n = static_cast<std::uint32_t>(c.size());
    std::vector<std::uint32_t> perm(n);
    std::iota(perm.begin(), perm.end(), 0u);
    double scale = 0;
    for (std::uint32_t i = 0; i < n; ++i)
      scale = std::max(scale, std::abs(c[i].x()) + std::abs(c[i].y()) + std::abs(c[i].z()) + std::abs(r[i]));
    // Each h_i and each bound is a sum of four terms of magnitude <= scale: rounding error
    // < 4 ulp(scale) ~ 9e-16 scale each. 1e-14 scale covers both with room to spare.
    margin_ = 1e-14 * scale;
    nodes_.reserve(2 * (n / kLeaf + 1));
    nodes_.push_back({});
    fill(c, r, perm, 0, 0, n);
    pts_.resize(n);
    for (std::uint32_t k = 0; k < n; ++k) pts_[k] = Pt{c[perm[k]], r[perm[k]], perm[k]};
  }

  Support support(const Vec3& d) const override {
    TopTwo t;
    // Depth-first, nearer (higher-bound) child first; bounds are recomputed for the pushed child.
    std::uint32_t stack[128];
    double bounds[128];
    int top = 0;
    stack[top] = 0;
    bounds[top++] = bound(nodes_[0], d);
    while (top > 0) {
      --top;
      if (bounds[top] < t.threshold()) continue;
      const Node& nd = nodes_[stack[top]];
      if (nd.left == 0) {
        for (std::uint32_t k = nd.begin; k < nd.end; ++k) t.offer(pts_[k].index, support_value(pts_[k].c, pts_[k].rho, d));
        continue;
      }
      const double bl = bound(nodes_[nd.left], d), br = bound(nodes_[nd.left + 1], d);
      // Push the worse child first so the better one is popped next.
      if (bl >= br) {
        stack[top] = nd.left + 1; bounds[top++] = br;
        stack[top] = nd.left; bounds[top++] = bl;
      } else {
        stack[top] = nd.left; bounds[top++] = bl;
        stack[top] = nd.left + 1; bounds[top++] = br;
      }
    }
    return t.result();
  }

  std::vector<std::uint32_t> within(const Vec3& p, double radius) const override {
    std::vector<std::uint32_t> out;
    const double r2 = radius * radius;
    std::uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& nd = nodes_[stack[--top]];
      double dist2 = 0;
      for (int k = 0; k < 3; ++k) {
        const double e = std::max({nd.lo[k] - p[k], 0.0, p[k] - nd.hi[k]});
        dist2 += e * e;
      }
      if (dist2 > r2 * (1 + 1e-12) + margin_ * margin_) continue;
      if (nd.left == 0) {
        for (std::uint32_t k = nd.begin; k < nd.end; ++k)
          if ((pts_[k].c - p).squaredNorm() <= r2) out.push_back(pts_[k].index);
        continue;
      }
      stack[top++] = nd.left;
      stack[top++] = nd.left + 1;
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  std::size_t memory_bytes() const override { return nodes_.capacity() * sizeof(Node) + pts_.capacity() * sizeof(Pt); }

 private:
  static constexpr std::uint32_t kLeaf = 8;
  struct Node {
    double lo[3], hi[3];
    double rho_max;
    Vec3 axis{0, 0, 1};        // cone of centre directions (valid when cone)
    double cphi = 1, sphi = 0; // cos, sin of its padded half-angle (< 90 degrees)
    double rmin = 0, rmax = 0; // range of |c| [m], padded
    bool cone = false;
    std::uint32_t begin, end;
    std::uint32_t left = 0;  // children at left, left+1; 0 = leaf (the root is never a child)
  };
  struct Pt {
    Vec3 c;
    double rho;
    std::uint32_t index;
  };

  double bound(const Node& nd, const Vec3& d) const {
    double s = 0;
    for (int k = 0; k < 3; ++k) s += std::max(nd.lo[k] * d[k], nd.hi[k] * d[k]);
    if (nd.cone) {
      // Every centre direction u lies within angle phi of the axis a, so for theta = angle(a, d)
      // u.d <= cos(max(0, theta - phi)) = cos(theta) cos(phi) + sin(theta) sin(phi) when theta > phi.
      // A box around a tilted surface patch sticks out to first order in the patch size; the
      // cone only to second order, which is what keeps the search local on curved bodies.
      const double ct = nd.axis.dot(d), st = nd.axis.cross(d).norm();
      double cone;
      if (st * nd.cphi - ct * nd.sphi <= 0 && ct * nd.cphi + st * nd.sphi >= 0) {
        cone = nd.rmax;
      } else {
        const double c = ct * nd.cphi + st * nd.sphi;
        cone = (c >= 0 ? nd.rmax : nd.rmin) * c;
      }
      s = std::min(s, cone);
    }
    return s + nd.rho_max + margin_;
  }

  // Builds the subtree rooted at the pre-allocated slot `slot`.
  void fill(std::span<const Vec3> c, std::span<const double> r, std::vector<std::uint32_t>& perm, std::uint32_t slot,
            std::uint32_t begin, std::uint32_t end) {
    Node nd;
    nd.begin = begin;
    nd.end = end;
    nd.rho_max = -kInf;
    for (int k = 0; k < 3; ++k) nd.lo[k] = kInf, nd.hi[k] = -kInf;
    Vec3 mean = Vec3::Zero();
    bool at_origin = false;
    nd.rmin = kInf;
    for (std::uint32_t j = begin; j < end; ++j) {
      const Vec3& p = c[perm[j]];
      for (int k = 0; k < 3; ++k) nd.lo[k] = std::min(nd.lo[k], p[k]), nd.hi[k] = std::max(nd.hi[k], p[k]);
      nd.rho_max = std::max(nd.rho_max, r[perm[j]]);
      const double len = p.norm();
      nd.rmin = std::min(nd.rmin, len);
      nd.rmax = std::max(nd.rmax, len);
      if (len > 0) mean += p / len;
      else at_origin = true;
    }
    if (!at_origin && mean.norm() > 0) {
      nd.axis = mean.normalized();
      // Half-angle from the largest sine while every centre is within 90 degrees of the axis
      // (asin is accurate for small angles, where acos of the smallest cosine is not).
      double smax = 0, cmin = 1;
      for (std::uint32_t j = begin; j < end; ++j) {
        const Vec3& p = c[perm[j]];
        const double len = p.norm();
        smax = std::max(smax, nd.axis.cross(p).norm() / len);
        cmin = std::min(cmin, nd.axis.dot(p) / len);
      }
      // Pad the angle and radii well beyond rounding (angles to ~1e-16 rad, lengths to ~1e-16 relative).
      const double phi = std::asin(std::min(1.0, smax)) + 1e-12;
      if (cmin > 1e-6 && phi < 1.5) {
        nd.cone = true;
        nd.cphi = std::cos(phi);
        nd.sphi = std::sin(phi);
        nd.rmax *= 1 + 1e-13;
        nd.rmin *= 1 - 1e-13;
      }
    }
    if (end - begin > kLeaf) {
      int axis = 0;
      for (int k = 1; k < 3; ++k)
        if (nd.hi[k] - nd.lo[k] > nd.hi[axis] - nd.lo[axis]) axis = k;
      const std::uint32_t mid = begin + (end - begin) / 2;
      std::nth_element(perm.begin() + begin, perm.begin() + mid, perm.begin() + end, [&](std::uint32_t a, std::uint32_t b) {
        return c[a][axis] < c[b][axis] || (c[a][axis] == c[b][axis] && a < b);
      });
      const auto l = static_cast<std::uint32_t>(nodes_.size());
      nodes_.push_back({});
      nodes_.push_back({});
      nd.left = l;
      fill(c, r, perm, l, begin, mid);
      fill(c, r, perm, l + 1, mid, end);
    }
    nodes_[slot] = nd;
  }

  double margin_ = 0;
  std::vector<Node> nodes_;
  std::vector<Pt> pts_;
};

}  // namespace

Support brute_support(std::span<const Vec3> centres, std::span<const double> radii, const Vec3& d) {
  check_spans(centres, radii);
  TopTwo t;
  const auto n = static_cast<std::uint32_t>(centres.size());
  for (std::uint32_t i = 0; i < n; ++i) t.offer(i, support_value(centres[i], radii[i], d));
  return t.result();
}

std::unique_ptr<SupportQuery> make_support_tree(std::span<const Vec3> centres, std::span<const double> radii) {
  return std::make_unique<Tree>(centres, radii);
}

BodyContact make_body_contact(const Support& s, const RoughBody& b, const Rotation& q) {
  const Vec3 d = body_down(q);
  BodyContact c;
  c.index = s.index;
  c.r = q * (b.centres[s.index] + b.radii[s.index] * d);
  c.gap = s.h - s.runner_up_h;
  return c;
}

}  // namespace asperity
