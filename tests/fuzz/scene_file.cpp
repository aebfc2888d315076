// SPDX-License-Identifier: GPL-3.0-or-later
// Fuzz target: the scene-file parser (asperity::parse_scene, TOML format 1).
// Contract checked on every input: parse_scene returns a scene that passes validate() and survives
// a round trip through to_toml unchanged, or throws SceneError with a message naming where; any
// other exception, crash, sanitizer report or hang is a bug.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "asperity/app/scene_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 16384) return 0;  // scene files are small; keep the fuzzer on syntax, not size
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const asperity::Scene s = asperity::parse_scene(text, "fuzz");
    asperity::validate(s);  // must not throw: the parser validated it
    if (!(asperity::parse_scene(asperity::to_toml(s), "round-trip") == s)) {
      std::fprintf(stderr, "to_toml/parse_scene round trip changed the scene\n");
      std::abort();
    }
  } catch (const asperity::SceneError& ex) {
    if (std::string(ex.what()).empty()) {
      std::fprintf(stderr, "SceneError without a message\n");
      std::abort();
    }
  }
  return 0;  // any other exception escapes: libFuzzer reports it as a crash
}
