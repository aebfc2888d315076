// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Scene files: a versioned TOML format (format = 1) describing one run -- body, material,
// asperities, ensemble, experiment, outputs. Documented in docs/scenes.md and, key by key, in
// scenes/example.toml. Every key is checked: unknown keys, wrong types, NaN/inf and out-of-range
// values are errors naming the full dotted key (and the value); features the engine does not have
// yet (oblique impacts, constant restitution, ...) are errors
// "not supported yet: <key> = <value>", never silently ignored.
#include <filesystem>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "asperity/app/scene.hpp"

namespace asperity {

/// The scene format version this library reads and writes.
inline constexpr int kSceneFormatVersion = 1;

/// A bad scene file: what() is "<origin>:<line>: <key>: <problem>"; key() is the dotted key
/// ("" for a TOML syntax error).
class SceneError : public std::invalid_argument {
 public:
  SceneError(const std::string& what, std::string key) : std::invalid_argument(what), key_(std::move(key)) {}
  const std::string& key() const noexcept { return key_; }

 private:
  std::string key_;
};

/// Parses and validates a scene. Pure (no file or environment access): `origin` only names the
/// text in messages. Throws SceneError.
Scene parse_scene(std::string_view toml_text, std::string_view origin = "scene");

/// One KEY=VALUE of an option's value (--tangential coulomb:mu=0.3,...): a number when `number`
/// holds it, else the text.
struct OptionItem {
  std::string key, text;
  std::optional<double> number;
};

/// material.tangential from the items of --tangential (model first), read by the one reader of
/// material.tangential, so each key is checked and worded as in a scene file. Throws SceneError
/// "<origin>: material.tangential.<key>: <problem>".
TangentialLaw read_tangential_items(const std::vector<OptionItem>& items, std::string_view origin);

/// Reads and parses a scene file; throws SceneError (also for an unreadable file).
Scene load_scene(const std::filesystem::path& file);

/// A key the command line sets in the scene's table before the one reading (issue 38): the value
/// as a scene file would hold it, checked by the reader like any key of the file. A problem with
/// it is named by its option ("--drops: ensemble.drops: must be >= 2, got 1"), not by a line.
struct SceneEdit {
  std::string key;     ///< dotted: "ensemble.drops"
  std::string option;  ///< "--drops"
  std::variant<std::int64_t, double, std::string, bool> value;
  /// What this key replaces (removed): keys of the same table ("areal_density"), "*" for every
  /// other key of that table, "[screening]" for a table of the scene.
  std::vector<std::string> replaces;
};

/// parse_scene, load_scene and preset with `edits` applied to the table before it is read.
Scene parse_scene(std::string_view toml_text, std::string_view origin, const std::vector<SceneEdit>& edits);
Scene load_scene(const std::filesystem::path& file, const std::vector<SceneEdit>& edits);
Scene preset(std::string_view name, const std::vector<SceneEdit>& edits);

/// The scene as a format-1 TOML document with every key it uses written: parse_scene(to_toml(s))
/// == s for every valid scene. Settings a scene does not use are not written and read back as
/// their defaults: V and Omega of a contact experiment, spheres in fresh mode.
std::string to_toml(const Scene& s);

}  // namespace asperity
