// validate-geometry: run a scene of explicit rough spheres, compare the contact statistics with
// the paper's laws and the exact finite-N laws, print a table, write report.json and figures.
// Exit status: 0 no law rejected (skipped laws: a warning), 1 a law rejected, 2 bad input or an
// output that cannot be written.
#include <malloc.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <new>
#include <sstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "asperity/app/plot.hpp"
#include "asperity/app/report.hpp"
#include "asperity/app/run.hpp"
#include "asperity/app/scene.hpp"
#include "app/cli/options.hpp"
#include "app/cli/progress_line.hpp"

namespace fs = std::filesystem;
using namespace asperity;
using asperity::cli::BadInput;
using asperity::cli::ProgressLine;

namespace {

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

// Explicit spheres (fixed mode) hold 24 bytes per centre plus the index, one sphere per thread
// when many small spheres run in parallel; per-drop samples take ~50 bytes. A run that cannot fit
// in physical memory is refused up front, naming the value, instead of dying in the OOM killer.
void check_memory(const EnsembleConfig& e) {
  const double pages = double(::sysconf(_SC_PHYS_PAGES)), page = double(::sysconf(_SC_PAGESIZE));
  if (!(pages > 0 && page > 0)) return;  // unknown: let the allocation decide
  const double ram = pages * page;
  double need = 64.0 * double(e.drops);
  if (e.mode == Mode::explicit_spheres) need += 2.0 * 24.0 * double(e.sphere.asperities);  // centres + index, at least
  if (need > ram) {
    std::ostringstream os;
    os << "--asperities " << e.sphere.asperities << " with --drops " << e.drops << " (" << to_string(e.mode)
       << " mode) needs at least " << std::setprecision(3) << need / 1e9 << " GB, more than this machine's "
       << ram / 1e9 << " GB";
    throw BadInput(os.str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  // Explicit runs build and drop K spheres and indexes of a few MB each: keep freed memory in the
  // heap instead of returning it to the kernel, so that the next sphere does not page-fault its
  // memory in again (halved the index stage of fig3 on the loaded 2-core machine; bench/RESULTS.md).
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  Scene scene;
  bool quiet = false;
  try {
    const std::vector<std::string> args(argv + 1, argv + argc);
    const cli::Options o = cli::parse_command_line(args);
    if (o.help) {
      std::cout << o.help_text;
      return 0;
    }
    scene = o.scene;
    quiet = o.quiet;
    if (scene.plots && !plotting_available())
      throw BadInput("gnuplot with the pngcairo terminal is needed for figures (run scripts/setup), or pass --no-plots");
    check_memory(scene.ensemble);
    prepare_output(scene.out);
  } catch (const std::exception& ex) {
    std::cerr << "validate-geometry: error: " << ex.what() << "\n";
    return 2;
  }

  // Every kind of run (sphere, unequal radii, mesh body, bounce) ends in the same report path:
  // run_scene_output renders the report with the common header, write_report_files writes it.
  std::vector<fs::path> written;
  auto remove_written = [&] {
    std::error_code ec;
    for (const auto& p : written) fs::remove(p, ec);
  };
  try {
    const bool sequences = run_kind(scene) == RunKind::mesh_bounce || run_kind(scene) == RunKind::bounce;
    ProgressLine progress(!quiet, stderr, ::isatty(2) != 0, &ProgressLine::steady_seconds, 1.0,
                          sequences ? "sequences" : "drops");
    const SceneOutput r = run_scene_output(scene, std::ref(progress), quiet ? nullptr : &std::cerr);
    progress.finish();
    for (const auto& f : r.files) written.push_back(scene.out / f);
    std::cout << r.table;
    for (const auto& p : write_report_files(scene.out, scene.report, r.json, r.table)) written.push_back(p);
    std::cout << "wrote " << (scene.out / scene.report).string() << ", " << written.back().filename().string();
    for (const auto& f : r.files) std::cout << ", " << f;
    std::cout << "\n";
    // A decisive law that could not be evaluated decides nothing: the exit status stays 0 (no law
    // was rejected), but it must not pass unnoticed. Warned even with --quiet (it is no progress).
    if (!r.skipped.empty()) {
      std::cerr << "validate-geometry: warning: " << r.skipped.size() << " decisive test"
                << (r.skipped.size() == 1 ? " was" : "s were") << " skipped (verdict \"skipped\" in "
                << scene.report << "):\n";
      for (const auto& k : r.skipped) std::cerr << "  " << k << "\n";
    }
    return r.rejected ? 1 : 0;
  } catch (const std::bad_alloc&) {
    remove_written();
    std::cerr << "validate-geometry: error: out of memory for " << scene.ensemble.sphere.asperities << " asperities x "
              << scene.ensemble.drops << " drops (" << to_string(scene.ensemble.mode) << " mode)\n";
    return 2;
  } catch (const std::exception& ex) {
    remove_written();
    std::cerr << "validate-geometry: error: " << ex.what() << "\n";
    return 2;
  }
}
