// Placeholder: being written.
#include <stdexcept>

#include "contact/detail.hpp"

namespace asperity::detail {
std::unique_ptr<ContactQuery> make_cgal(std::span<const Vec3>) {
  throw std::logic_error("backend 'cgal' is not built yet");
}
}  // namespace asperity::detail
