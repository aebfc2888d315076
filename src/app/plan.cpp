// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/app/plan.hpp"

#include <atomic>
#include <stdexcept>

#include "app/checkpoint.hpp"
#include "asperity/app/resources.hpp"
#include "app/runs/kinds.hpp"
#include "app/runs/mesh_body.hpp"

namespace asperity {

namespace {

std::atomic<std::uint64_t> g_plans{0};  // plans_made(): a diagnostic count, read by tests only

}  // namespace

bool Plan::runs(std::string_view name) const {
  for (const auto& s : stages)
    if (s.name == name) return s.run;
  return false;
}

PlanStage& Plan::stage(std::string_view name) {
  for (auto& s : stages)
    if (s.name == name) return s;
  throw std::out_of_range("no stage '" + std::string(name) + "' in the plan");
}

Plan plan(Scene s, RunControl control) {
  g_plans.fetch_add(1, std::memory_order_relaxed);
  validate(s);  // the cross-key rules (scene.hpp); the reader has checked each key
  Plan p;
  p.kind = run_kind(s);
  p.scene = s;
  p.given = std::move(s);
  if (const auto& row = runs::kind(p.kind); row.plan) row.plan(p);
  p.streams = p.kind == RunKind::sphere && uses_streaming(p.scene.ensemble);
  if (!p.streams) control.share = {};  // a run that does not stream is rank 0's alone
  if (control.resume && !p.streams)
    throw std::invalid_argument("--resume: the scene of " + p.given.out.string() +
                                " does not stream (statistics = raw, or not a contact ensemble)");
  p.control = control;
  check_memory(p);  // before the mesh is read: its size comes from its header
  // A checkpoint in the output directory belongs to an interrupted streaming run: never
  // overwritten; a resumed run's is read whole now, before any file is touched.
  if (p.streams) check_checkpoint_files(p);
  if (p.given.mesh) p.mesh = runs::read_checked_mesh(p.given);
  return p;
}

std::uint64_t plans_made() { return g_plans.load(std::memory_order_relaxed); }

}  // namespace asperity
