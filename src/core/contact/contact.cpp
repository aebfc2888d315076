#include "asperity/core/contact.hpp"

#include "asperity/config.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/contact/detail.hpp"

namespace asperity {

namespace {
#if ASPERITY_WITH_FCL
constexpr std::array kBackends{Backend::brute, Backend::kdtree, Backend::cgal, Backend::fcl, Backend::grid};
#else
constexpr std::array kBackends{Backend::brute, Backend::kdtree, Backend::cgal, Backend::grid};
#endif
}

std::string_view to_string(Backend b) {
  switch (b) {
    case Backend::brute: return "brute";
    case Backend::kdtree: return "kdtree";
    case Backend::cgal: return "cgal";
    case Backend::fcl: return "fcl";
    case Backend::grid: return "grid";
  }
  return "?";
}

Backend parse_backend(std::string_view name) {
  for (Backend b : kBackends)
    if (to_string(b) == name) return b;
  throw std::invalid_argument("unknown backend '" + std::string(name) +
                              "' (expected brute, kdtree, cgal, fcl or grid)");
}

std::span<const Backend> all_backends() { return kBackends; }

void ContactQuery::lowest(std::span<const Vec3> d, std::span<Nearest> out) const {
  if (out.size() != d.size()) throw std::invalid_argument("lowest(): output size differs from input size");
  for (std::size_t i = 0; i < d.size(); ++i) out[i] = lowest(d[i]);
}

std::unique_ptr<ContactQuery> make_contact_query(Backend backend, std::span<const Vec3> centres) {
  if (centres.empty()) throw std::invalid_argument("make_contact_query: a body needs at least one asperity");
  switch (backend) {
    case Backend::brute: return detail::make_brute(centres);
    case Backend::kdtree: return detail::make_nanoflann(centres);
    case Backend::cgal: return detail::make_cgal(centres);
    case Backend::fcl:
#if ASPERITY_WITH_FCL
      return detail::make_fcl(centres);
#else
      throw std::invalid_argument("backend 'fcl': not built (configure with -DASPERITY_WITH_FCL=ON and libfcl-dev)");
#endif
    case Backend::grid: return detail::make_grid(centres);
  }
  throw std::invalid_argument("make_contact_query: unknown backend");
}

Contact make_contact(const Nearest& n, const Vec3& u, const Rotation& q, double R, double a) {
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
