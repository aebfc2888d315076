#include "app/cli/options.hpp"

#include <CLI/CLI.hpp>

#include <cmath>

#include "asperity/app/scene_file.hpp"
#include <cstdint>
#include <vector>

namespace asperity::cli {

namespace {

// Every number goes through here: the whole text must parse and be finite.
double parse_real(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;  // not a number, or out of the range of double
  }
  if (text.empty() || used != text.size()) throw BadInput(option + ": '" + text + "' is not a number");
  if (!std::isfinite(v)) throw BadInput(option + ": '" + text + "' must be finite");
  return v;
}

double parse_positive(const std::string& option, const std::string& text, const char* unit = "metres") {
  const double v = parse_real(option, text);
  if (v <= 0) throw BadInput(option + ": '" + text + "' must be > 0 (" + unit + ")");
  return v;
}

// Counts may be written as integers or in exact scientific notation ("1e5").
std::uint64_t parse_count(const std::string& option, const std::string& text, double min = 1) {
  const double v = parse_real(option, text);
  if (v < min) throw BadInput(option + ": '" + text + "' must be >= " + (min == 0 ? "0" : "1"));
  if (v != std::floor(v)) throw BadInput(option + ": '" + text + "' must be a whole number");
  if (v > 9.007199254740992e15) throw BadInput(option + ": '" + text + "' is too large");
  return static_cast<std::uint64_t>(v);
}

}  // namespace

Options parse_command_line(std::span<const std::string> args, const SceneLoader& load) {
  CLI::App app{"validate-geometry: contact statistics of explicit rough spheres against the laws of "
               "Gunkelmann, Montaine & Poeschel, PRE 89, 022205 (2014). Lengths in metres.",
               "validate-geometry"};
  std::string preset_name = "fig3", asperities, radius, asperity_radius, drops, spheres, mode, backend, seed, out;
  std::string threads, alpha;
  bool no_plots = false, quiet = false;
  std::string scene_file;
  auto* preset_opt = app.add_option("--preset", preset_name, "scene preset: fig3 (default), fig3-fixed, fig4, fig5, fig6");
  app.add_option("--scene", scene_file, "scene file (TOML, see README \"Scenes\"); the options below override it")
      ->excludes(preset_opt);
  app.add_option("--asperities,-N", asperities, "number of asperities N (>= 1)");
  app.add_option("--radius", radius, "central sphere radius R [m]");
  app.add_option("--asperity-radius", asperity_radius, "asperity radius a [m], 0 < a < R");
  app.add_option("--drops", drops, "number of drops (fixed: spheres x rotations)");
  app.add_option("--mode", mode, "fresh (a new sphere per drop) or fixed (K spheres x M rotations)");
  app.add_option("--spheres,-K", spheres, "number of explicit spheres K (fixed mode)");
  app.add_option("--seed", seed, "random seed (results are identical for any thread count)");
  app.add_option("--backend", backend, "contact query: brute, kdtree, cgal, fcl, grid (fixed mode)");
  app.add_option("--threads", threads, "OpenMP threads (0 = all)");
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

  try {
    // Presence, not emptiness: `--radius ''` is a bad value, not a missing option.
    auto given = [&](const char* name) { return app.count(name) > 0; };
    Scene scene = !given("--scene") ? preset(preset_name) : load ? load(scene_file) : load_scene(scene_file);
    auto& e = scene.ensemble;
    // Options override the file (README "Scenes"). An option that cannot apply to the scene's
    // kind of run is an error naming it and why, never silently ignored.
    auto refuse = [](const std::string& option, const std::string& why) { throw BadInput(option + ": " + why); };
    if (given("--asperities")) e.sphere.asperities = parse_count("--asperities", asperities);
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
      e.drops = parse_count("--drops", drops);
      if (bounce) refuse("--drops", "not used by " + kind + ", which counts bounce sequences: use --sequences");
    }
    if (given("--mode")) {
      e.mode = parse_mode(mode);
      // A backend the file chose for its explicit spheres does not apply to fresh drops.
      if (e.mode == Mode::fresh && !given("--backend")) scene.backend_auto = true;
      if (bounce) refuse("--mode", "not used by " + kind + ": every sequence bounces its own sphere");
      if (mesh && e.mode != Mode::fixed)
        refuse("--mode", "'" + mode + "': " + kind + " runs explicit bodies x rotations: only \"fixed\"");
      if (radii && e.mode != Mode::fresh)
        refuse("--mode", "'" + mode + "': " + kind + " draws fresh spheres and screens [screening] bodies: only "
                         "\"fresh\" (or give --asperity-radius for the paper's equal radii)");
    }
    if (given("--spheres")) {
      e.spheres = parse_count("--spheres", spheres);
      if ((bounce && !mesh) || radii)
        refuse("--spheres", "not used by " + kind + (radii ? " (its explicit spheres are screening.bodies of the scene file)" : ""));
      if (!mesh && e.mode != Mode::fixed)
        refuse("--spheres", "only for fixed mode (explicit spheres x rotations); fresh mode draws a new sphere per drop: "
                            "add --mode fixed");
    }
    if (given("--seed")) {
      std::size_t used = 0;
      try {
        e.seed = std::stoull(seed, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (seed.empty() || used != seed.size() || seed.front() == '-')
        throw BadInput("--seed: '" + seed + "' is not a non-negative integer");
    }
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
      if (e.mode != Mode::fixed)
        refuse("--backend", "only for fixed mode (explicit spheres); fresh mode queries no index (the lowest asperities "
                            "are drawn exactly): add --mode fixed");
    }
    if ((given("--variant") || given("--sequences")) && !scene.bounce.enabled)
      throw BadInput("--variant/--sequences need a bounce run: --preset fig6");
    if (scene.bounce.enabled) {
      if (given("--speed")) scene.bounce.speed = e.impact.speed, e.impact.enabled = false;
      if (given("--sequences")) scene.bounce.sequences = parse_count("--sequences", sequences);
      if (given("--variant")) {
        scene.bounce.variants.clear();
        std::size_t pos = 0;
        do {
          const std::size_t comma = variants.find(',', pos);
          scene.bounce.variants.push_back(parse_bounce_variant(variants.substr(pos, comma - pos)));
          pos = comma == std::string::npos ? comma : comma + 1;
        } while (pos != std::string::npos);
      }
    }
    if (given("--threads")) {
      const std::uint64_t t = parse_count("--threads", threads, 0);
      if (t > std::uint64_t(kMaxThreads))
        throw BadInput("--threads: '" + threads + "' must be <= " + std::to_string(kMaxThreads));
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
    if (!given("--scene") && preset_name != scene.name) scene.name = preset_name;
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
