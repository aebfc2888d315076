// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What app/ makes of the experiments' reports: tables, report.json bodies (to_json: the JSON body;
// the common header is report.hpp's with_header) and the figures drawn from report data (plot.hpp).
#include <filesystem>
#include <string>
#include <vector>

#include "asperity/app/plot.hpp"
#include "asperity/experiments/body_bounce.hpp"
#include "asperity/experiments/body_experiments.hpp"
#include "asperity/experiments/bounce.hpp"

namespace asperity {

std::string format_table(const RadiiReport& r);
std::string to_json(const RadiiReport& r);
std::string format_table(const MeshImpactReport& r);
std::string to_json(const MeshImpactReport& r);
std::string format_table(const MeshBounceReport& r);
std::string to_json(const MeshBounceReport& r);

/// The table: one row per (variant, group).
std::string format_bounce_table(const std::vector<BounceVariantReport>& r);

/// report.json (schema_version 1): the usual header fields plus `bounce`.
std::string bounce_to_json(const std::string& scene_name, const SphereParams& sphere, const BounceExperiment& b,
                           std::uint64_t seed, const std::vector<BounceVariantReport>& r,
                           const std::vector<std::string>& plots, const std::vector<BounceComparison>& comparisons = {});

/// Fig. 6 per variant: log-density histograms of eps - m (fitted mode) per speed window with the
/// fitted laws, each with its data (CSV); returns the file names written into `dir`.
std::vector<std::string> write_bounce_plots(const std::filesystem::path& dir, const std::vector<BounceVariantReport>& r,
                                            const PlotFormats& formats = {});

/// A mesh-bounce run's figures, in report order: eps against speed, r.figures, then Fig. 6 of the
/// base report, each with its data (CSV); returns the file names written into `dir`.
std::vector<std::string> write_mesh_bounce_plots(const std::filesystem::path& dir, const MeshBounceReport& r,
                                                 const PlotFormats& formats = {});

}  // namespace asperity
