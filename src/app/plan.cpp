// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/app/plan.hpp"

#include <stdexcept>

namespace asperity {

bool Plan::runs(std::string_view name) const {
  for (const auto& s : stages)
    if (s.name == name) return s.run;
  return false;
}

PlanStage& Plan::stage(std::string_view name) {
  for (auto& s : stages)
    if (s.name == name) return s;
  throw std::out_of_range("no stage '" + std::string(name) + "' in the plan");
}

Plan make_plan(const Scene& s) {
  Plan p;
  p.scene = s;
  auto& e = p.scene.ensemble;
  const bool fixed = e.mode == Mode::explicit_spheres;
  if (fixed && s.spheres_auto) e.spheres = auto_spheres(e.sphere.asperities, e.drops);
  const std::uint64_t rotations = fixed ? e.drops / e.spheres : 1;
  if (fixed && s.backend_auto) e.backend = rotations < kScanBelowRotations ? Backend::brute : Backend::grid;

  const std::string n = std::to_string(e.sphere.asperities);
  if (fixed)
    p.stages.push_back({"generate", true,
                        std::to_string(e.spheres) + " explicit sphere(s) of " + n + " asperities" +
                            (s.spheres_auto ? " (spheres auto: error budget M <= N/(10 c^2) rotations per sphere, K >= " +
                                                  std::to_string(kAutoMinSpheres) + ")"
                                            : std::string())});
  else
    p.stages.push_back({"generate", false,
                        "sampled: each drop draws its lowest asperities from the exact finite-N law; no sphere is built"});

  if (!fixed) {
    p.stages.push_back({"index", false, "sampled: no sphere, no index"});
  } else if (e.backend == Backend::brute) {
    p.stages.push_back(
        {"index", false,
         s.backend_auto ? "backend auto: " + std::to_string(rotations) + " rotation(s) per sphere < " +
                              std::to_string(kScanBelowRotations) + ", a brute scan costs less than building the grid"
                        : std::string("backend brute: every query scans the sphere")});
  } else {
    p.stages.push_back({"index", true,
                        std::string(to_string(e.backend)) + " index per sphere" +
                            (s.backend_auto ? ", backend auto: " + std::to_string(rotations) + " rotations per sphere >= " +
                                                  std::to_string(kScanBelowRotations)
                                            : std::string())});
  }
  p.stages.push_back({"query", true,
                      "lowest asperity of each of " + std::to_string(e.drops) + " drops" +
                          (fixed ? std::string(" by spatial query") : std::string(" (exact sampler, no geometry)"))});
  if (fixed)
    p.stages.push_back({"cross_check", true,
                        "a deterministic subsample of the queries answered again by brute force and the kd-tree (and FCL "
                        "where built and N is small)"});
  else
    p.stages.push_back({"cross_check", false, "sampled: no spatial queries to check"});

  const bool impact = e.impact.enabled && s.restitution_stats;
  if (impact)
    p.stages.push_back({"impact", true, "outputs.restitution: the impulse of every drop"});
  else
    p.stages.push_back({"impact", false,
                        e.impact.enabled ? "outputs.restitution = false" : "experiment.kind = contact: no impacts"});
  e.impact.enabled = impact;

  std::string what;
  if (s.contact_stats) what = "contact laws (r_xy, r_x, r_y, r_z, core contacts)";
  if (impact) what += std::string(what.empty() ? "" : " and ") + "restitution laws (eps, Omega'_x)";
  if (what.empty()) what = "summaries only: no law requested";
  p.stages.push_back({"analysis", true, what});

  if (s.plots)
    p.stages.push_back({"plots", true, "outputs.plots: a figure per analysed quantity"});
  else
    p.stages.push_back({"plots", false, "outputs.plots = false"});
  return p;
}

}  // namespace asperity
