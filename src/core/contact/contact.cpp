// SPDX-License-Identifier: GPL-3.0-or-later
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

void ContactQuery::lowest_winners(std::span<const Vec3> d, std::span<Nearest> out) const {
  lowest(d, out);  // checks the sizes
  for (Nearest& n : out) n = winner_only(n);
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

}  // namespace asperity
