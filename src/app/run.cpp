// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/app/run.hpp"

#include <filesystem>
#include <optional>

#include "app/io/output_staging.hpp"
#include "asperity/core/thread_count.hpp"
#include "app/runs/kinds.hpp"

namespace asperity {

namespace {

// Whether a run of p writes a file (figures, a restitution table, a mesh body's PLY): one that
// writes none needs no staging directory, and touches no directory at all (asperity.run, out=None).
bool writes_files(const Plan& p) { return p.scene.plots || !file_output_key(p.scene).empty(); }

}  // namespace

SceneOutput run_plan(const Plan& p, const Progress& progress, std::ostream* log, const std::filesystem::path& dir,
                     Collective* group, ContactSamples* keep) {
  const ThreadCountScope thread_scope(p.scene.ensemble.threads);  // for this call only (core/thread_count.hpp)
  // Without a directory from the caller the run stages its own files in out and renames them
  // into place at the end: a failure leaves out as it was (output_staging.hpp).
  std::optional<OutputStaging> own;
  if (dir.empty() && writes_files(p)) own.emplace(p.scene.out);
  const std::filesystem::path into = own ? own->dir() : dir;
  SceneOutput o = runs::kind(p.kind).run(p, {progress, log, into, group, keep});
  o.kind = p.kind;
  if (own) {
    for (const auto& f : o.files) own->add(f);
    own->commit();
  }
  return o;
}

SceneOutput run_scene_output(const Scene& s, const Progress& progress, std::ostream* log, const std::filesystem::path& dir) {
  return run_plan(plan(s), progress, log, dir);
}

}  // namespace asperity
