// SPDX-License-Identifier: GPL-3.0-or-later
// Fuzz target: the command line of validate-geometry (asperity::cli::parse_command_line).
// Contract checked on every input: the parser returns a scene with finite numbers in range (its
// cross-key rules are plan()'s, once per run), or throws BadInput with a message; anything else (another exception, a crash, a
// sanitizer report, a hang) is a bug. Input: one argument per line.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "app/cli/options.hpp"
#include "fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 4096) return 0;  // command lines, not files
  const auto args = asperity::fuzz::split_lines(data, size);
  try {
    // --scene FILE: never read files while fuzzing (the scene parser has its own target).
    const auto o = asperity::cli::parse_command_line(args, [](const std::string& file, const std::vector<asperity::SceneEdit>&) -> asperity::Scene {
      throw asperity::cli::BadInput("--scene: '" + file + "' (files are not read while fuzzing)");
    });
    if (o.help) return o.help_text.empty() ? (std::abort(), 0) : 0;
    // Each value the parser accepted is in range; the cross-key rules are plan()'s (once per run).
    const auto& e = o.scene.ensemble;
    if (!std::isfinite(e.sphere.radius) || !std::isfinite(e.sphere.asperity_radius) || !e.impact.omega.allFinite() ||
        !std::isfinite(e.impact.speed) || !(o.scene.alpha > 0 && o.scene.alpha < 1) || o.scene.out.empty()) {
      std::fprintf(stderr, "parse_command_line accepted an invalid scene\n");
      std::abort();
    }
  } catch (const asperity::cli::BadInput& ex) {
    if (std::string(ex.what()).empty()) {
      std::fprintf(stderr, "BadInput without a message\n");
      std::abort();
    }
  }
  return 0;  // any other exception escapes: libFuzzer reports it as a crash
}
