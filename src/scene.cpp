#include "asperity/scene.hpp"

#include <cmath>
#include <stdexcept>

namespace asperity {

std::vector<std::string> preset_names() { return {"fig3", "fig3-fixed", "fig4", "fig5", "fig6"}; }

Scene preset(std::string_view name) {
  Scene s;
  s.ensemble.sphere = SphereParams{100000, 3e-3, 6.5e-7};
  s.ensemble.drops = 1000000;
  s.ensemble.seed = 1;
  if (name == "fig3") {
    s.name = "fig3";
    s.ensemble.mode = Mode::fresh;
    return s;
  }
  if (name == "fig3-fixed") {
    // The same physics from explicit spheres: 100 spheres x 10^4 rotations.
    s.name = "fig3-fixed";
    s.ensemble.mode = Mode::fixed;
    s.ensemble.spheres = 100;
    s.ensemble.backend = Backend::grid;
    return s;
  }
  if (name == "fig4") {
    // Fig. 4: eps from explicit geometry + the full impulse; V.n = 1.3 m/s, Omega_x = 0.2 rad/s.
    s.name = "fig4";
    s.ensemble.impact.enabled = true;
    s.ensemble.impact.speed = 1.3;
    s.ensemble.impact.omega = Vec3(0.2, 0.0, 0.0);
    return s;
  }
  if (name == "fig5") {
    // Fig. 5: Omega'_x with Omega = 0, V.n = 1 m/s, a = R x 1e-4.
    s.name = "fig5";
    s.ensemble.sphere.asperity_radius = 3e-3 * 1e-4;
    s.ensemble.impact.enabled = true;
    s.ensemble.impact.speed = 1.0;
    s.ensemble.impact.omega = Vec3(0.0, 0.0, 0.0);
    return s;
  }
  if (name == "fig6") {
    // Sec. V / Fig. 6: bounce sequences of a rough sphere, N = 1e6, a = 5e-4 mm.
    s.name = "fig6";
    s.ensemble.sphere = SphereParams{1000000, 3e-3, 5e-7};
    s.bounce.enabled = true;
    return s;
  }
  std::string known;
  for (const auto& p : preset_names()) known += (known.empty() ? "" : ", ") + p;
  throw std::invalid_argument("unknown preset '" + std::string(name) + "' (known: " + known + ")");
}

void validate(const Scene& s) {
  validate(s.ensemble);
  if (!(s.alpha > 0 && s.alpha < 1))
    throw std::invalid_argument("alpha must be in (0, 1), got " + std::to_string(s.alpha));
  if (s.out.empty()) throw std::invalid_argument("out must not be empty");
  if (s.bounce.enabled) validate(s.bounce);
}

}  // namespace asperity
