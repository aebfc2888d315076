// SPDX-License-Identifier: GPL-3.0-or-later
// run_scene_output: every kind of scene through one report path, with progress of the drops.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <regex>
#include <unistd.h>
#include <thread>
#include <string>
#include <utility>
#include <vector>

#include "asperity/app/run.hpp"
#include "asperity/app/scene_file.hpp"

namespace {

using namespace asperity;

Scene scene_of(const std::string& text) { return parse_scene(text, "test_run"); }

const std::filesystem::path kOut =
    std::filesystem::temp_directory_path() / ("asperity-test-run-" + std::to_string(::getpid()));
const std::string kOutputs = "[outputs]\nplots = false\ndir = \"" + kOut.string() + "\"\n";

Scene levels_scene(const std::string& radius) {
  return scene_of("format = 1\nname = \"lv\"\n[asperities]\ncount = 2000\n" + radius +
                  "[screening]\nbodies = 2\ndirections = 1000\n[ensemble]\ndrops = 40000\nseed = 3\n" + kOutputs);
}

Scene mesh_scene() {
  return scene_of("format = 1\nname = \"m\"\n[body]\nkind = \"mesh\"\nmesh = \"" + std::string(ASPERITY_MESH_DIR) +
                  "/ellipsoid.off\"\nsmooth = [4e-3, 3e-3, 2.25e-3]\n[asperities]\ncount = 2000\n"
                  "[ensemble]\nmode = \"explicit\"\nspheres = 2\ndrops = 40000\n"
                  "[experiment]\nkind = \"impact\"\nV = [0, 0, -1.3]\nOmega = [0.2, 0, 0]\n" + kOutputs);
}

// Wall-clock fields differ between two runs; everything else must not.
std::string without_clock(std::string text) {
  text = std::regex_replace(text, std::regex("\"timings_s\": *\\{[^}]*\\}"), "\"timings_s\": {}");
  return std::regex_replace(text, std::regex("\"(seconds[a-z_]*)\": *[-+.0-9eE]+"), "\"$1\": 0");
}

// Progress goes from the calling thread, never backwards, and ends at (drops, drops); a run
// without a callback gives the same report (the chunking does not depend on the callback).
TEST(RunSceneOutput, RadiiAndMeshRunsReportProgressAndTheCommonHeader) {
  const std::vector<std::pair<Scene, RunKind>> scenes = {
      {levels_scene("radius = { distribution = \"levels\", radii = [1.3e-6, 6.5e-7], fractions = [0.2, 0.8] }\n"),
       RunKind::radii},
      {levels_scene("radius = { distribution = \"lognormal\", median = 6.5e-7, sigma = 0.5 }\n"), RunKind::radii},
      {mesh_scene(), RunKind::mesh}};
  for (const auto& [scene, kind] : scenes) {
    EXPECT_EQ(run_kind(scene), kind);
    std::vector<std::pair<std::uint64_t, std::uint64_t>> calls;
    bool other_thread = false;
    const auto caller = std::this_thread::get_id();
    const SceneOutput a = run_scene_output(scene, [&](std::uint64_t done, std::uint64_t total) {
      other_thread |= std::this_thread::get_id() != caller;  // callbacks must not come from OpenMP workers
      calls.emplace_back(done, total);
    });
    EXPECT_FALSE(other_thread) << to_string(kind);
    ASSERT_GE(calls.size(), 2u) << to_string(kind);  // 40000 drops are more than one chunk
    for (std::size_t i = 0; i < calls.size(); ++i) {
      EXPECT_EQ(calls[i].second, 40000u);
      if (i > 0) {
        EXPECT_GT(calls[i].first, calls[i - 1].first);
      }
    }
    EXPECT_EQ(calls.back().first, 40000u);
    const SceneOutput b = run_scene_output(scene);
    EXPECT_EQ(without_clock(a.json), without_clock(b.json));
    const auto j = nlohmann::json::parse(a.json);
    EXPECT_EQ(j.at("schema_version"), 1);
    EXPECT_EQ(j.at("tool"), "validate-geometry");
    EXPECT_EQ(j.at("scene"), scene.name);
    EXPECT_EQ(j.at("scene_file"), to_toml(scene));
    EXPECT_FALSE(a.table.empty());
    EXPECT_EQ(a.rejected, j.at("rejected").get<bool>());
  }
  std::filesystem::remove_all(kOut);
}

}  // namespace
