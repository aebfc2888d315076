// validate-geometry: run a scene of explicit rough spheres, compare the contact statistics with
// the paper's laws and the exact finite-N laws, print a table, write report.json and figures.
// Exit status: 0 no law rejected, 1 a law rejected, 2 bad input or an output that cannot be written.
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>

#include "asperity/plot.hpp"
#include "asperity/report.hpp"
#include "asperity/scene.hpp"

namespace fs = std::filesystem;
using namespace asperity;

namespace {

struct BadInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

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
std::uint64_t parse_count(const std::string& option, const std::string& text) {
  const double v = parse_real(option, text);
  if (v < 1) throw BadInput(option + ": '" + text + "' must be >= 1");
  if (v != std::floor(v)) throw BadInput(option + ": '" + text + "' must be a whole number");
  if (v > 9.007199254740992e15) throw BadInput(option + ": '" + text + "' is too large");
  return static_cast<std::uint64_t>(v);
}

// Creates the directory if needed and proves it writable before any work starts.
void prepare_output(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) throw BadInput("--out: cannot create directory '" + dir.string() + "'");
  const fs::path probe = dir / (".write-test." + std::to_string(::getpid()));
  std::FILE* f = std::fopen(probe.c_str(), "w");
  if (!f) throw BadInput("--out: directory '" + dir.string() + "' is not writable");
  std::fclose(f);
  fs::remove(probe, ec);
}

class ProgressLine {
 public:
  explicit ProgressLine(bool enabled) : on_(enabled), tty_(::isatty(2)) {}
  void operator()(std::uint64_t done, std::uint64_t total) {
    if (!on_) return;
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (elapsed < 1.0) return;  // short runs stay quiet
    const int pct = static_cast<int>(100.0 * double(done) / double(total));
    if (tty_) {
      if (std::chrono::duration<double>(now - last_).count() < 0.25 && done < total) return;
      std::fprintf(stderr, "\r  drops: %3d%% (%llu / %llu), %.1f s", pct, (unsigned long long)done,
                   (unsigned long long)total, elapsed);
      shown_ = true;
    } else if (pct >= next_pct_) {
      std::fprintf(stderr, "  drops: %d%% (%llu / %llu), %.1f s\n", pct, (unsigned long long)done,
                   (unsigned long long)total, elapsed);
      next_pct_ = pct / 10 * 10 + 10;
    }
    last_ = now;
  }
  void finish() {
    if (shown_) std::fprintf(stderr, "\n");
  }

 private:
  bool on_, tty_;
  bool shown_ = false;
  int next_pct_ = 10;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now(), last_{};
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"validate-geometry: contact statistics of explicit rough spheres against the laws of "
               "Gunkelmann, Montaine & Poeschel, PRE 89, 022205 (2014). Lengths in metres."};
  std::string preset_name = "fig3", asperities, radius, asperity_radius, drops, spheres, mode, backend, seed, out;
  int threads = 0;
  double alpha = 0.01;
  bool no_plots = false, quiet = false;
  app.add_option("--preset", preset_name, "scene preset: fig3 (default), fig3-fixed, fig4, fig5, fig6");
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
  app.add_option("--variant", variants, "bounce runs (fig6): comma list of paper, paper-printed33, random-orientation, dynamic");
  app.add_option("--sequences", sequences, "bounce runs (fig6): bounce sequences per variant");
  app.add_flag("--no-plots", no_plots, "do not write PNG figures");
  app.add_flag("--quiet,-q", quiet, "print no progress");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }

  Scene scene;
  try {
    // Presence, not emptiness: `--radius ''` is a bad value, not a missing option.
    auto given = [&](const char* name) { return app.count(name) > 0; };
    scene = preset(preset_name);
    auto& e = scene.ensemble;
    if (given("--asperities")) e.sphere.asperities = parse_count("--asperities", asperities);
    if (given("--radius")) e.sphere.radius = parse_positive("--radius", radius);
    if (given("--asperity-radius")) e.sphere.asperity_radius = parse_positive("--asperity-radius", asperity_radius);
    if (given("--drops")) e.drops = parse_count("--drops", drops);
    if (given("--spheres")) e.spheres = parse_count("--spheres", spheres);
    if (given("--seed")) {
      std::size_t used = 0;
      try {
        e.seed = std::stoull(seed, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (seed.empty() || used != seed.size() || seed.front() == '-') throw BadInput("--seed: '" + seed + "' is not a non-negative integer");
    }
    if (given("--mode")) e.mode = parse_mode(mode);
    if (given("--speed")) {
      e.impact.enabled = true;
      e.impact.speed = parse_positive("--speed", speed, "m/s");
    }
    if (given("--omega-x")) e.impact.omega.x() = parse_real("--omega-x", omega_x);
    if (given("--omega-y")) e.impact.omega.y() = parse_real("--omega-y", omega_y);
    if ((given("--omega-x") || given("--omega-y")) && !e.impact.enabled)
      throw BadInput("--omega-x/--omega-y need an impact: give --speed or a preset with impacts (fig4, fig5)");
    if (given("--backend")) e.backend = parse_backend(backend);
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
    if (threads < 0) throw BadInput("--threads: '" + std::to_string(threads) + "' must be >= 0");
    e.threads = threads;
    if (!std::isfinite(alpha) || !(alpha > 0 && alpha < 1))
      throw BadInput("--alpha: '" + std::to_string(alpha) + "' must be in (0, 1)");
    scene.alpha = alpha;
    scene.plots = !no_plots;
    if (given("--out")) {
      if (out.empty()) throw BadInput("--out: '' is not a directory name");
      scene.out = out;
    }
    if (preset_name != scene.name) scene.name = preset_name;
    if (given("--asperities") || given("--radius") || given("--asperity-radius") || given("--mode") ||
        given("--speed") || given("--omega-x") || given("--omega-y"))
      scene.name += "+custom";
    validate(scene);
    if (scene.plots && !plotting_available())
      throw BadInput("gnuplot with the pngcairo terminal is needed for figures (run scripts/setup), or pass --no-plots");
    prepare_output(scene.out);
  } catch (const std::exception& ex) {
    std::cerr << "validate-geometry: error: " << ex.what() << "\n";
    return 2;
  }

  std::vector<fs::path> written;
  if (scene.bounce.enabled) {  // Sec. V bouncing ball (bounce.hpp)
    try {
      const auto& e = scene.ensemble;
      const auto reports = run_bounce_experiment(e.sphere, scene.bounce, e.seed, e.threads, quiet ? nullptr : &std::cerr);
      std::vector<std::string> plots;
      if (scene.plots) plots = write_bounce_plots(scene.out, reports);
      for (const auto& p : plots) written.push_back(scene.out / p);
      std::cout << format_bounce_table(reports);
      const auto comparisons = compare_bounce_variants(reports);
      for (const auto& c : comparisons)
        std::cout << "KS " << to_string(c.a) << " vs " << to_string(c.b) << ", " << c.by << " [" << c.lo << ", " << c.hi
                  << "]: D = " << c.ks.D << ", p = " << c.ks.p << "\n";
      write_file_atomic(scene.out / "report.json",
                        bounce_to_json(scene.name, e.sphere, scene.bounce, e.seed, reports, plots, comparisons));
      std::cout << "wrote " << (scene.out / "report.json").string();
      for (const auto& p : plots) std::cout << ", " << p;
      std::cout << "\n";
      return 0;
    } catch (const std::exception& ex) {
      std::error_code ec;
      for (const auto& p : written) fs::remove(p, ec);
      std::cerr << "validate-geometry: error: " << ex.what() << "\n";
      return 2;
    }
  }
  try {
    using Clock = std::chrono::steady_clock;
    ProgressLine progress(!quiet);
    const auto samples = run_contact_ensemble(scene.ensemble, std::ref(progress));
    progress.finish();
    auto t0 = Clock::now();
    GeometryReport report = analyse(scene, samples);
    report.timings_s.emplace_back("analysis", std::chrono::duration<double>(Clock::now() - t0).count());
    if (scene.plots) {
      t0 = Clock::now();
      report.plots = write_plots(scene.out, scene, samples);
      for (const auto& p : report.plots) written.push_back(scene.out / p);
      report.timings_s.emplace_back("plots", std::chrono::duration<double>(Clock::now() - t0).count());
    }
    std::cout << format_table(report);
    write_file_atomic(scene.out / "report.json", to_json(report));
    std::cout << "wrote " << (scene.out / "report.json").string();
    for (const auto& p : report.plots) std::cout << ", " << p;
    std::cout << "\n";
    return report.rejected() ? 1 : 0;
  } catch (const std::exception& ex) {
    std::error_code ec;
    for (const auto& p : written) fs::remove(p, ec);
    std::cerr << "validate-geometry: error: " << ex.what() << "\n";
    return 2;
  }
}
