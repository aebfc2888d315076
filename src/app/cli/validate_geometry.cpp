// SPDX-License-Identifier: GPL-3.0-or-later
// validate-geometry: run a scene of explicit rough spheres, compare the contact statistics with
// the paper's laws and the exact finite-N laws, print a table, write report.json and figures.
// Exit status: 0 no law rejected (skipped laws: a warning), 1 the family of decisive tests rejects
// a law (Holm at the run's alpha, laws/family.hpp; report.json "rejected"), 2 bad input or an
// output that cannot be written.
#include <malloc.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <new>
#include <sstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/checkpoint.hpp"
#include "app/io/interrupt.hpp"
#include "app/io/output_staging.hpp"
#include "asperity/app/plan.hpp"
#include "asperity/app/plot.hpp"
#include "asperity/app/report.hpp"
#include "asperity/app/resources.hpp"
#include "asperity/app/run.hpp"
#include "asperity/app/scene.hpp"
#include "app/stream_report.hpp"
#include "app/cli/options.hpp"
#include "app/cli/processes.hpp"
#include "app/cli/progress_line.hpp"
#include "app/io/text_escape.hpp"

namespace fs = std::filesystem;
using namespace asperity;
using asperity::cli::BadInput;
using asperity::cli::ProgressLine;

namespace {

// The command line, checked as far as it can be before the output directory is touched, and
// planned (plan(), plan.hpp: the one place that decides how the run goes). Returns the exit status
// when the run ends here (--help: 0; bad input: 2). `share`: this process's share of a split run
// (its checkpoint file is checked); only rank 0 prints help and errors.
std::optional<int> read_command_line(int argc, char** argv, std::optional<Plan>& planned, bool& quiet,
                                     const StreamShare& share, std::string& error) {
  try {
    const std::vector<std::string> args(argv + 1, argv + argc);
    cli::Options o = cli::parse_command_line(args);
    if (o.help) {
      if (share.rank == 0) std::cout << o.help_text;
      return 0;
    }
    quiet = o.quiet || share.rank > 0;
    if (o.scene.plots && share.rank == 0)  // only rank 0 draws
      if (const std::string why = plotting_problem(parse_plot_formats(o.scene.plot_format)); !why.empty())
        throw BadInput("figures cannot be drawn: " + why + "; or pass --no-plots");
    o.control.share = share;  // plan() keeps it for a streaming run only
    planned.emplace(plan(std::move(o.scene), o.control));
    // Options that act on streaming statistics only would be silently ignored by a run that keeps
    // raw samples: refused, by the plan's answer.
    if (!planned->streams && !o.streaming_only.empty())
      throw BadInput(o.streaming_only.front() +
                     ": acts on streaming statistics only, and this run keeps raw samples (give --statistics "
                     "streaming, or leave the option out)");
  } catch (const std::exception& ex) {
    error = ex.what();
    return 2;
  }
  return std::nullopt;
}

// Text for the terminal: a scene name or key can hold escape sequences (ESC [2J clears the
// screen, OSC sequences set the title or write to the clipboard); every control character but
// the line breaks of a multi-line table or message is shown as \xNN (issue 33 item 8).
std::string shown(const std::string& text) {
  std::string out;
  std::size_t from = 0;
  for (std::size_t nl; (nl = text.find('\n', from)) != std::string::npos; from = nl + 1)
    out += asperity::detail::escaped(std::string_view(text).substr(from, nl - from)) + "\n";
  return out + asperity::detail::escaped(std::string_view(text).substr(from));
}

// The table, the files written, and a warning for every decisive test that was skipped.
void print_outcome(const Scene& scene, const SceneOutput& r, const std::vector<fs::path>& reports) {
  std::cout << shown(r.table);
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
int run_staged(const Plan& p, bool quiet, std::string& staging_dir, Collective* group) {
  const Scene& scene = p.scene;
  std::optional<OutputStaging> staging;
  try {
    staging.emplace(scene.out);
  } catch (const std::exception& ex) {
    throw BadInput(std::string("--out: ") + ex.what());
  }
  staging_dir = staging->dir().string();
  // The report and its table cannot be renamed over a link or a directory: found now, before the
  // run, not at commit time after it (issue 33 item 7).
  try {
    std::vector<std::string> known{scene.report, report_table_name(scene.report)};
    if (scene.mesh && !scene.mesh->export_ply.empty()) known.push_back(scene.mesh->export_ply);
    staging->check_replaceable(known);
  } catch (const std::exception& ex) {
    throw BadInput(ex.what());
  }
  // Checked again under the directory's lock: a run that ended between plan() and the lock
  // may have left its checkpoint here, which this run must neither overwrite nor remove.
  if (!p.control.resume && p.streams) {
    try {
      check_checkpoint_files(p);
    } catch (const std::exception& ex) {
      throw BadInput(ex.what());
    }
  }
  const bool sequences = p.kind == RunKind::mesh_bounce || p.kind == RunKind::bounce;
  ProgressLine progress(!quiet, stderr, ::isatty(2) != 0, &ProgressLine::steady_seconds, 1.0,
                        sequences ? "sequences" : "drops");
  ProgressLine::Log log(progress);
  const SceneOutput r = run_plan(p, std::ref(progress), quiet ? nullptr : &log, staging->dir(), group);
  progress.finish();
  for (const auto& f : r.files) staging->add(f);
  const auto reports = write_report_files(staging->dir(), scene.report, r.json, r.table);
  staging->add(reports.at(1).filename().string());  // the table, then the report last
  staging->add(reports.at(0).filename().string());
  staging->commit();
  // Under the lock still: this run's checkpoint (or the one it continued), no other run's.
  if (p.streams) remove_checkpoint(scene.out, p.control.share);
  staging.reset();
  print_outcome(scene, r, reports);
  return r.rejected ? 1 : 0;
}

// Messages name the files where they were going, not the staging copy.
std::string in_place(std::string message, const std::string& staging_dir, const fs::path& out) {
  for (std::size_t at; !staging_dir.empty() && (at = message.find(staging_dir)) != std::string::npos;)
    message.replace(at, staging_dir.size(), out.string());
  return message;
}

// Rank 0 of a split run, or the only process: runs and reports the scene. Returns the exit status.
int run_reporting(const Plan& p, bool quiet, Collective* group) {
  const Scene& scene = p.scene;
  std::string staging_dir;
  try {
    return run_staged(p, quiet, staging_dir, group);
  } catch (const std::bad_alloc&) {
    std::cerr << "validate-geometry: error: out of memory for " << scene.ensemble.sphere.asperities << " asperities x "
              << scene.ensemble.drops << " drops (" << to_string(scene.ensemble.mode) << " mode); "
              << scene.out.string() << " is as it was\n";
    return 2;
  } catch (const std::exception& ex) {
    std::cerr << "validate-geometry: error: " << shown(in_place(ex.what(), staging_dir, scene.out)) << "\n";
    return 2;
  }
}

// A split run's collective steps, counted so that rank 0 completes them when it fails early: the
// other processes wait for exactly these (read_command_line's agreement, the stream's outcome, the
// gather and sums when it succeeded, the exit status).
class CountedSteps final : public Collective {
 public:
  explicit CountedSteps(Collective& g) : g_(g) {}
  int rank() const override { return g_.rank(); }
  int size() const override { return g_.size(); }
  int max(int v) override { return ++steps, g_.max(v); }
  std::vector<std::string> gather(const std::string& b) override { return ++steps, g_.gather(b); }
  void sum(std::vector<std::uint64_t>& v) override { ++steps, g_.sum(v); }
  int steps = 0;

 private:
  Collective& g_;
};

// The processes of a split run: rank 0 reports (a scene that does not stream runs on rank 0 alone),
// the others run their share of the stream; all end with rank 0's exit status.
int run_split(const Plan& p, bool quiet, Collective& world) {
  CountedSteps group(world);
  const bool split = p.control.share.ranks > 1;
  int status = 0;
  if (group.rank() == 0) {
    if (!split)
      std::cerr << "validate-geometry: note: this scene does not stream (statistics = raw, or not a contact ensemble): "
                   "rank 0 runs it alone (--statistics streaming splits a contact ensemble across the processes)\n";
    status = run_reporting(p, quiet, split ? &group : nullptr);
    // Failed before the stream's outcome was agreed: take part in it, as failed.
    if (split && group.steps == 0) group.max(2);
  } else if (split) {
    try {
      run_stream_share(p, group);
    } catch (const StreamEnded&) {
      status = 2;  // told already: by rank 0 (a stop) or by the process that failed
    } catch (const std::exception& ex) {
      std::cerr << "validate-geometry: error (rank " << group.rank() << "): " << ex.what() << "\n";
      status = 2;
    }
  }
  return group.max(group.rank() == 0 ? status : 0);
}

}  // namespace

namespace {

int run_main(int argc, char** argv) {
  // First, before any thread exists: SIGINT/SIGTERM/SIGHUP/SIGPIPE remove this run's temporaries
  // (its staging directory, its temporary files, the directories it created) and exit 128 + signal.
  install_interrupt_cleanup("validate-geometry");
  // Explicit runs build and drop K spheres and indexes of a few MB each: keep freed memory in the
  // heap instead of returning it to the kernel, so that the next sphere does not page-fault its
  // memory in again (halved the index stage of fig3 on the loaded 2-core machine; bench/RESULTS.md).
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  std::unique_ptr<Collective> world;
  try {
    world = cli::join_processes(&argc, &argv);
  } catch (const std::exception& ex) {
    std::cerr << "validate-geometry: error: " << shown(ex.what()) << "\n";
    return 2;
  }
  const StreamShare share = world ? StreamShare{world->rank(), world->size()} : StreamShare{};
  std::optional<Plan> planned;  // the run's one plan
  bool quiet = false;
  // Everything that can be checked is checked before the output directory is touched (by every
  // process: each checks its own checkpoint file; all stop when one finds a fault).
  std::string error;
  const std::optional<int> status = read_command_line(argc, argv, planned, quiet, share, error);
  if (world && world->max(status ? (*status == 0 ? 1 : 2) : 0) != 0) {
    // One message: rank 0's, or (when only other processes refused, e.g. a missing checkpoint of
    // theirs) each of theirs.
    const bool rank0_failed = world->max(share.rank == 0 && !error.empty()) != 0;
    if (!error.empty() && (share.rank == 0 || !rank0_failed))
      std::cerr << "validate-geometry: error" << (share.rank > 0 ? " (rank " + std::to_string(share.rank) + ")" : "")
                << ": " << shown(error) << "\n";
    return status && *status == 0 ? 0 : 2;
  }
  if (status) {
    if (!error.empty()) std::cerr << "validate-geometry: error: " << shown(error) << "\n";
    return *status;
  }
  if (world) return run_split(*planned, quiet, *world);
  return run_reporting(*planned, quiet, nullptr);
}

}  // namespace

int main(int argc, char** argv) {
  const int status = run_main(argc, argv);
  asperity::mark_normal_exit();  // any other exit() is a library's failure (interrupt.hpp)
  return status;
}
