// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The command line of validate-geometry, parsed into a validated Scene without touching the file
// system: main() and the fuzz target (tests/fuzz/cli_options.cpp) call the same function.
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "asperity/app/plan.hpp"
#include "asperity/app/scene_file.hpp"

namespace asperity::cli {

/// Bad user input. what() names the option and the offending value; validate-geometry exits 2.
struct BadInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Options {
  Scene scene;             ///< each key checked; its cross-key rules are plan()'s (plan.hpp)
  RunControl control;      ///< --resume, --checkpoint-every (the share is the caller's)
  /// The options given that act on streaming statistics only (--checkpoint-every, --bins-log2):
  /// validate-geometry refuses them when the run's plan keeps raw samples.
  std::vector<std::string> streaming_only;
  bool quiet = false;      ///< --quiet: no progress lines
  bool help = false;       ///< --help or --version was given: print help_text, exit 0, nothing else
  std::string help_text;
};

/// Parses the arguments after the program name. Throws BadInput (and only BadInput) for any bad
/// option or value: unknown options, malformed/non-finite/out-of-range numbers, options that do not
/// apply to the scene's kind of run. The scene's cross-key rules are checked once, by plan(). No files are written; `--scene FILE` is read through `load` (load_scene by default;
/// the fuzz target passes its own, so that fuzzing never touches the file system). `edits`: the
/// options that set one scene key, applied before the file is read (scene_file.hpp).
using SceneLoader = std::function<Scene(const std::string& file, const std::vector<SceneEdit>& edits)>;
Options parse_command_line(std::span<const std::string> args, const SceneLoader& load = {});

}  // namespace asperity::cli
