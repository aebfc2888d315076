#include <asperity/contact.hpp>
#include <asperity/geometry.hpp>

#include <iostream>

int main() {
  const auto body = asperity::make_rough_sphere({1000, 3e-3, 6.5e-7}, 1, 0);
  const auto index = asperity::make_contact_query(asperity::Backend::grid, body.centres);
  const asperity::Vec3 down(0, 0, -1);
  const auto n = index->lowest(down);
  const bool ok = n == asperity::brute_lowest(body.centres, down);
  std::cout << "lowest asperity " << n.index << (ok ? " (matches brute force)" : " (MISMATCH)") << "\n";
  return ok ? 0 : 1;
}
