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

#include "asperity/app/checkpoint.hpp"
#include "asperity/app/interrupt.hpp"
#include "asperity/app/output_staging.hpp"
#include "asperity/app/plot.hpp"
#include "asperity/app/report.hpp"
#include "asperity/app/resources.hpp"
#include "asperity/app/run.hpp"
#include "asperity/app/scene.hpp"
#include "app/cli/options.hpp"
#include "app/cli/progress_line.hpp"

namespace fs = std::filesystem;
using namespace asperity;
using asperity::cli::BadInput;
using asperity::cli::ProgressLine;

namespace {

// The command line, checked as far as it can be before the output directory is touched. Returns
// the exit status when the run ends here (--help: 0; bad input: 2).
std::optional<int> read_command_line(int argc, char** argv, Scene& scene, bool& quiet) {
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
    check_scene_inputs(scene);
    check_memory(scene);
  } catch (const std::exception& ex) {
    std::cerr << "validate-geometry: error: " << ex.what() << "\n";
    return 2;
  }
  return std::nullopt;
}

// The table, the files written, and a warning for every decisive test that was skipped.
void print_outcome(const Scene& scene, const SceneOutput& r, const std::vector<fs::path>& reports) {
  std::cout << r.table;
  std::cout << "wrote " << (scene.out / scene.report).string() << ", " << reports.at(1).filename().string();
  for (const auto& f : r.files) std::cout << ", " << f;
  std::cout << "\n";
  std::cout.flush();
  // A decisive law that could not be evaluated decides nothing: the exit status stays 0 (no law
  // was rejected), but it must not pass unnoticed. Warned even with --quiet (it is no progress).
  if (!r.skipped.empty()) {
    std::cerr << "validate-geometry: warning: " << r.skipped.size() << " decisive test"
              << (r.skipped.size() == 1 ? " was" : "s were") << " skipped (verdict \"skipped\" in "
              << scene.report << "):\n";
    for (const auto& k : r.skipped) std::cerr << "  " << k << "\n";
  }
}

// Every kind of run (sphere, unequal radii, mesh body, bounce) ends in the same report path:
// run_scene_output renders the report with the common header, write_report_files writes it.
// Every file goes into a staging directory inside the output directory and is renamed into
// place only when the whole run succeeded (the report last): a failed or interrupted run
// leaves the directory as it found it (output_staging.hpp). `staging_dir` is set as soon as it
// exists, for the messages. Returns the exit status.
int run_staged(const Scene& scene, bool quiet, std::string& staging_dir) {
  std::optional<OutputStaging> staging;
  try {
    staging.emplace(scene.out);
  } catch (const std::exception& ex) {
    throw BadInput(std::string("--out: ") + ex.what());
  }
  staging_dir = staging->dir().string();
  const bool sequences = run_kind(scene) == RunKind::mesh_bounce || run_kind(scene) == RunKind::bounce;
  ProgressLine progress(!quiet, stderr, ::isatty(2) != 0, &ProgressLine::steady_seconds, 1.0,
                        sequences ? "sequences" : "drops");
  ProgressLine::Log log(progress);
  const SceneOutput r = run_scene_output(scene, std::ref(progress), quiet ? nullptr : &log, staging->dir());
  progress.finish();
  for (const auto& f : r.files) staging->add(f);
  const auto reports = write_report_files(staging->dir(), scene.report, r.json, r.table);
  staging->add(reports.at(1).filename().string());  // the table, then the report last
  staging->add(reports.at(0).filename().string());
  staging->commit();
  staging.reset();
  if (uses_streaming(scene.ensemble)) remove_checkpoint(scene.out);  // this run's (or the run it continued)
  print_outcome(scene, r, reports);
  return r.rejected ? 1 : 0;
}

// Messages name the files where they were going, not the staging copy.
std::string in_place(std::string message, const std::string& staging_dir, const fs::path& out) {
  for (std::size_t at; !staging_dir.empty() && (at = message.find(staging_dir)) != std::string::npos;)
    message.replace(at, staging_dir.size(), out.string());
  return message;
}

}  // namespace

int main(int argc, char** argv) {
  // First, before any thread exists: SIGINT/SIGTERM/SIGHUP/SIGPIPE remove this run's temporaries
  // (its staging directory, gnuplot's files, the directories it created) and exit 128 + signal.
  install_interrupt_cleanup("validate-geometry");
  // Explicit runs build and drop K spheres and indexes of a few MB each: keep freed memory in the
  // heap instead of returning it to the kernel, so that the next sphere does not page-fault its
  // memory in again (halved the index stage of fig3 on the loaded 2-core machine; bench/RESULTS.md).
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  Scene scene;
  bool quiet = false;
  // Everything that can be checked is checked before the output directory is touched.
  if (const auto status = read_command_line(argc, argv, scene, quiet)) return *status;
  std::string staging_dir;
  try {
    return run_staged(scene, quiet, staging_dir);
  } catch (const std::bad_alloc&) {
    std::cerr << "validate-geometry: error: out of memory for " << scene.ensemble.sphere.asperities << " asperities x "
              << scene.ensemble.drops << " drops (" << to_string(scene.ensemble.mode) << " mode); "
              << scene.out.string() << " is as it was\n";
    return 2;
  } catch (const std::exception& ex) {
    std::cerr << "validate-geometry: error: " << in_place(ex.what(), staging_dir, scene.out) << "\n";
    return 2;
  }
}
