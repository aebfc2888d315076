#include "asperity/app/scene.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "asperity/app/scene_file.hpp"
#include "core/format.hpp"
#include "asperity_embedded_scenes.hpp"  // generated from scenes/*.toml (CMakeLists.txt)

namespace asperity {

std::vector<std::string> preset_names() {
  std::vector<std::string> names;
  for (const auto& s : embedded::kScenes) names.emplace_back(s.name);
  return names;
}

std::string_view preset_text(std::string_view name) {
  for (const auto& s : embedded::kScenes)
    if (s.name == name) return s.text;
  std::string known;
  for (const auto& p : preset_names()) known += (known.empty() ? "" : ", ") + p;
  throw std::invalid_argument("unknown preset '" + std::string(name) + "' (known: " + known + ")");
}

Scene preset(std::string_view name) {
  return parse_scene(preset_text(name), "preset " + std::string(name) + " (scenes/" + std::string(name) + ".toml)");
}

void validate(const Scene& s) {
  validate(s.ensemble);
  if (!(s.alpha > 0 && s.alpha < 1))
    throw std::invalid_argument("alpha must be in (0, 1), got " + std::to_string(s.alpha));
  if (s.out.empty()) throw std::invalid_argument("out must not be empty");
  if (s.report.empty() || s.report.find('/') != std::string::npos || s.report == "." || s.report == "..")
    throw std::invalid_argument("report must be a file name inside out, got '" + s.report + "'");
  if (s.name.empty()) throw std::invalid_argument("name must not be empty");
  if (s.bounce.enabled) validate(s.bounce);
  if (s.bounce.enabled && !s.mesh && s.bounce.omega != Vec3::Zero())
    throw std::invalid_argument("bounce: Omega is for mesh bodies; the sphere's variants start without spin (Sec. V)");
  // Mesh bodies and unequal radii are the runs of body_experiments.hpp (also after command-line
  // overrides of a scene file): only the ensembles and experiments those runs have.
  if (s.radii) validate(s.radii->radii);
  if (s.mesh) {
    if (s.mesh->file.empty()) throw std::invalid_argument("mesh file must not be empty");
    if (s.ensemble.mode != Mode::explicit_spheres)
      throw std::invalid_argument("a mesh body needs mode explicit (explicit bodies x rotations), got " +
                                  std::string(to_string(s.ensemble.mode)));
    if (s.ensemble.impact.enabled == s.bounce.enabled)
      throw std::invalid_argument("a mesh body runs single impacts or bounce sequences: it needs an impact or a bounce "
                                  "experiment");
    if (s.bounce.enabled && s.bounce.variants != std::vector<BounceVariant>{BounceVariant::dynamic})
      throw std::invalid_argument("a mesh body bounces with its orientation carried by the free rotation: variants must "
                                  "be \"dynamic\" only");
  } else if (s.radii) {
    // As the scene file checks it, also after --radius: every level (the lognormal median) below R.
    const auto& d = s.radii->radii;
    const double R = s.ensemble.sphere.radius;
    const double top = d.kind == RadiusDistribution::Kind::levels
                           ? *std::max_element(d.levels.begin(), d.levels.end())
                           : d.kind == RadiusDistribution::Kind::lognormal ? d.median : d.radius;
    if (!(top < R))
      throw std::invalid_argument("asperity radii " + d.describe() + " must be smaller than radius = " + detail::num(R) + " m");
    if (s.ensemble.mode != Mode::sampled)
      throw std::invalid_argument("unequal asperity radii on a sphere need mode sampled (their exact sampler), got " +
                                  std::string(to_string(s.ensemble.mode)));
    if (s.ensemble.impact.enabled || s.bounce.enabled)
      throw std::invalid_argument("unequal asperity radii on a sphere are analysed as contacts only (no impacts)");
  }
}

}  // namespace asperity
