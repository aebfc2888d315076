#include "app/cli/options.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "asperity/app/scene_file.hpp"

namespace asperity::cli {

namespace {

constexpr std::uint64_t kMaxAsperities = (std::uint64_t{1} << 32) - 1;  // geometry.hpp: N < 2^32
constexpr std::uint64_t kMaxDrops = std::uint64_t{1} << 31;              // ensemble.hpp

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

std::string bound_text(std::uint64_t v) {
  std::string s = std::to_string(v);
  for (int k = 16; k < 64; ++k) {
    const std::uint64_t p = std::uint64_t{1} << k;
    if (v == p) return s + " (2^" + std::to_string(k) + ")";
    if (v == p - 1) return s + " (2^" + std::to_string(k) + " - 1)";
  }
  if (v == ~std::uint64_t{0}) return s + " (2^64 - 1)";
  return s;
}

// Counts are integers: digits, or exact scientific notation ("1e5", "2.5e3"); no sign, spaces,
// hexadecimal or rounding. The value must lie in [lo, hi], named in the message.
std::uint64_t parse_count(const std::string& option, const std::string& text, std::uint64_t lo, std::uint64_t hi) {
  const std::string got = option + ": '" + text + "' ";
  const bool negative = !text.empty() && text[0] == '-';
  if (names_infinity_or_nan(text)) throw BadInput(got + "must be a finite whole number");
  if (!decimal_syntax(text) || text[0] == '+')
    throw BadInput(got + "is not a whole number (write digits, e.g. 1000 or 1e3)");
  if (negative) throw BadInput(got + "must be >= " + std::to_string(lo));
  // Exact: mantissa digits x 10^exponent.
  std::string mant;
  long long exp10 = 0;
  std::size_t i = 0;
  for (; i < text.size() && text[i] != 'e' && text[i] != 'E'; ++i) {
    if (text[i] == '.') continue;
    mant += text[i];
  }
  const std::size_t dot = text.find('.');
  const std::size_t epos = text.find_first_of("eE");
  if (dot != std::string::npos) exp10 -= static_cast<long long>((epos == std::string::npos ? text.size() : epos) - dot - 1);
  if (epos != std::string::npos) {
    const std::string e = text.substr(epos + 1);
    if (e.size() > 6) throw BadInput(got + (e[0] == '-' ? "must be a whole number >= " + std::to_string(lo) : "is too large: must be <= " + bound_text(hi)));
    exp10 += std::stoll(e);
  }
  mant.erase(0, std::min(mant.find_first_not_of('0'), mant.size()));
  if (mant.empty()) mant = "0";
  while (exp10 < 0 && mant.size() > 1 && mant.back() == '0') mant.pop_back(), ++exp10;
  if (mant == "0") exp10 = 0;
  if (exp10 < 0) throw BadInput(got + "must be a whole number");
  if (static_cast<long long>(mant.size()) + exp10 > 20) throw BadInput(got + "is too large: must be <= " + bound_text(hi));
  constexpr std::uint64_t kMax = ~std::uint64_t{0};
  std::uint64_t v = 0;
  auto push = [&](unsigned d) {
    if (v > (kMax - d) / 10) throw BadInput(got + "is too large: must be <= " + bound_text(hi));
    v = v * 10 + d;
  };
  for (char c : mant) push(static_cast<unsigned>(c - '0'));
  for (long long k = 0; k < exp10; ++k) push(0);
  if (v > hi) throw BadInput(got + "must be <= " + bound_text(hi));
  if (v < lo) throw BadInput(got + "must be >= " + std::to_string(lo));
  return v;
}

}  // namespace

Options parse_command_line(std::span<const std::string> args, const SceneLoader& load) {
  CLI::App app{"validate-geometry: contact statistics of explicit rough spheres against the laws of "
               "Gunkelmann, Montaine & Poeschel, PRE 89, 022205 (2014). Lengths in metres.",
               "validate-geometry"};
  std::string preset_name = "fig3", asperities, radius, asperity_radius, drops, spheres, mode, backend, seed, out;
  std::string threads, alpha, statistics, bins_log2, checkpoint_every, resume;
  bool no_plots = false, quiet = false;
  std::string scene_file;
  auto* preset_opt = app.add_option("--preset", preset_name, "scene preset: fig3 (default), fig3-fixed, fig4, fig5, fig6");
  app.add_option("--scene", scene_file, "scene file (TOML, see README \"Scenes\"); the options below override it")
      ->excludes(preset_opt);
  app.add_option("--asperities,-N", asperities, "number of asperities N (>= 1)");
  app.add_option("--radius", radius, "central sphere radius R [m]");
  app.add_option("--asperity-radius", asperity_radius, "asperity radius a [m], 0 < a < R");
  app.add_option("--drops", drops, "number of drops (explicit: spheres x rotations)");
  app.add_option("--mode", mode,
                 "explicit (default: K explicit spheres x M rotations, contacts by spatial query) or sampled (drawn "
                 "from the exact finite-N law of the lowest asperity; no geometry); fixed and fresh are read as explicit");
  app.add_option("--spheres,-K", spheres, "number of explicit spheres K (explicit design; default: from the error budget)");
  app.add_option("--seed", seed, "random seed (results are identical for any thread count)");
  app.add_option("--backend", backend, "contact query: brute, kdtree, cgal, fcl, grid (explicit design)");
  app.add_option("--threads", threads, "OpenMP threads (0 = all)");
  app.add_option("--statistics", statistics,
                 "auto (default: streaming above 2^25 drops without impacts), raw (every drop kept: exact KS, figures "
                 "of every quantity) or streaming (integer histograms, memory independent of the drops; contact only)");
  app.add_option("--bins-log2", bins_log2, "streaming: 2^k fine bins per quantity, k in [10, 24] (default 16)");
  app.add_option("--checkpoint-every", checkpoint_every,
                 "streaming: seconds between checkpoints in --out (default 300; 0: only on SIGINT/SIGTERM)");
  auto* resume_opt = app.add_option("--resume", resume,
                                    "continue the interrupted streaming run whose checkpoint is in DIR (its scene; only "
                                    "--threads, --quiet, --no-plots, --checkpoint-every may be given)");
  resume_opt->excludes(preset_opt);
  app.add_option("--alpha", alpha, "significance level of each test, in (0,1)");
  app.add_option("--out", out, "output directory for report.json and figures");
  std::string speed, omega_x, omega_y;
  app.add_option("--speed", speed, "impact: approach speed -V.n [m/s] (enables the impact stage)");
  app.add_option("--omega-x", omega_x, "impact: spin Omega_x before [rad/s]");
  app.add_option("--omega-y", omega_y, "impact: spin Omega_y before [rad/s]");
  std::string variants, sequences;
  app.add_option("--variant", variants, "bounce runs (fig6): comma list of paper, paper-printed33, paper-corrected28, random-orientation, dynamic");
  app.add_option("--sequences", sequences, "bounce runs (fig6): bounce sequences per variant");
  app.add_flag("--no-plots", no_plots, "do not write PNG figures");
  app.add_flag("--quiet,-q", quiet, "print no progress");

  Options o;
  // "--out=" (nothing after '='): CLI11 would take the next argument as the value.
  for (const auto& a : args) {
    if (a == "--") break;
    if (a.size() > 3 && a.compare(0, 2, "--") == 0 && a.back() == '=' && a.find('=') == a.size() - 1)
      throw BadInput(a.substr(0, a.size() - 1) + ": '' (an empty value after '=') is not a value; write " +
                     a.substr(0, a.size() - 1) + "=VALUE or " + a.substr(0, a.size() - 1) + " VALUE");
  }
  app.allow_extras();
  try {
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 consumes from the back
    app.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    o.help = true;
    o.help_text = app.help();
    return o;
  } catch (const CLI::ParseError& e) {
    throw BadInput(std::string(e.what()) + "\nRun with --help for more information.");
  }
  if (auto extra = app.remaining(); !extra.empty()) {
    // Listed as the user wrote them (CLI11's own message lists them backwards: we parse reversed).
    std::string list;
    for (const auto& x : extra) list += " " + x;
    throw BadInput("The following arguments were not expected:" + list + "\nRun with --help for more information.");
  }

  try {
    // Presence, not emptiness: `--radius ''` is a bad value, not a missing option.
    auto given = [&](const char* name) { return app.count(name) > 0; };
    if (given("--resume")) {
      for (const char* o : {"--scene", "--asperities", "--radius", "--asperity-radius", "--drops", "--mode", "--spheres",
                            "--seed", "--backend", "--alpha", "--out", "--speed", "--omega-x", "--omega-y", "--variant",
                            "--sequences", "--statistics", "--bins-log2"})
        if (given(o))
          throw BadInput(std::string(o) + ": --resume continues the checkpoint's own scene; only --threads, --quiet, "
                                          "--no-plots and --checkpoint-every may be given with it");
      if (resume.empty()) throw BadInput("--resume: '' is not a directory name");
    }
    const std::string scene_path = given("--resume") ? (std::filesystem::path(resume) / "checkpoint.toml").string() : scene_file;
    Scene scene = !given("--scene") && !given("--resume") ? preset(preset_name)
                  : load                                 ? load(scene_path)
                                                         : load_scene(scene_path);
    if (given("--resume")) scene.out = resume, scene.resume = true;
    auto& e = scene.ensemble;
    // Options override the file (README "Scenes"). An option that cannot apply to the scene's
    // kind of run is an error naming it and why, never silently ignored.
    auto refuse = [](const std::string& option, const std::string& why) { throw BadInput(option + ": " + why); };
    if (given("--asperities")) e.sphere.asperities = parse_count("--asperities", asperities, 1, kMaxAsperities);
    if (given("--radius")) {
      const double r = parse_positive("--radius", radius);
      if (scene.mesh)
        refuse("--radius", "a mesh body's size is its mesh file x body.scale (body.kind = \"mesh\"); --radius is the "
                           "radius of a sphere body");
      e.sphere.radius = r;
    }
    if (given("--asperity-radius")) {
      // Every asperity gets this radius: the option replaces a "levels"/"lognormal" distribution of
      // the file by "fixed" (on a sphere the run becomes the paper's; a mesh stays a mesh run).
      e.sphere.asperity_radius = parse_positive("--asperity-radius", asperity_radius);
      scene.radii.reset();
    }
    const bool bounce = scene.bounce.enabled, mesh = scene.mesh.has_value(), radii = scene.radii && !scene.mesh;
    const std::string kind = bounce ? "a bounce run (experiment.kind = \"bounce\")"
                             : mesh ? "a mesh body (body.kind = \"mesh\")"
                                    : "a run with unequal asperity radii on a sphere (asperities.radius \"" +
                                          std::string(radii && scene.radii->radii.kind == RadiusDistribution::Kind::lognormal
                                                          ? "lognormal"
                                                          : "levels") +
                                          "\")";
    if (given("--drops")) {
      e.drops = parse_count("--drops", drops, 1, kMaxStreamingDrops);  // > 2^31: streaming only (validate)
      if (bounce) refuse("--drops", "not used by " + kind + ", which counts bounce sequences: use --sequences");
    }
    if (given("--mode")) {
      e.mode = parse_mode(mode);
      // Earlier names: "fixed" = explicit; "fresh" = explicit (with a note), for unequal radii their sampler.
      scene.legacy_mode = is_legacy_mode(mode) && !radii && !mesh && !bounce ? mode : std::string();
      if (radii && mode == "fresh") e.mode = Mode::sampled;
      // A backend the file chose for its explicit spheres does not apply to sampled drops.
      if (e.mode == Mode::sampled && !given("--backend")) scene.backend_auto = true;
      if (bounce) refuse("--mode", "not used by " + kind + ": every sequence bounces its own sphere");
      if (mesh && e.mode != Mode::explicit_spheres)
        refuse("--mode", "'" + mode + "': " + kind + " runs explicit bodies x rotations: only \"explicit\"");
      if (radii && e.mode != Mode::sampled)
        refuse("--mode", "'" + mode + "': " + kind + " draws from its exact sampler and screens [screening] bodies: only "
                         "\"sampled\" (or give --asperity-radius for the paper's equal radii)");
    }
    if (given("--spheres")) {
      e.spheres = parse_count("--spheres", spheres, 1, kMaxDrops);
      scene.spheres_auto = false;
      if ((bounce && !mesh) || radii)
        refuse("--spheres", "not used by " + kind + (radii ? " (its explicit spheres are screening.bodies of the scene file)" : ""));
      if (!mesh && e.mode != Mode::explicit_spheres)
        refuse("--spheres", "only for the explicit design (explicit spheres x rotations); sampled drops build no sphere: "
                            "add --mode explicit");
    }
    if (given("--seed")) e.seed = parse_count("--seed", seed, 0, ~std::uint64_t{0});
    if (given("--speed")) {
      const double u = parse_positive("--speed", speed, "m/s");
      if (radii) refuse("--speed", kind + " is analysed as contacts only (no impacts)");
      e.impact.enabled = true;
      scene.restitution_stats = true;
      e.impact.speed = u;
    }
    if (given("--omega-x")) e.impact.omega.x() = parse_real("--omega-x", omega_x);
    if (given("--omega-y")) e.impact.omega.y() = parse_real("--omega-y", omega_y);
    if (given("--omega-x") || given("--omega-y")) {
      const std::string opt = given("--omega-x") ? "--omega-x" : "--omega-y";
      if (bounce && mesh) {  // a mesh body's bounce starts with experiment.Omega
        if (given("--omega-x")) scene.bounce.omega.x() = e.impact.omega.x();
        if (given("--omega-y")) scene.bounce.omega.y() = e.impact.omega.y();
      } else if (bounce) {
        refuse(opt, "not used by " + kind + ": every sequence starts without spin (Omega = 0, Sec. V)");
      }
      if (radii) refuse(opt, kind + " is analysed as contacts only (no impacts)");
      if (!e.impact.enabled && !(bounce && mesh))
        refuse("--omega-x/--omega-y", "need an impact: give --speed or a preset with impacts (fig4, fig5)");
    }
    if (given("--backend")) {
      e.backend = parse_backend(backend);
      scene.backend_auto = false;
      if (bounce || mesh || radii)
        refuse("--backend", "not used by " + kind + (bounce ? "" : ", which queries the exact support tree"));
      if (e.mode != Mode::explicit_spheres)
        refuse("--backend", "only for the explicit design (explicit spheres); sampled drops query no index (the lowest "
                            "asperities are drawn from the exact law): add --mode explicit");
    }
    if ((given("--variant") || given("--sequences")) && !scene.bounce.enabled)
      throw BadInput("--variant/--sequences need a bounce run: --preset fig6");
    if (scene.bounce.enabled) {
      if (given("--speed")) scene.bounce.speed = e.impact.speed, e.impact.enabled = false;
      if (given("--sequences")) scene.bounce.sequences = parse_count("--sequences", sequences, 1, kMaxDrops);
      if (given("--variant")) {
        scene.bounce.variants.clear();
        std::size_t pos = 0;
        do {
          const std::size_t comma = variants.find(',', pos);
          const BounceVariant v = parse_bounce_variant(variants.substr(pos, comma - pos));
          if (std::find(scene.bounce.variants.begin(), scene.bounce.variants.end(), v) != scene.bounce.variants.end())
            throw BadInput("--variant: '" + std::string(to_string(v)) + "' is given twice in '" + variants +
                           "' (a variant compared with itself decides nothing)");
          scene.bounce.variants.push_back(v);
          pos = comma == std::string::npos ? comma : comma + 1;
        } while (pos != std::string::npos);
      }
    }
    if (given("--checkpoint-every")) {
      scene.checkpoint_seconds = parse_real("--checkpoint-every", checkpoint_every);
      if (!(scene.checkpoint_seconds >= 0) || !std::isfinite(scene.checkpoint_seconds))
        throw BadInput("--checkpoint-every: '" + checkpoint_every + "' must be a finite number of seconds >= 0");
    }
    if (given("--statistics")) e.statistics = parse_statistics(statistics);
    if (given("--bins-log2")) e.bins_log2 = static_cast<unsigned>(parse_count("--bins-log2", bins_log2, 10, 24));
    if ((given("--statistics") || given("--bins-log2")) && (bounce || mesh || radii))
      refuse(given("--statistics") ? "--statistics" : "--bins-log2", "not used by " + kind + " (sphere contact runs only)");
    if (given("--threads")) {
      const std::uint64_t t = parse_count("--threads", threads, 0, std::uint64_t(kMaxThreads));
      e.threads = static_cast<int>(t);
    }
    if (given("--alpha")) {
      const double a = parse_real("--alpha", alpha);
      if (!(a > 0 && a < 1)) throw BadInput("--alpha: '" + alpha + "' must be in (0, 1)");
      if (scene.bounce.enabled)
        throw BadInput("--alpha: not used by a bounce run (experiment.kind = \"bounce\"): its fits describe, they "
                       "decide nothing (exit status 0)");
      scene.alpha = a;
    }
    if (no_plots) scene.plots = false;
    if (given("--out")) {
      if (out.empty()) throw BadInput("--out: '' is not a directory name");
      scene.out = out;
    }
    if (!given("--scene") && !given("--resume") && preset_name != scene.name) scene.name = preset_name;
    if (given("--asperities") || given("--radius") || given("--asperity-radius") || given("--mode") ||
        given("--speed") || given("--omega-x") || given("--omega-y"))
      scene.name += "+custom";
    validate(scene);
    o.scene = std::move(scene);
    o.quiet = quiet;
    return o;
  } catch (const BadInput&) {
    throw;
  } catch (const std::exception& ex) {  // the library's validation names field and value
    throw BadInput(ex.what());
  }
}

}  // namespace asperity::cli
