#include "asperity/run.hpp"

#include <chrono>

#include "asperity/scene_file.hpp"

namespace asperity {

GeometryReport run_scene(const Scene& s, const Progress& progress) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  validate(s);
  Plan plan = make_plan(s);
  const Scene& run = plan.scene;
  const ContactSamples samples = run_contact_ensemble(run.ensemble, progress);
  auto t0 = Clock::now();
  GeometryReport r = analyse(run, samples);
  r.timings_s.emplace_back("analysis", since(t0));
  plan.stage("analysis").seconds = r.timings_s.back().second;
  if (plan.runs("plots")) {
    t0 = Clock::now();
    r.plots = write_plots(run.out, run, samples);
    r.timings_s.emplace_back("plots", since(t0));
    plan.stage("plots").seconds = r.timings_s.back().second;
  }
  plan.stage("generate").seconds = samples.seconds_generate;
  plan.stage("index").seconds = samples.seconds_index;
  plan.stage("query").seconds = samples.seconds_query;
  plan.stage("impact").seconds = samples.seconds_impact;
  r.plan = std::move(plan.stages);
  r.scene_toml = to_toml(s);
  return r;
}

}  // namespace asperity
