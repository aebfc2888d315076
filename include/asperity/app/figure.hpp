// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A figure as data: panels stacked top to bottom sharing one x range, each with points (y error
// bars), lines and filled bands. Every figure of a run is built as such a value and drawn by one
// renderer (plot.hpp), which also writes the plotted data as CSV. Text uses the markup of
// laws/figure.hpp (figure_text_literal): the renderer turns it into glyphs only.
#include <cstdint>
#include <string>
#include <vector>

namespace asperity {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
};

/// Okabe-Ito colours (colour-blind safe), in the order curves take them.
inline constexpr Rgb kOkabeIto[] = {{0xD5, 0x5E, 0x00}, {0x00, 0x72, 0xB2}, {0x00, 0x9E, 0x73},
                                    {0xCC, 0x79, 0xA7}, {0xE6, 0x9F, 0x00}, {0x56, 0xB4, 0xE9}};
inline constexpr Rgb kBlack{0, 0, 0};

enum class Dash { solid, dashed, long_dash, dash_dot, dotted, dash_dot_dot };

/// Measured values with +-se error bars. `count` (optional, one per point) goes to the CSV.
struct PointSeries {
  std::string label;  ///< legend text and the CSV's series name
  bool in_legend = true;
  std::vector<double> x, y, se, count;
  Rgb colour = kBlack;
  double size = 1.0;  ///< marker size relative to the default
};

struct LineSeries {
  std::string label;
  bool in_legend = true;
  std::vector<double> x, y;
  Rgb colour = kOkabeIto[0];
  Dash dash = Dash::solid;
  double width = 2.2;  ///< pen width (1 = thinnest)
};

/// The area between lo(x) and hi(x).
struct BandSeries {
  std::string label;
  bool in_legend = true;
  std::vector<double> x, lo, hi;
  Rgb colour{0xCC, 0xE0, 0xF0};
};

enum class LegendAt { top_right, top_left, bottom_right, none };

struct Panel {
  std::string ylabel;
  bool log_y = false;
  double y_lo = 0, y_hi = 0;  ///< the y range; y_hi <= y_lo: from the data (log: decades)
  LegendAt legend = LegendAt::top_right;
  bool grid = false;
  std::vector<BandSeries> bands;   ///< drawn first
  std::vector<LineSeries> lines;   ///< then the lines
  std::vector<PointSeries> points; ///< and the points on top
};

struct Figure {
  std::string title;
  std::string xlabel;  ///< with units, e.g. "r_{xy} [µm]"; under every panel
  double x_lo = 0, x_hi = 0;  ///< x_hi <= x_lo: from the data (log: decades)
  bool log_x = false;         ///< logarithmic x (values <= 0 are not drawn)
  int width = 900, height = 1000;  ///< pixels of the PNG (SVG/PDF: the same aspect)
  double resolution_scale = 1;     ///< the page's resolution relative to 90 dpi (PlotFormats::scale)
  std::vector<Panel> panels;
  /// The panel whose series the CSV holds (the others show the same data differently).
  std::size_t data_panel = 0;
};

}  // namespace asperity
