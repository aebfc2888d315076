// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Figures as values: a measured histogram with the analytic laws to overlay. The layers below app/
// build them; app/plot.hpp renders them (PLplot, in-process), so no experiment writes a file.
//
// Text (titles, labels, legends) is UTF-8 (Greek letters as themselves: ε, µ, λ) with a small
// markup: `_{xy}` / `^{-6}` are sub/superscripts (`_x`, `^2` for one character), `\c` is the
// character c itself. Text from a user (a mesh name) goes in through figure_text_literal, so that
// it reads as written; whatever it contains, the renderer draws glyphs only.
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "asperity/laws/statistics.hpp"

namespace asperity {

/// `text` with the markup characters escaped: drawn exactly as written.
inline std::string figure_text_literal(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (c == '\\' || c == '_' || c == '^' || c == '{' || c == '}') out += '\\';
    out += c;
  }
  return out;
}

/// An analytic curve to overlay on a histogram.
struct Curve {
  std::string label;  ///< legend text, e.g. "Eq. (14), Rayleigh"
  ///@{
  /// The curve's points, in the variable's own units (the figure's x_scale and y_scale apply when
  /// drawn); equal lengths.
  std::vector<double> x, y;
  ///@}
};

/// f (e.g. a law's pdf) at segments + 1 equally spaced points on [lo, hi]; where f is not finite
/// the curve is drawn at 0.
Curve sampled_curve(const std::function<double(double)>& f, std::string label, double lo, double hi, int segments = 300);

/// One histogram panel: the measured density with error bars and the laws it is compared with.
struct HistogramFigure {
  std::string title;        ///< e.g. "r_{xy}, N = 10^5, explicit geometry: 50 spheres x 20000 rotations"
  /// Legend of the measured points, followed by " (n = <count>)": which ensemble they come from.
  std::string data_label = "explicit geometry";
  std::string xlabel;       ///< with units, e.g. "r_x [µm]"
  std::string ylabel = "probability density";  ///< y axis label
  double x_scale = 1.0;     ///< multiply x values (histogram and curves) for display, e.g. 1e6 for µm
  double y_scale = 1.0;     ///< multiply densities for display (use 1/x_scale to keep them normalised)
  Histogram histogram;      ///< drawn as points with Poisson error bars (density, density_se)
  std::vector<Curve> curves;  ///< laws overlaid as lines, in legend order
};

/// A figure with the file name it is to be written under (e.g. "r_x.png"), relative to the run's
/// output directory.
struct NamedFigure {
  std::string file;         ///< file name, e.g. "r_x.png" (no directory)
  HistogramFigure figure;   ///< what the file shows
};

}  // namespace asperity

namespace asperity {

/// Measured points with a +-1 se band (e.g. a pooled cdf minus a law) against predicted curves,
/// one panel.
struct BandFigure {
  ///@{
  /// Title and axis labels (the figure markup of app/figure.hpp: _{..}, ^{..}; labels with units, e.g. "r_{xy} [µm]").
  std::string title, xlabel, ylabel;
  ///@}
  std::string data_label;   ///< the ensemble the points come from, with n
  ///@{
  /// Display factors applied to x (points and curves) and to y and se, e.g. x_scale = 1e6 for µm.
  double x_scale = 1.0, y_scale = 1.0;
  ///@}
  ///@{
  /// The measured points, their y values and +-1 se half-widths (unscaled; equal lengths).
  std::vector<double> x, y, se;
  ///@}
  std::vector<Curve> curves;  ///< predictions drawn as lines, in legend order
};

}  // namespace asperity
