// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The report of a run on the streaming path (experiments/streaming.hpp): the same GeometryReport
// as analyse() gives for raw samples, with tests evaluated on the binned data (laws/binned.hpp),
// each row naming its statistic and resolution; report.json "statistics" says which path ran.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/collective.hpp"
#include "asperity/app/plan.hpp"
#include "asperity/app/report.hpp"
#include "asperity/experiments/streaming.hpp"
#include "asperity/laws/figure.hpp"

namespace asperity {

/// "streaming histogram, 2^k bins of u = F_ref(x) (...)".
std::string streaming_label(const EnsembleConfig& c);

/// Summaries and tests of a streamed run. Decisive rows: KS-sphere-bootstrap (every law, on the
/// 2^10 coarse per-block cells) and, for r_xy, the likelihood ratio of Eq. 14 against the exact
/// finite-N law (LR-block, se from the spread between blocks of spheres). binned-KS and chi2 on the
/// 2^k fine bins assume iid drops: decisive for sampled runs, information for explicit ones.
GeometryReport analyse_stream(const Scene& scene, const ContactStream& s);

/// The finite-N figure: measured F^(r_xy) - F_Eq14(r_xy) with its +-1 se band (spread between
/// blocks of spheres) against the predicted F_exact - F_Eq14.
BandFigure finite_n_figure(const Scene& scene, const ContactStream& s);

/// run_scene's streaming branch (p.streams): the stream, its analysis, the finite-N figure
/// (finite_n.png in `dir`, default the scene's out, when plots are planned) and the plan with stage
/// times. `group` (rank 0 of a split run, p.control.share its share): the other processes' shares are gathered
/// and merged before the analysis; the report is the same bits as one process's (timings aside).
GeometryReport run_stream_scene(const Plan& p, const Progress& progress, const std::filesystem::path& dir,
                                const StreamHooks& hooks = {}, const StreamState* resume = nullptr,
                                Collective* group = nullptr);

/// A streaming run that ended without a result for a reason already told: a signal stopped it (its
/// checkpoint is written) or another process of a split run failed (that process said why).
struct StreamEnded : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A process of rank > 0 of a split run: runs its share p.control.share of the planned stream (with its own
/// checkpoints) and sends it to rank 0. Throws as rank 0's run does when any process failed or
/// stopped (std::runtime_error), so every process ends with the same outcome.
void run_stream_share(const Plan& p, Collective& group);

}  // namespace asperity
