// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Publication-style PNG figures of measured histograms against analytic laws, drawn by gnuplot
// (pngcairo). A figure is a value (laws/figure.hpp); writing it is one call.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "asperity/laws/figure.hpp"

namespace asperity {

/// True if gnuplot with the pngcairo terminal is available.
bool plotting_available();

/// Writes `png` with two panels stacked vertically: linear y (top) and logarithmic y (bottom),
/// like the paper's Figs. 3-5. Empty bins are omitted from the log panel. Writes to a temporary
/// file and renames, so a failure never leaves a partial PNG. Throws std::runtime_error with
/// gnuplot's message on failure.
void write_histogram_png(const std::filesystem::path& png, const HistogramFigure& fig);

/// Runs a caller-built gnuplot script that renders to the path it is given (a temporary beside
/// `png`), then renames the result onto `png`: like write_histogram_png, a failure leaves no
/// partial file. Throws std::runtime_error with gnuplot's message on failure.
void write_gnuplot_png(const std::filesystem::path& png,
                       const std::function<std::string(const std::filesystem::path& out)>& script);

/// Writes each figure to dir / file (write_histogram_png), in order; returns the file names.
std::vector<std::string> write_figures(const std::filesystem::path& dir, const std::vector<NamedFigure>& figures);

}  // namespace asperity
