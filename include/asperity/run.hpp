#pragma once
// One call runs a scene as validate-geometry does: plan, ensemble, analysis, figures.
#include "asperity/ensemble.hpp"
#include "asperity/plan.hpp"
#include "asperity/report.hpp"
#include "asperity/scene.hpp"

namespace asperity {

/// Runs only the stages make_plan(s) lists (figures are written into s.out when planned; the
/// report file is not written). The report carries the plan with stage times and the scene as
/// TOML (to_toml(s)). Throws std::invalid_argument for an invalid scene.
GeometryReport run_scene(const Scene& s, const Progress& progress = {});

}  // namespace asperity
