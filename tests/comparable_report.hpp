// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// report.json without what may differ between runs that must agree (a split, an interrupted and
// resumed, and a whole run): wall-clock timings, the plan's stage seconds, the echoed scene file.
#include <filesystem>

#include <nlohmann/json.hpp>

#include "run_command.hpp"

namespace asperity::testing {

inline nlohmann::json comparable_report(const std::filesystem::path& report) {
  auto j = nlohmann::json::parse(slurp(report));
  for (const char* k : {"timings_s", "plan", "scene_file"}) j.erase(k);
  return j;
}

}  // namespace asperity::testing
