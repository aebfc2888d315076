// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Figures of a run: every figure is a value (figure.hpp; histograms against laws come from
// laws/figure.hpp), drawn in-process by PLplot (cairo) as PNG and optionally SVG/PDF, with the
// plotted data as CSV beside it. Files are created new (O_EXCL, never through a symlink) under a
// temporary name in the directory given and renamed into place: never a partial file.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "asperity/app/figure.hpp"
#include "asperity/laws/figure.hpp"

namespace asperity {

/// The image formats written per figure (CSV is always written).
struct PlotFormats {
  bool png = true, svg = false, pdf = false;
  /// Size factor in [0.25, 8]: the page's pixels and its resolution scale together, so a figure at
  /// scale 2 is the same drawing at twice the pixels (text, lines and margins keep their proportions).
  double scale = 1;
};

/// "png", "svg", "pdf", "png+svg", "png+pdf" (also "svg+pdf", "png+svg+pdf"), optionally followed by
/// "@S", a size factor S in [0.25, 8] (e.g. "png@2": 1800 x 2000 pixels for a 900 x 1000 figure).
/// Throws std::invalid_argument naming the accepted values.
PlotFormats parse_plot_formats(std::string_view text);
std::string to_string(const PlotFormats& f);

/// "" when figures can be drawn in `formats` (built with PLplot, its cairo driver installed), else
/// why not, with what to install.
std::string plotting_problem(const PlotFormats& formats = {});
/// plotting_problem().empty().
bool plotting_available();

/// The two-panel figure of a histogram against its laws: linear y (top), logarithmic y (bottom,
/// empty bins omitted), like the paper's Figs. 3-5. Throws std::invalid_argument for a figure that
/// cannot be drawn (no bins, no counts, non-finite values, curves of unequal lengths).
Figure histogram_figure(const HistogramFigure& fig);

/// Measured points with their +-se error bars against predicted curves, one panel.
Figure band_figure(const BandFigure& fig);

/// Writes `fig` as dir/<stem>.png (and .svg / .pdf as `formats` says) and its data as
/// dir/<stem>.csv; returns the file names written, images first. A failure removes what this
/// call wrote and throws (std::invalid_argument for the figure, std::runtime_error for the files).
std::vector<std::string> write_figure(const std::filesystem::path& dir, const std::string& stem, const Figure& fig,
                                      const PlotFormats& formats = {});

/// write_figure(png's directory, png's stem, histogram_figure(fig), png only).
void write_histogram_png(const std::filesystem::path& png, const HistogramFigure& fig);

/// Each figure (its file "x.png" gives the stem "x") through write_figure, in order; returns every
/// file written.
std::vector<std::string> write_figures(const std::filesystem::path& dir, const std::vector<NamedFigure>& figures,
                                       const PlotFormats& formats = {});

/// The figures among files a writer returned (report.json "plots"), and their data ("plot_data").
std::vector<std::string> image_files(const std::vector<std::string>& files);
std::vector<std::string> data_files(const std::vector<std::string>& files);

}  // namespace asperity
