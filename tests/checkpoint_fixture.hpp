// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A small streaming run and its checkpoints, in-process (test_checkpoint_trust, the checkpoint fuzz
// target): no process is started, so a test can take many checkpoints and resume each.
#include <filesystem>
#include <functional>
#include <vector>

#include "asperity/app/plan.hpp"
#include "asperity/app/scene.hpp"
#include "asperity/experiments/streaming.hpp"

namespace asperity::testing {

/// 2 explicit spheres of 200 asperities x 65536 rotations, 2^10 fine bins: each sphere is one wave
/// (the big-sphere path), so the run can be cut after sphere 0; its state file has ~75 kB.
inline Scene small_stream_scene() {
  Scene s = preset("fig3");
  s.ensemble.sphere.asperities = 200;
  s.ensemble.drops = 2 * 65536;
  s.ensemble.spheres = 2;
  s.spheres_auto = false;
  s.ensemble.bins_log2 = 10;
  s.ensemble.statistics = Statistics::streaming;
  s.ensemble.threads = 1;
  s.plots = false;
  return s;
}

/// The plan of `s` (as plan() makes it) for checkpoints in `out`, continuing them when `resume`:
/// planned for an empty place and pointed at `out` afterwards, so that the tests can write and read
/// checkpoints in a directory plan() itself would refuse for a new run.
inline Plan checkpoint_plan(Scene s, const std::filesystem::path& out = {}, bool resume = false) {
  const std::filesystem::path dir = out.empty() ? s.out : out;
  s.out = std::filesystem::temp_directory_path() / "asperity-test-no-such-dir";
  Plan p = plan(std::move(s));
  p.given.out = p.scene.out = dir;
  p.control.resume = resume;
  return p;
}

/// Runs the planned stream of p; `each` sees the state at every wave boundary before the last
/// (a checkpoint), and the run stops after `stop_after` of them (0: never). Returns the state at
/// its end.
inline StreamState run_stream(const Plan& p, const std::function<void(const StreamState&)>& each, int stop_after = 0,
                              const StreamState* resume = nullptr) {
  int waves = 0;
  StreamHooks h;
  h.stop = [&] { return stop_after > 0 && ++waves >= stop_after; };
  h.checkpoint_due = [] { return true; };
  h.checkpoint = [&](const StreamState& st) {
    if (each) each(st);
  };
  return run_contact_stream(p.scene.ensemble, {}, h, resume, p.control.share).state;
}

}  // namespace asperity::testing
