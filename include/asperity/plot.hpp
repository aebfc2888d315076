#pragma once
// Publication-style PNG figures of measured histograms against analytic laws, drawn by gnuplot
// (pngcairo). A figure is a value; writing it is one call.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "asperity/statistics.hpp"

namespace asperity {

/// An analytic curve to overlay on a histogram.
struct Curve {
  std::string label;  ///< legend text, e.g. "Eq. (14), Rayleigh"
  std::vector<double> x, y;
};

/// f (e.g. a law's pdf) at segments + 1 equally spaced points on [lo, hi]; where f is not finite
/// the curve is drawn at 0.
Curve sampled_curve(const std::function<double(double)>& f, std::string label, double lo, double hi, int segments = 300);

struct HistogramFigure {
  std::string title;        ///< e.g. "r_{xy}, N = 10^5, fresh, 10^6 drops"
  std::string xlabel;       ///< with units, e.g. "r_x [µm]"
  std::string ylabel = "probability density";
  double x_scale = 1.0;     ///< multiply x values (histogram and curves) for display, e.g. 1e6 for µm
  double y_scale = 1.0;     ///< multiply densities for display (use 1/x_scale to keep them normalised)
  Histogram histogram;      ///< drawn as points with Poisson error bars (density, density_se)
  std::vector<Curve> curves;
};

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

}  // namespace asperity
