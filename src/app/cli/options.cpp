// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/cli/options.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "app/option_table.hpp"
#include "asperity/app/plan.hpp"
#include "asperity/app/run.hpp"
#include "asperity/app/scene_file.hpp"
#include "asperity/config.hpp"

namespace asperity::cli {

namespace {

bool digits(const std::string& t, std::size_t& i) {
  const std::size_t from = i;
  while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i;
  return i > from;
}

// Plain decimal notation: [sign] digits [. digits] [e [sign] digits] (or [sign] . digits ...).
// No spaces, no hexadecimal, no "inf"/"nan": what a person writes for a number.
bool decimal_syntax(const std::string& t) {
  std::size_t i = 0;
  if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
  const bool whole = digits(t, i);
  bool fraction = false;
  if (i < t.size() && t[i] == '.') {
    ++i;
    fraction = digits(t, i);
  }
  if (!whole && !fraction) return false;
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    if (!digits(t, i)) return false;
  }
  return i == t.size();
}

bool names_infinity_or_nan(std::string t) {
  for (char& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!t.empty() && (t[0] == '+' || t[0] == '-')) t.erase(0, 1);
  return t == "inf" || t == "infinity" || t == "nan";
}

// Every real number goes through here: the whole text must be a decimal number whose value is a
// finite, normal double (or zero); out-of-range numbers are named as such, not as "not a number".
double parse_real(const std::string& option, const std::string& text) {
  if (names_infinity_or_nan(text)) throw BadInput(option + ": '" + text + "' must be finite");
  if (!decimal_syntax(text)) throw BadInput(option + ": '" + text + "' is not a number");
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (std::isinf(v)) throw BadInput(option + ": '" + text + "' is out of range (larger than 1.8e308)");
  if ((errno == ERANGE && v == 0) || std::fpclassify(v) == FP_SUBNORMAL)
    throw BadInput(option + ": '" + text + "' is out of range (its magnitude is below 2.2e-308, the smallest normal double)");
  return v;
}

double parse_positive(const std::string& option, const std::string& text, const char* unit = "metres") {
  const double v = parse_real(option, text);
  if (v <= 0) throw BadInput(option + ": '" + text + "' must be > 0 (" + unit + ")");
  return v;
}

// The options as the user wrote them, by long flag: every value is text until its own parser
// reads it, so that a bad value is named as written.
struct RawOptions {
  std::map<std::string, std::string, std::less<>> values{{"--preset", "fig3"}};
  bool no_plots = false, quiet = false;
  const std::string& operator[](std::string_view flag) const {
    static const std::string none;
    const auto it = values.find(flag);
    return it == values.end() ? none : it->second;
  }
};

// The options that change no result (--resume takes only these), from their rows.
std::string result_free_options() {
  std::string list;
  for (const OptionRow& row : option_rows())
    if (!row.changes_result && long_flag(row) != "--resume") list += (list.empty() ? "" : ", ") + std::string(long_flag(row));
  return list;
}

// The options from their rows (option_table.hpp): type, range and help in --help.
void add_options(CLI::App& app, RawOptions& r) {
  for (const OptionRow& row : option_rows()) {
    const std::string flag(row.flag), name(long_flag(row));
    std::string help(row.help);
    if (name == "--resume") help += "; only " + result_free_options() + " may be given with it";
    if (row.type.empty()) {
      app.add_flag(flag, name == "--quiet" ? r.quiet : r.no_plots, help);
      continue;
    }
    CLI::Option* opt = app.add_option(flag, r.values[name], help)->type_name(type_text(row));
    if (name == "--scene" || name == "--resume") opt->excludes("--preset");
  }
}

// "--out=" (nothing after '='): CLI11 would take the next argument as the value.
void refuse_empty_equals(std::span<const std::string> args) {
  for (const auto& a : args) {
    if (a == "--") break;
    if (a.size() > 3 && a.compare(0, 2, "--") == 0 && a.back() == '=' && a.find('=') == a.size() - 1)
      throw BadInput(a.substr(0, a.size() - 1) + ": '' (an empty value after '=') is not a value; write " +
                     a.substr(0, a.size() - 1) + "=VALUE or " + a.substr(0, a.size() - 1) + " VALUE");
  }
}

enum class Parsed { run, help, version };

// `--out --no-plots` would take "--no-plots" as the directory: a value that is the name of one of
// our options is a forgotten value, never meant. (A directory really named so: ./--no-plots.)
void refuse_options_as_values(const CLI::App& app) {
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->get_expected_min() == 0) continue;  // a flag: no value
    for (const std::string& v : opt->results())
      if (v.size() > 1 && v[0] == '-' && app.get_option_no_throw(v) != nullptr)
        throw BadInput(opt->get_name() + ": '" + v + "' is an option, not a value; give " + opt->get_name() +
                       " a value (a name that starts with '-' can be written ./" + v + ")");
  }
}

// CLI11's parse: whether to run, or print help or the version. Unknown arguments are BadInput.
Parsed parse_arguments(CLI::App& app, std::span<const std::string> args) {
  app.allow_extras();
  try {
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 consumes from the back
    app.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    return Parsed::help;
  } catch (const CLI::CallForVersion&) {
    return Parsed::version;
  } catch (const CLI::ParseError& e) {
    throw BadInput(std::string(e.what()) + "\nRun with --help for more information.");
  }
  if (auto extra = app.remaining(); !extra.empty()) {
    // Listed as the user wrote them (CLI11's own message lists them backwards: we parse reversed).
    std::string list;
    for (const auto& x : extra) list += " " + x;
    throw BadInput("The following arguments were not expected:" + list + "\nRun with --help for more information.");
  }
  refuse_options_as_values(app);
  return Parsed::run;
}

// What --help ends with: the exit status is part of the interface (scripts and Slurm arrays test it).
constexpr const char* kHelpFooter =
    "\nExit status:\n"
    "  0  the run completed and no decisive law was rejected\n"
    "  1  the run completed and the family of decisive tests rejected a law (Holm at --alpha;\n"
    "     report.json \"rejected\", \"family\")\n"
    "  2  bad input or failure (the message names the option, key or file); the output directory\n"
    "     is left as it was\n"
    "\nManual: docs/README.md in the source tree (user guide, scene keys, report.json schema).\n";

// Presence, not emptiness: `--radius ''` is a bad value, not a missing option.
struct Given {
  const CLI::App& app;
  bool operator()(const char* name) const { return app.count(name) > 0; }
};

// An option that cannot apply to the scene's kind of run is an error naming it and why, never
// silently ignored.
[[noreturn]] void refuse(const std::string& option, const std::string& why) { throw BadInput(option + ": " + why); }

// The kind of run a scene is, for the options that apply to some kinds only.
struct OptionKind {
  bool bounce = false, mesh = false, radii = false;
  std::string text;  ///< named in refusals
};

OptionKind option_kind(const Scene& scene) {
  OptionKind k;
  k.bounce = scene.bounce.enabled, k.mesh = scene.mesh.has_value(), k.radii = scene.radii && !scene.mesh;
  k.text = k.bounce ? "a bounce run (experiment.kind = \"bounce\")"
           : k.mesh ? "a mesh body (body.kind = \"mesh\")"
                    : "a run with unequal asperity radii on a sphere (asperities.radius \"" +
                          std::string(k.radii && scene.radii->radii.kind == RadiusDistribution::Kind::lognormal
                                          ? "lognormal"
                                          : "levels") +
                          "\")";
  return k;
}

// --speed, --omega-x, --omega-y: the impact (a mesh body's bounce takes the spin as its start).
void apply_impact_options(Scene& scene, const RawOptions& r, const Given& given, const OptionKind& k) {
  auto& e = scene.ensemble;
  if (given("--speed")) {
    const double u = parse_positive("--speed", r["--speed"], "m/s");
    if (k.radii) refuse("--speed", k.text + " is analysed as contacts only (no impacts)");
    e.impact.enabled = true;
    scene.restitution_stats = true;
    e.impact.speed = u;
  }
  if (given("--omega-x")) e.impact.omega.x() = parse_real("--omega-x", r["--omega-x"]);
  if (given("--omega-y")) e.impact.omega.y() = parse_real("--omega-y", r["--omega-y"]);
  if (!given("--omega-x") && !given("--omega-y")) return;
  const std::string opt = given("--omega-x") ? "--omega-x" : "--omega-y";
  if (k.bounce && k.mesh) {  // a mesh body's bounce starts with experiment.Omega
    if (given("--omega-x")) scene.bounce.omega.x() = e.impact.omega.x();
    if (given("--omega-y")) scene.bounce.omega.y() = e.impact.omega.y();
  } else if (k.bounce) {
    refuse(opt, "not used by " + k.text + ": every sequence starts without spin (Omega = 0, Sec. V)");
  }
  if (k.radii) refuse(opt, k.text + " is analysed as contacts only (no impacts)");
  if (!e.impact.enabled && !(k.bounce && k.mesh))
    refuse("--omega-x/--omega-y", "need an impact: give --speed or a preset with impacts (fig4, fig5)");
}

// --speed as the bounce's first speed.
void apply_bounce_options(Scene& scene, const Given& given) {
  if (given("--speed") && scene.bounce.enabled) scene.bounce.speed = scene.ensemble.impact.speed, scene.ensemble.impact.enabled = false;
}

// --tangential MODEL[:KEY=VALUE[,KEY=VALUE]]: the items of material.tangential, which its one reader
// checks (scene_file.hpp); a value in decimal notation is a number, any other a name.
TangentialLaw tangential_option(const std::string& text) {
  const std::size_t colon = text.find(':');
  std::vector<OptionItem> items{{"model", text.substr(0, colon), std::nullopt}};
  for (std::size_t pos = colon; pos != std::string::npos;) {
    const std::size_t comma = text.find(',', pos + 1);
    const std::string item = text.substr(pos + 1, comma - pos - 1);
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      throw BadInput("--tangential: '" + text + "' has '" + item + "' where KEY=VALUE belongs (e.g. coulomb:mu=0.3,restitution=energetic)");
    const std::string value = item.substr(eq + 1);
    items.push_back({item.substr(0, eq), value, decimal_syntax(value) ? std::optional(parse_real("--tangential", value)) : std::nullopt});
    pos = comma;
  }
  return read_tangential_items(items, "--tangential");
}

void apply_tangential_option(Scene& scene, const RawOptions& r, const OptionKind& k) {
  const TangentialLaw law = tangential_option(r["--tangential"]);
  if (k.radii) refuse("--tangential", k.text + " is analysed as contacts only (no impacts)");
  auto& x = scene.ensemble.impact;
  if (!x.enabled && !scene.bounce.enabled)
    refuse("--tangential", "needs impacts: give --speed, or a preset with impacts (fig4, fig5) or bounces (fig6)");
  x.tangential = law;
  // eps_t belongs to the kinematic law; any other law leaves it at the paper's 1.
  x.eps_t = law.model == TangentialLaw::Model::kinematic ? law.eps_t : 1.0;
  scene.bounce.eps_t = x.eps_t;
}

// --checkpoint-every (streaming runs): run control, not scene data.
void apply_checkpoint_option(RunControl& control, const RawOptions& r, const Given& given) {
  if (!given("--checkpoint-every")) return;
  control.checkpoint_seconds = parse_real("--checkpoint-every", r["--checkpoint-every"]);
  if (!(control.checkpoint_seconds >= 0) || !std::isfinite(control.checkpoint_seconds))
    throw BadInput("--checkpoint-every: '" + r["--checkpoint-every"] + "' must be a finite number of seconds >= 0");
}

// --resume DIR: the checkpoint's own scene; only options that change no result (their rows) may
// come with it.
void check_resume_option(const RawOptions& r, const Given& given) {
  for (const OptionRow& row : option_rows())
    if (row.changes_result && given(std::string(long_flag(row)).c_str()))
      throw BadInput(std::string(long_flag(row)) + ": --resume continues the checkpoint's own scene; only " +
                     result_free_options() + " may be given with it");
  if (r["--resume"].empty()) throw BadInput("--resume: '' is not a directory name");
}

// --alpha on bounce runs; and the scene's name says when options changed the physics.
void apply_run_options(Scene& scene, const RawOptions& r, const Given& given) {
  if (given("--alpha") && scene.bounce.enabled)
    throw BadInput("--alpha: not used by a bounce run (experiment.kind = \"bounce\"): its fits describe, they "
                   "decide nothing (exit status 0)");
  if (!given("--scene") && !given("--resume") && r["--preset"] != scene.name) scene.name = r["--preset"];
  if (given("--asperities") || given("--radius") || given("--asperity-radius") || given("--mode") ||
      given("--speed") || given("--omega-x") || given("--omega-y") || given("--tangential"))
    scene.name += "+custom";
}

// An option's text as the value a scene file would hold, for the reader to check: a whole number as
// an integer (a seed above 2^63 - 1 as its digits, as scene files write it), another number as a
// float, any other text as a string.
// A float goes through parse_real: a value beyond a double's normal range is named as written.
decltype(SceneEdit::value) scene_value(const std::string& flag, const std::string& text) {
  if (!decimal_syntax(text)) return text;
  const long double v = std::strtold(text.c_str(), nullptr);
  if (v == std::floor(v) && text[0] == '+') return text;  // whole numbers are written without a sign
  if (v == std::floor(v) && std::fabs(v) < 0x1p63L) return static_cast<std::int64_t>(v);
  if (flag == "--seed" && text.find_first_not_of("0123456789") == std::string::npos) return text;
  return parse_real(flag, text);
}

// The options that are edits of one scene key (their rows' target), read with the scene. An edit
// removes the file's keys that it makes inapplicable: --asperities an areal_density; --mode sampled
// the explicit design's spheres, backend and kernel (unless given too).
std::vector<SceneEdit> scene_edits(const RawOptions& r, const Given& given) {
  std::vector<SceneEdit> edits;
  for (const char* flag : {"--radius", "--asperities", "--drops", "--mode", "--spheres", "--seed", "--backend", "--kernel", "--threads",
                           "--statistics", "--bins-log2", "--alpha", "--sequences", "--variant", "--plot-format"}) {
    if (!given(flag)) continue;
    const std::string_view f(flag);
    std::vector<std::string> replaces;
    if (f == "--asperities") replaces = {"areal_density"};
    if (f == "--mode" && r[f] == "sampled")
      for (const char* key : {"spheres", "backend", "kernel"})
        if (!given(("--" + std::string(key)).c_str())) replaces.emplace_back(key);
    edits.push_back({std::string(option_row(flag).target), flag, scene_value(flag, r[flag]), replaces});
  }
  if (given("--out")) edits.push_back({"outputs.dir", "--out", r["--out"], {}});  // a name, even "2024"
  if (r.no_plots) edits.push_back({"outputs.plots", "--no-plots", false, {}});
  // Every asperity gets this radius: "fixed" replaces a "levels"/"lognormal" distribution and its
  // [screening] (on a sphere the run becomes the paper's; a mesh stays a mesh run).
  if (given("--asperity-radius")) {
    edits.push_back({"asperities.radius.distribution", "--asperity-radius", std::string("fixed"), {"*", "[screening]"}});
    edits.push_back({"asperities.radius.value", "--asperity-radius", scene_value("--asperity-radius", r["--asperity-radius"]), {}});
  }
  return edits;
}

// The preset or scene file, then the options over it (docs/scenes.md), in this order: the kind of
// run is taken after --asperity-radius, which can turn a radii run into the paper's.
Scene scene_with_options(const RawOptions& r, const Given& given, const SceneLoader& load, RunControl& control) {
  if (given("--resume")) check_resume_option(r, given);
  const std::string path = given("--resume") ? (std::filesystem::path(r["--resume"]) / "checkpoint.toml").string() : r["--scene"];
  const std::vector<SceneEdit> edits = scene_edits(r, given);
  Scene scene = !given("--scene") && !given("--resume") ? preset(r["--preset"], edits) : load ? load(path, edits)
                                                                                        : load_scene(path, edits);
  if (given("--resume")) scene.out = r["--resume"], control.resume = true;
  const OptionKind k = option_kind(scene);
  apply_impact_options(scene, r, given, k);
  apply_bounce_options(scene, given);
  if (given("--tangential")) apply_tangential_option(scene, r, k);
  apply_checkpoint_option(control, r, given);
  apply_run_options(scene, r, given);
  return scene;  // the cross-key rules: plan() (plan.hpp), once per run
}

}  // namespace

Options parse_command_line(std::span<const std::string> args, const SceneLoader& load) {
  CLI::App app{"validate-geometry: contact statistics of explicit rough spheres against the laws of "
               "Gunkelmann, Montaine & Poeschel, PRE 89, 022205 (2014). Lengths in metres.",
               "validate-geometry"};
  RawOptions raw;
  add_options(app, raw);
  app.set_version_flag("--version", std::string("validate-geometry ") + ASPERITY_VERSION);
  app.footer(kHelpFooter);
  Options o;
  refuse_empty_equals(args);
  switch (parse_arguments(app, args)) {
    case Parsed::help:
      o.help = true;
      o.help_text = app.help();
      return o;
    case Parsed::version:
      o.help = true;  // printed like --help: exit 0, nothing else done
      o.help_text = std::string("validate-geometry ") + ASPERITY_VERSION + "\n";
      return o;
    case Parsed::run:
      break;
  }
  try {
    o.scene = scene_with_options(raw, Given{app}, load, o.control);
    o.quiet = raw.quiet;
    // Acting on streaming statistics only: refused by validate-geometry when the plan keeps raw
    // samples (statistics auto streams above 2^25 drops without impacts).
    for (const char* opt : {"--checkpoint-every", "--bins-log2"})
      if (app.count(opt) > 0) o.streaming_only.emplace_back(opt);
    return o;
  } catch (const BadInput&) {
    throw;
  } catch (const std::exception& ex) {  // the library's validation names field and value
    throw BadInput(ex.what());
  }
}

}  // namespace asperity::cli
