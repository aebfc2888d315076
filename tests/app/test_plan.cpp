// SPDX-License-Identifier: GPL-3.0-or-later
// The planner runs only what a scene's outputs need: no impact stage for contact statistics, no
// sphere or index in fresh mode, a scan instead of an index for few rotations per sphere, no law
// that was not asked for -- and skipping a stage never changes a result that is reported.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "asperity/app/plan.hpp"
#include "asperity/app/run.hpp"
#include "asperity/app/scene_file.hpp"

using namespace asperity;

namespace {

Scene small(const std::string& name) {
  Scene s = preset(name);
  s.ensemble.sphere.asperities = 2000;
  s.ensemble.drops = 4000;
  if (s.ensemble.mode == Mode::explicit_spheres && !s.spheres_auto) s.ensemble.spheres = 4;
  s.plots = false;
  return s;
}

const PlanStage& stage(const GeometryReport& r, const std::string& name) {
  const auto it = std::find_if(r.plan.begin(), r.plan.end(), [&](const PlanStage& s) { return s.name == name; });
  if (it == r.plan.end()) throw std::runtime_error("no stage " + name);
  return *it;
}

// Bitwise equal, NaN == NaN (a count test has no KS distance).
bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

bool has_test(const GeometryReport& r, const std::string& quantity) {
  return std::any_of(r.tests.begin(), r.tests.end(), [&](const TestReport& t) { return t.quantity == quantity; });
}

}  // namespace

TEST(Plan, EveryStageIsListedWithAReason) {
  for (const auto& name : preset_names()) {
    const Plan p = plan(preset(name));
    if (p.kind != RunKind::sphere) {  // the other kinds list their stages as they run (run.cpp)
      EXPECT_TRUE(p.stages.empty()) << name;
      continue;
    }
    std::vector<std::string> names;
    for (const auto& s : p.stages) {
      names.push_back(s.name);
      EXPECT_FALSE(s.reason.empty()) << name << " " << s.name;
    }
    EXPECT_EQ(names, (std::vector<std::string>{"generate", "index", "query", "cross_check", "impact", "analysis", "plots"}))
        << name;
  }
}

TEST(Plan, SampledModeBuildsNoSphereAndNoIndex) {
  Scene s = preset("fig3");
  s.ensemble.mode = Mode::sampled;
  const Plan p = plan(s);
  EXPECT_FALSE(p.runs("generate"));
  EXPECT_FALSE(p.runs("index"));
  EXPECT_FALSE(p.runs("cross_check"));
  EXPECT_TRUE(p.runs("query"));
  Scene t = small("fig3");
  t.ensemble.mode = Mode::sampled;
  const auto r = run_scene(t);
  EXPECT_FALSE(stage(r, "generate").run);
  EXPECT_EQ(stage(r, "generate").seconds, 0.0);
  EXPECT_EQ(stage(r, "index").seconds, 0.0);
}

TEST(Plan, ExplicitDefaultBuildsSpheresIndexesAndCrossChecks) {
  const Plan p = plan(preset("fig3"));
  EXPECT_TRUE(p.runs("generate"));
  EXPECT_TRUE(p.runs("index"));
  EXPECT_TRUE(p.runs("cross_check"));
  EXPECT_EQ(p.scene.ensemble.spheres, auto_spheres(100000, 1000000));
  EXPECT_EQ(p.scene.ensemble.backend, Backend::grid);
  const auto r = run_scene(small("fig3"));
  EXPECT_TRUE(stage(r, "cross_check").run);
  EXPECT_GE(r.cross_check.queries, 100u);
  EXPECT_EQ(r.cross_check.agreed, r.cross_check.queries);
}

TEST(Plan, ContactOnlySceneRunsNoImpactStage) {
  // fig3: a contact experiment.
  auto r = run_scene(small("fig3"));
  EXPECT_FALSE(stage(r, "impact").run);
  EXPECT_FALSE(has_test(r, "eps"));
  // fig4 with restitution switched off: the impact experiment is planned away, the contact results
  // are the same bits as with it.
  Scene with = small("fig4"), without = small("fig4");
  without.restitution_stats = false;
  const Plan p = plan(without);
  EXPECT_FALSE(p.runs("impact"));
  EXPECT_FALSE(p.scene.ensemble.impact.enabled);
  const auto a = run_scene(with), b = run_scene(without);
  EXPECT_TRUE(stage(a, "impact").run);
  EXPECT_FALSE(stage(b, "impact").run);
  EXPECT_EQ(stage(b, "impact").reason, "outputs.restitution = false");
  EXPECT_TRUE(has_test(a, "eps") && has_test(a, "omega_x_after"));
  EXPECT_FALSE(has_test(b, "eps") || has_test(b, "omega_x_after"));
  for (const auto& ta : a.tests) {
    if (ta.quantity == "eps" || ta.quantity == "omega_x_after") continue;
    const auto tb = std::find_if(b.tests.begin(), b.tests.end(), [&](const TestReport& t) {
      return t.quantity == ta.quantity && t.law == ta.law && t.scope == ta.scope;
    });
    ASSERT_NE(tb, b.tests.end()) << ta.quantity << " " << ta.law;
    EXPECT_TRUE(same(tb->D, ta.D)) << ta.quantity;
    EXPECT_EQ(tb->p, ta.p) << ta.quantity;
  }
}

TEST(Plan, RestitutionOnlySceneAnalysesNoContactLaw) {
  Scene s = small("fig4");
  s.contact_stats = false;
  const auto r = run_scene(s);
  EXPECT_TRUE(stage(r, "impact").run);
  EXPECT_EQ(stage(r, "analysis").reason.find("contact laws"), std::string::npos);
  for (const char* q : {"r_xy", "r_x", "r_y", "core_contacts"}) EXPECT_FALSE(has_test(r, q)) << q;
  EXPECT_TRUE(has_test(r, "eps") && has_test(r, "omega_x_after"));
  for (const auto& q : r.quantities) EXPECT_TRUE(q.name == "eps" || q.name == "omega_x_after") << q.name;
}

TEST(Plan, AutoBackendScansFewRotationsAndIndexesMany) {
  Scene s = small("fig3-fixed");
  s.backend_auto = true;
  s.ensemble.spheres = 4000;  // one rotation per sphere
  Plan p = plan(s);
  EXPECT_EQ(p.scene.ensemble.backend, Backend::brute);
  EXPECT_FALSE(p.runs("index"));
  EXPECT_TRUE(p.runs("generate"));
  s.ensemble.spheres = 4000 / 40;  // 40 rotations per sphere >= kScanBelowRotations
  p = plan(s);
  EXPECT_EQ(p.scene.ensemble.backend, Backend::grid);
  EXPECT_TRUE(p.runs("index"));
  // An explicit backend is honoured.
  s.backend_auto = false;
  s.ensemble.backend = Backend::kdtree;
  s.ensemble.spheres = 4000;
  EXPECT_EQ(plan(s).scene.ensemble.backend, Backend::kdtree);
  // Brute and an index give the same bits (every backend is exact): the choice is free.
  s.ensemble.spheres = 400;  // 10 rotations
  s.backend_auto = true;
  const auto scan = run_scene(s);
  s.backend_auto = false;
  s.ensemble.backend = Backend::grid;
  const auto grid = run_scene(s);
  EXPECT_FALSE(stage(scan, "index").run);
  EXPECT_TRUE(stage(grid, "index").run);
  ASSERT_EQ(scan.tests.size(), grid.tests.size());
  for (std::size_t i = 0; i < scan.tests.size(); ++i) {
    EXPECT_TRUE(same(scan.tests[i].D, grid.tests[i].D)) << scan.tests[i].quantity;
    EXPECT_EQ(scan.tests[i].p, grid.tests[i].p) << scan.tests[i].quantity;
  }
  EXPECT_EQ(scan.core_contacts, grid.core_contacts);
}

TEST(Plan, PlotsOnlyWhenAsked) {
  EXPECT_FALSE(plan(small("fig3")).runs("plots"));
  EXPECT_TRUE(plan(preset("fig3")).runs("plots"));
}

TEST(Plan, ReportEchoesTheSceneThatRan) {
  const Scene s = small("fig4");
  const auto r = run_scene(s);
  EXPECT_TRUE(parse_scene(r.scene_toml) == s);
  const std::string json = to_json(r);
  EXPECT_NE(json.find("\"plan\""), std::string::npos);
  EXPECT_NE(json.find("\"scene_file\""), std::string::npos);
}

// Issue 35: one plan per run, and the plan alone says whether a run streams. The scene of the issue
// (an impact scene with outputs.restitution = false, sampled, N = 1000, 4e7 drops): the planner
// switches the impacts off, so statistics "auto" streams; the scene as written does not say so.
TEST(Plan, ThePlanAloneDecidesThatARunStreams) {
  Scene s = preset("fig4");
  s.restitution_stats = false, s.plots = false;
  s.ensemble.mode = Mode::sampled, s.ensemble.sphere.asperities = 1000, s.ensemble.drops = 40'000'000;
  s.ensemble.statistics = Statistics::automatic;
  ASSERT_FALSE(uses_streaming(s.ensemble)) << "as written: impacts on, so the old deciders took it for raw";
  RunControl c;
  c.share = {1, 4}, c.resume = false;
  const Plan p = plan(s, c);
  EXPECT_TRUE(p.streams);
  EXPECT_FALSE(p.scene.ensemble.impact.enabled);
  EXPECT_EQ(p.control.share, (StreamShare{1, 4})) << "a streaming run keeps its share";
  // The wrong input: the same scene with its restitution output on keeps raw samples, and then
  // neither a share nor --resume applies.
  s.restitution_stats = true;
  const Plan raw = plan(s, c);
  EXPECT_FALSE(raw.streams);
  EXPECT_EQ(raw.control.share, StreamShare{}) << "a run that does not stream is rank 0's alone";
  c.resume = true;
  try {
    plan(s, c);
    ADD_FAILURE() << "--resume of a run that does not stream was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("does not stream"), std::string::npos) << e.what();
  }
}

TEST(Plan, EveryRunIsPlannedOnce) {
  // A sphere run, a streaming sphere run and a bounce run: each one plan, by run_scene_output.
  Scene stream = small("fig3");
  stream.ensemble.statistics = Statistics::streaming;
  Scene bounce = preset("fig6");
  bounce.plots = false, bounce.bounce.sequences = 20, bounce.bounce.variants = {bounce.bounce.variants.front()};
  for (Scene s : {small("fig4"), stream, bounce}) {
    s.out = std::filesystem::temp_directory_path() / "asperity-test-plan-once";
    const std::uint64_t before = plans_made();
    const SceneOutput o = run_scene_output(s, {}, nullptr, {});
    EXPECT_EQ(plans_made() - before, 1u) << s.name << " (" << to_string(o.kind) << ")";
    std::filesystem::remove_all(s.out);
  }
  const std::uint64_t before = plans_made();
  run_scene(small("fig3"));
  EXPECT_EQ(plans_made() - before, 1u) << "run_scene";
}
