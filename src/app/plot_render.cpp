// SPDX-License-Identifier: GPL-3.0-or-later
// Figures drawn by PLplot's cairo drivers into memory (plot_render.hpp). PLplot keeps its state
// in globals and is not thread-safe: every call into it happens under one mutex, here. It never
// sees a path (it writes to an open_memstream that its driver closes) and never sees text that
// plplot_text did not convert.
#include "plot_render.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef ASPERITY_HAVE_PLPLOT
#include <plplot.h>
#endif

namespace asperity::detail {

namespace {

void check_values(const std::vector<double>& v, std::size_t n, const std::string& what) {
  if (v.size() != n) throw std::invalid_argument("figure: " + what + " has a length different from x");
  for (double x : v)
    if (!std::isfinite(x)) throw std::invalid_argument("figure: " + what + " has a value that is not finite");
}

void validate(const Figure& fig) {
  if (fig.panels.empty()) throw std::invalid_argument("figure: no panels");
  if (fig.width < 100 || fig.width > 10000 || fig.height < 100 || fig.height > 10000)
    throw std::invalid_argument("figure: size outside 100..10000 pixels");
  if (fig.data_panel >= fig.panels.size()) throw std::invalid_argument("figure: data_panel names no panel");
  if (!std::isfinite(fig.x_lo) || !std::isfinite(fig.x_hi)) throw std::invalid_argument("figure: x range not finite");
  if (fig.log_x && fig.x_hi > fig.x_lo && !(fig.x_lo > 0)) throw std::invalid_argument("figure: log x with x_lo <= 0");
  for (const Panel& p : fig.panels) {
    if (!std::isfinite(p.y_lo) || !std::isfinite(p.y_hi)) throw std::invalid_argument("figure: y range not finite");
    if (p.log_y && p.y_hi > p.y_lo && !(p.y_lo > 0)) throw std::invalid_argument("figure: log panel with y_lo <= 0");
    for (const auto& s : p.points) {
      check_values(s.x, s.x.size(), "points \"" + s.label + "\" x");
      check_values(s.y, s.x.size(), "points \"" + s.label + "\" y");
      check_values(s.se, s.x.size(), "points \"" + s.label + "\" se");
      if (!s.count.empty()) check_values(s.count, s.x.size(), "points \"" + s.label + "\" count");
    }
    for (const auto& s : p.lines) {
      check_values(s.x, s.x.size(), "line \"" + s.label + "\" x");
      check_values(s.y, s.x.size(), "line \"" + s.label + "\" y");
    }
    for (const auto& s : p.bands) {
      check_values(s.x, s.x.size(), "band \"" + s.label + "\" x");
      check_values(s.lo, s.x.size(), "band \"" + s.label + "\" lo");
      check_values(s.hi, s.x.size(), "band \"" + s.label + "\" hi");
    }
  }
}

}  // namespace

#ifdef ASPERITY_HAVE_PLPLOT

namespace {

const char* device_of(ImageFormat f) {
  switch (f) {
    case ImageFormat::png: return "pngcairo";
    case ImageFormat::svg: return "svgcairo";
    case ImageFormat::pdf: return "pdfcairo";
  }
  return "pngcairo";
}

// The x range: the figure's, else from every series.
std::pair<double, double> x_range(const Figure& fig) {
  if (fig.x_hi > fig.x_lo) return {fig.x_lo, fig.x_hi};
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  auto take = [&](const std::vector<double>& x) {
    for (double v : x)
      if (!fig.log_x || v > 0) lo = std::min(lo, v), hi = std::max(hi, v);
  };
  for (const Panel& p : fig.panels) {
    for (const auto& s : p.points) take(s.x);
    for (const auto& s : p.lines) take(s.x);
    for (const auto& s : p.bands) take(s.x);
  }
  if (fig.log_x) {
    if (!(hi >= lo)) return {1.0, 10.0};
    return {std::pow(10.0, std::floor(std::log10(lo))), std::pow(10.0, std::ceil(std::log10(hi) + 1e-12))};
  }
  if (!(hi > lo)) return {std::isfinite(lo) ? lo - 1 : 0.0, std::isfinite(hi) ? hi + 1 : 1.0};
  return {lo, hi};
}

// The y range of a panel: its own, else from the data (log: whole decades around the positive values).
std::pair<double, double> y_range(const Panel& p) {
  if (p.y_hi > p.y_lo) return {p.y_lo, p.y_hi};
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  auto take = [&](double v) {
    if (p.log_y && !(v > 0)) return;
    lo = std::min(lo, v), hi = std::max(hi, v);
  };
  for (const auto& s : p.points)
    for (std::size_t i = 0; i < s.y.size(); ++i) take(s.y[i] - s.se[i]), take(s.y[i] + s.se[i]), take(s.y[i]);
  for (const auto& s : p.lines)
    for (double v : s.y) take(v);
  for (const auto& s : p.bands)
    for (std::size_t i = 0; i < s.x.size(); ++i) take(s.lo[i]), take(s.hi[i]);
  if (!(hi >= lo)) return p.log_y ? std::pair{1.0, 10.0} : std::pair{0.0, 1.0};
  if (p.log_y) return {std::pow(10.0, std::floor(std::log10(lo))), std::pow(10.0, std::ceil(std::log10(hi) + 1e-12))};
  const double pad = hi > lo ? 0.05 * (hi - lo) : 0.5 * std::max(1.0, std::abs(hi));
  return {lo - pad, hi + pad};
}

std::mutex& plplot_mutex() {
  static std::mutex m;
  return m;
}

// Holds the lock on PLplot (every function below runs under it).
using Lock = std::lock_guard<std::mutex>;

bool has_device(const char* name) {
  const char** menu = nullptr;
  const char** devs = nullptr;
  int n = 64;
  std::vector<const char*> m(static_cast<std::size_t>(n)), d(static_cast<std::size_t>(n));
  menu = m.data(), devs = d.data();
  plgDevs(&menu, &devs, &n);
  for (int i = 0; i < n; ++i)
    if (devs[i] && std::strcmp(devs[i], name) == 0) return true;
  return false;
}

// Text size relative to PLplot's default (which is large for a 900-pixel page); a default-size
// character is ~14 pixels wide on average with the cairo drivers.
constexpr double kTextScale = 0.8, kCharPixels = 14.0;

// Characters drawn (sub/superscript markup and escapes not counted).
std::size_t glyphs(const std::string& markup) {
  std::size_t n = 0;
  for (unsigned char c : plain_text(markup)) n += (c & 0xC0) != 0x80;
  return n;
}

constexpr const char* kMarker = "\xE2\x97\x8F";  // U+25CF BLACK CIRCLE, drawn centred on each point

// PLplot's line styles (pllsty): the pattern is drawn and shown in the legend alike.
PLINT style_of(Dash d) {
  switch (d) {
    case Dash::solid: return 1;
    case Dash::dashed: return 2;
    case Dash::long_dash: return 3;
    case Dash::dash_dot: return 5;
    case Dash::dotted: return 7;
    case Dash::dash_dot_dot: return 6;
  }
  return 1;
}

// cmap0 entries: 0 background, 1 black, 2 grid grey, then one per series colour.
struct Palette {
  std::vector<Rgb> colours{{255, 255, 255}, {0, 0, 0}, {0xE2, 0xE2, 0xE2}};
  PLINT index(Rgb c) {
    for (std::size_t i = 0; i < colours.size(); ++i)
      if (colours[i].r == c.r && colours[i].g == c.g && colours[i].b == c.b) return static_cast<PLINT>(i);
    colours.push_back(c);
    return static_cast<PLINT>(colours.size() - 1);
  }
};

// Plot coordinates: logarithmic axes are drawn in log10 of the value.
struct Axes {
  bool log = false, log_x = false;
  double floor = 0;  ///< log: values <= 0 (error bars reaching below) are drawn at this log10 value
  double y(double v) const { return log ? (v > 0 ? std::max(std::log10(v), floor) : floor) : v; }
  double x(double v) const { return log_x ? std::log10(v) : v; }
  /// Whether (x, y) can be drawn at all (a logarithmic axis has no place for values <= 0).
  bool shown(double xv, double yv) const { return (!log_x || xv > 0) && (!log || yv > 0); }
};

void draw_bands(const Panel& p, const Axes& ax, Palette& pal) {
  for (const auto& b : p.bands) {
    if (b.x.size() < 2) continue;
    std::vector<PLFLT> x, y;
    for (std::size_t i = 0; i < b.x.size(); ++i)
      if (ax.shown(b.x[i], 1)) x.push_back(ax.x(b.x[i])), y.push_back(ax.y(b.lo[i]));
    for (std::size_t i = b.x.size(); i-- > 0;)
      if (ax.shown(b.x[i], 1)) x.push_back(ax.x(b.x[i])), y.push_back(ax.y(b.hi[i]));
    if (x.size() < 3) continue;
    plcol0(pal.index(b.colour));
    plfill(static_cast<PLINT>(x.size()), x.data(), y.data());
  }
}

// A line; on a log panel it breaks where y <= 0 (a law that vanishes there).
void draw_lines(const Panel& p, const Axes& ax, Palette& pal) {
  for (const auto& l : p.lines) {
    plcol0(pal.index(l.colour));
    pllsty(style_of(l.dash));
    plwidth(l.width);
    std::vector<PLFLT> x, y;
    auto flush = [&] {
      if (x.size() >= 2) plline(static_cast<PLINT>(x.size()), x.data(), y.data());
      x.clear(), y.clear();
    };
    for (std::size_t i = 0; i < l.x.size(); ++i) {
      if (!ax.shown(l.x[i], l.y[i])) {
        flush();
        continue;
      }
      x.push_back(ax.x(l.x[i])), y.push_back(ax.y(l.y[i]));
    }
    flush();
  }
  pllsty(1);
  plwidth(1);
}

void draw_points(const Panel& p, const Axes& ax, Palette& pal) {
  for (const auto& s : p.points) {
    std::vector<PLFLT> x, y, lo, hi;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!ax.shown(s.x[i], s.y[i])) continue;
      x.push_back(ax.x(s.x[i])), y.push_back(ax.y(s.y[i]));
      lo.push_back(ax.y(s.y[i] - s.se[i])), hi.push_back(ax.y(s.y[i] + s.se[i]));
    }
    if (x.empty()) continue;
    plcol0(pal.index(s.colour));
    plwidth(1.2);
    // Error bars where there is an error (a bar of zero length would still draw its end ticks).
    std::vector<PLFLT> bx, blo, bhi;
    for (std::size_t i = 0; i < x.size(); ++i)
      if (hi[i] > lo[i]) bx.push_back(x[i]), blo.push_back(lo[i]), bhi.push_back(hi[i]);
    if (!bx.empty()) plerry(static_cast<PLINT>(bx.size()), bx.data(), blo.data(), bhi.data());
    plschr(0, 0.5 * s.size);
    plstring(static_cast<PLINT>(x.size()), x.data(), y.data(), kMarker);
    plschr(0, kTextScale);
  }
  plwidth(1);
}

// The legend inside the panel (`width_px` wide): its text shrinks until its longest entry fits.
void draw_legend(const Panel& p, double width_px, Palette& pal) {
  if (p.legend == LegendAt::none) return;
  std::vector<std::string> texts;
  std::vector<PLINT> opt, colour, style, box_pattern, sym_n;
  std::vector<PLFLT> width, box_scale, box_width, sym_scale;
  std::vector<const char*> symbols;
  auto entry = [&](const auto& series, PLINT kind, Rgb c, PLINT st, PLFLT w) {
    if (!series.in_legend || series.label.empty()) return;
    const std::string& label = series.label;
    texts.push_back(plplot_text(label));
    opt.push_back(kind), colour.push_back(pal.index(c)), style.push_back(st), width.push_back(w);
    box_pattern.push_back(0), box_scale.push_back(0.8), box_width.push_back(1);
    sym_n.push_back(1), sym_scale.push_back(0.6), symbols.push_back(kMarker);
  };
  for (const auto& s : p.points) entry(s, PL_LEGEND_SYMBOL, s.colour, 1, 1);
  for (const auto& l : p.lines) entry(l, PL_LEGEND_LINE, l.colour, style_of(l.dash), l.width);
  for (const auto& b : p.bands) entry(b, PL_LEGEND_COLOR_BOX, b.colour, 1, 1);
  if (texts.empty()) return;
  std::vector<const char*> text;
  for (const auto& t : texts) text.push_back(t.c_str());
  std::vector<PLINT> text_colour(texts.size(), 1);
  PLINT pos = PL_POSITION_INSIDE | PL_POSITION_VIEWPORT;
  pos |= p.legend == LegendAt::bottom_right ? PL_POSITION_BOTTOM | PL_POSITION_RIGHT
         : p.legend == LegendAt::top_left   ? PL_POSITION_TOP | PL_POSITION_LEFT
                                            : PL_POSITION_TOP | PL_POSITION_RIGHT;
  const auto n = static_cast<PLINT>(texts.size());
  std::size_t longest = 1;
  auto longest_of = [&](const auto& series) {
    for (const auto& x : series)
      if (x.in_legend) longest = std::max(longest, glyphs(x.label));
  };
  longest_of(p.points), longest_of(p.lines), longest_of(p.bands);
  constexpr double scale = 0.8;  // of the current text size
  const double room = 0.9 * width_px - 0.08 * width_px - 40;  // minus the symbols' column and the margins
  const double text_scale = std::max(0.45, scale * std::min(1.0, room / (static_cast<double>(longest) * kCharPixels * kTextScale * scale)));
  PLFLT w = 0, h = 0;
  pllegend(&w, &h, 0, pos, 0.02, 0.03, 0.08, 0, 1, 1, n, 1, n, opt.data(), 0.8, text_scale, 1.7, 0.0, text_colour.data(),
           text.data(), colour.data(), box_pattern.data(), box_scale.data(), box_width.data(), colour.data(), style.data(),
           width.data(), colour.data(), sym_scale.data(), sym_n.data(), symbols.data());
}

// Tick labels of linear axes as plain numbers (%g): PLplot's own labels move a common power of ten
// into a "(x10^-3)" beside the axis, which collides with the title. `data` holds the axes' spans,
// to print rounding noise at zero (1e-17) as 0.
struct Spans {
  double x = 1, y = 1;
};

}  // namespace

std::string tick_text(double value, double span) {
  if (std::abs(value) < 1e-9 * span) value = 0;
  char text[64];
  std::snprintf(text, sizeof text, "%g", value);
  // "2e+06" as "2×10^6" (PLplot's superscript escapes, in our own text only).
  std::string out = text;
  if (const auto e = out.find('e'); e != std::string::npos) {
    const std::string mantissa = out.substr(0, e);
    const int exponent = std::atoi(out.c_str() + e + 1);
    out = (mantissa == "1" ? "" : mantissa == "-1" ? "-" : mantissa + "\xC3\x97") + "10#u" + std::to_string(exponent) + "#d";
  }
  return out;
}

YAxisLayout y_axis_layout(double lo, double hi, bool log) {
  YAxisLayout l;
  if (log) {  // PLplot's own ticks at the decades, labels 10^k: at most ~4 glyphs wide
    l.widest = 4, l.title_disp = 4.6;
    return l;
  }
  // A step of 1, 2 or 5 x 10^k giving 4-8 intervals, as PLplot would choose; fixed here so that
  // every label is known before drawing.
  const double span = hi - lo, raw = span / 6, mag = std::pow(10.0, std::floor(std::log10(raw))), f = raw / mag;
  l.step = (f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10) * mag;
  for (double k = std::ceil(lo / l.step); k * l.step <= hi + 1e-9 * span; k += 1) {
    std::string t = tick_text(k * l.step, span);
    std::size_t n = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (t[i] == '#') { ++i; continue; }             // #u, #d: super/subscript switches, no glyph
      if ((static_cast<unsigned char>(t[i]) & 0xC0) != 0x80) ++n;  // UTF-8: count lead bytes only
    }
    l.widest = std::max(l.widest, n);
  }
  // The labels end kTickGap from the axis and are kGlyphWidth per glyph wide; the title's centre
  // sits half its height plus a gap beyond them.
  l.title_disp = std::max(4.0, kTickGap + kGlyphWidth * static_cast<double>(l.widest) + 1.0);
  return l;
}

namespace {

void number_label(PLINT axis, PLFLT value, char* label, PLINT length, PLPointer data) {
  const auto* s = static_cast<const Spans*>(data);
  const std::string out = tick_text(value, axis == PL_X_AXIS ? s->x : s->y);
  std::snprintf(label, static_cast<std::size_t>(length), "%s", out.c_str());
}

// One panel in the viewport [vx0, vx1] x [vy0, vy1] (fractions of the page).
void draw_panel(const Figure& fig, const Panel& p, double vx0, double vx1, double vy0, double vy1, Palette& pal) {
  const auto [xa, xb] = x_range(fig);
  const auto [ya, yb] = y_range(p);
  Axes ax;
  ax.log = p.log_y, ax.log_x = fig.log_x;
  if (ax.log) ax.floor = std::log10(ya) - 1;
  const YAxisLayout yl = y_axis_layout(ax.y(ya), ax.y(yb), ax.log);
  plvpor(vx0, vx1, vy0, vy1);
  plwind(ax.x(xa), ax.x(xb), ax.y(ya), ax.y(yb));
  if (p.grid) {
    plcol0(2);
    plbox(ax.log_x ? "gh" : "g", 0, 0, ax.log ? "gh" : "g", 0, 0);
  }
  draw_bands(p, ax, pal);
  draw_lines(p, ax, pal);
  draw_points(p, ax, pal);
  plcol0(1);
  Spans spans{xb - xa, yb - ya};
  plslabelfunc(number_label, &spans);
  plbox(ax.log_x ? "bcnstl" : "bcnsto", 0, 0, ax.log ? "bcnstlv" : "bcnstvo", yl.step, 0);
  plslabelfunc(nullptr, nullptr);
  plmtex("b", 3.0, 0.5, 0.5, plplot_text(fig.xlabel).c_str());
  plmtex("l", yl.title_disp, 0.5, 0.5, plplot_text(p.ylabel).c_str());
  draw_legend(p, (vx1 - vx0) * fig.width / fig.resolution_scale, pal);
}


// The title, shrunk to fit the page width; a title too long even then is split in two lines at
// the ", " or ": " nearest its middle (outside braces, so no sub/superscript is cut).
void draw_title(const Figure& fig) {
  const double fit = 0.95 * fig.width / fig.resolution_scale / kCharPixels;  // characters that fit at scale 1
  const std::string& t = fig.title;
  std::vector<std::string> lines{t};
  if (static_cast<double>(glyphs(t)) > fit / 0.65) {
    std::size_t best = std::string::npos;
    int depth = 0;
    for (std::size_t i = 0; i + 1 < t.size(); ++i) {
      if (t[i] == '\\') ++i;
      else if (t[i] == '{') ++depth;
      else if (t[i] == '}') --depth;
      else if (depth == 0 && (t[i] == ',' || t[i] == ':') && t[i + 1] == ' ' &&
               (best == std::string::npos || std::abs(double(i) - t.size() / 2.0) < std::abs(double(best) - t.size() / 2.0)))
        best = i;
    }
    if (best != std::string::npos) lines = {t.substr(0, best + 1), t.substr(best + 2)};
  }
  std::size_t longest = 0;
  for (const auto& l : lines) longest = std::max(longest, glyphs(l));
  const double scale = std::clamp(fit / std::max<double>(1, static_cast<double>(longest)), 0.5, 1.05);
  plvpor(0, 1, 0, 1);
  plwind(0, 1, 0, 1);
  plcol0(1);
  plschr(0, scale);
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const double y = 1 - (lines.size() == 1 ? 32.0 : 20.0 + 26.0 * static_cast<double>(k)) * fig.resolution_scale / fig.height;
    plptex(0.5, y, 1, 0, 0.5, plplot_text(lines[k]).c_str());
  }
  plschr(0, kTextScale);
}

void draw(const Figure& fig, Palette& pal) {
  pladv(0);
  plschr(0, kTextScale);
  // Margins in pixels of the scale-1 page (PlotFormats::scale scales page and resolution alike).
  const double px_x = fig.resolution_scale / fig.width, px = fig.resolution_scale / fig.height;
  // The left margin holds the widest panel's y title (its outer half-height beyond its centre).
  PLFLT char_mm = 0, ht_mm = 0;
  plgchr(&char_mm, &ht_mm);
  // One character height in pixels of the scale-1 page: plgchr answers in millimetres of the page as
  // drawn, whose resolution (and so the characters' size in mm) grows with the size factor @S.
  const double char_px = ht_mm / 25.4 * 90.0 / fig.resolution_scale;
  double title_disp = 0;
  for (const Panel& p : fig.panels) {
    const auto [ya, yb] = y_range(p);
    Axes ax;
    ax.log = p.log_y;
    if (ax.log) ax.floor = std::log10(ya) - 1;
    title_disp = std::max(title_disp, y_axis_layout(ax.y(ya), ax.y(yb), ax.log).title_disp);
  }
  const double left = std::max(95.0, (title_disp + 0.9) * char_px) * px_x, right = 1 - 30.0 * px_x;
  const double top = 1 - 70.0 * px, bottom = 72.0 * px, gap = 90.0 * px;
  const auto n = static_cast<double>(fig.panels.size());
  const double h = (top - bottom - gap * (n - 1)) / n;
  for (std::size_t k = 0; k < fig.panels.size(); ++k) {
    const double y1 = top - static_cast<double>(k) * (h + gap);
    draw_panel(fig, fig.panels[k], left, right, y1 - h, y1, pal);
  }
  draw_title(fig);
}

// The colours a figure uses, so that cmap0 can be set before plinit.
Palette palette_of(const Figure& fig) {
  Palette pal;
  for (const Panel& p : fig.panels) {
    for (const auto& s : p.points) pal.index(s.colour);
    for (const auto& s : p.lines) pal.index(s.colour);
    for (const auto& s : p.bands) pal.index(s.colour);
  }
  return pal;
}

}  // namespace

std::string renderer_problem(ImageFormat format) {
  Lock lock(plplot_mutex());
  if (!has_device(device_of(format)))
    return std::string("PLplot's ") + device_of(format) + " driver is not installed (Debian: plplot-driver-cairo)";
  return "";
}

std::string render_figure(const Figure& fig, ImageFormat format) {
  validate(fig);
  Lock lock(plplot_mutex());
  if (!has_device(device_of(format)))
    throw std::runtime_error(std::string("PLplot's ") + device_of(format) + " driver is not installed (plplot-driver-cairo)");
  char* buf = nullptr;
  std::size_t size = 0;
  FILE* out = ::open_memstream(&buf, &size);
  if (!out) throw std::runtime_error(std::string("cannot draw a figure: ") + std::strerror(errno));
  Palette pal = palette_of(fig);
  PLINT code = 0;
  char message[1024] = "";
  plsdev(device_of(format));
  plsfile(out);  // closed by the driver in plend1
  plsError(&code, message);
  // The resolution scales with the size (PlotFormats::scale): text and line sizes are in mm, so
  // the drawing keeps its proportions at any size. 90 dpi is the cairo drivers' default.
  const PLFLT dpi = 90.0 * fig.resolution_scale;
  plspage(dpi, dpi, fig.width, fig.height, 0, 0);
  plscmap0n(static_cast<PLINT>(pal.colours.size()));
  for (std::size_t i = 0; i < pal.colours.size(); ++i)
    plscol0(static_cast<PLINT>(i), pal.colours[i].r, pal.colours[i].g, pal.colours[i].b);
  plinit();
  draw(fig, pal);
  plend1();
  std::string bytes(buf ? buf : "", buf ? size : 0);
  std::free(buf);
  if (code != 0) throw std::runtime_error(std::string("PLplot: ") + message);
  if (bytes.empty()) throw std::runtime_error("PLplot produced no output");
  return bytes;
}

#else  // built without PLplot: figures are off, and a run that asks for them is told why

std::string renderer_problem(ImageFormat) {
  return "this build has no PLplot (install libplplot-dev and plplot-driver-cairo, scripts/setup, and rebuild)";
}

std::string render_figure(const Figure& fig, ImageFormat format) {
  validate(fig);
  throw std::runtime_error("cannot draw figures: " + renderer_problem(format));
}

#endif

}  // namespace asperity::detail
