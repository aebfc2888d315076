// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The one place that draws (PLplot, through cairo): a Figure in, the bytes of the file out. No
// path ever reaches PLplot (it writes into memory), and no text reaches it unconverted: the
// figure markup becomes PLplot's sub/superscript escapes, '#' becomes "##", so a label can change
// nothing but the glyphs drawn.
#include <cstddef>
#include <string>
#include <string_view>

#include "asperity/app/figure.hpp"

namespace asperity::detail {

enum class ImageFormat { png, svg, pdf };

/// "" when `format` can be drawn (built with PLplot, its cairo driver found), else why not.
std::string renderer_problem(ImageFormat format);

/// The file `fig` draws to in `format`. Throws std::invalid_argument for a figure that cannot be
/// drawn (no panels, lengths that differ, non-finite values), std::runtime_error when PLplot
/// reports an error. Serialised: PLplot's state is global.
std::string render_figure(const Figure& fig, ImageFormat format);

/// The figure markup as PLplot text: `_{..}` / `^{..}` (or `_c` / `^c`) as sub/superscripts,
/// `\c` as c, '#' as "##", control characters and invalid UTF-8 as '?'.
std::string plplot_text(std::string_view markup);

/// A linear y axis's ticks and where its title goes, known before drawing: PLplot writes the tick
/// labels horizontally, so their width grows with their glyphs and the title must sit beyond the
/// widest. Distances in character heights from the axis (plmtex's `disp`).
constexpr double kTickGap = 0.6;     ///< from the axis to a tick label's right end
constexpr double kGlyphWidth = 0.9;  ///< one digit's width (measured on the cairo PNGs: 0.88)
struct YAxisLayout {
  double step = 0;          ///< tick interval (0: PLplot's own, the logarithmic axis's decades)
  std::size_t widest = 0;   ///< glyphs of the widest tick label
  double title_disp = 0;    ///< the y title's centre
};
YAxisLayout y_axis_layout(double lo, double hi, bool log);

/// A tick label's text (%g; 2e+06 as 2×10^6 with PLplot's superscript escapes), `span` the axis's
/// (values within 1e-9 of it from zero read 0).
std::string tick_text(double value, double span);

/// The figure markup as plain text (CSV headers): markup characters kept as written, braces of
/// sub/superscripts dropped ("r_{xy}" -> "r_xy"), escapes resolved.
std::string plain_text(std::string_view markup);

}  // namespace asperity::detail
