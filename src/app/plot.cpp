// SPDX-License-Identifier: GPL-3.0-or-later
// Figures of a run (plot.hpp): histogram and band figures built as Figure values, drawn by the one
// renderer (plot_render.cpp, PLplot), written with their data as CSV. Every file is created new
// under a name this run chose (O_CREAT | O_EXCL | O_NOFOLLOW, relative to the directory's
// descriptor) and renamed onto its final name: no partial file, no path followed out.
#include "asperity/app/plot.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "app/io/interrupt.hpp"
#include "plot_render.hpp"

namespace asperity {
namespace fs = std::filesystem;

namespace {

using detail::ImageFormat;

// ---- the histogram figure ----

/// Sample count for the legend: exact powers of ten >= 1000 as "10^{5}", anything else as the
/// plain integer (never rounded: the legend states the exact n).
std::string format_count(std::size_t n) {
  if (n >= 1000) {
    std::size_t k = n;
    int e = 0;
    while (k % 10 == 0) k /= 10, ++e;
    if (k == 1) return "10^{" + std::to_string(e) + "}";
  }
  return std::to_string(n);
}

void validate(const HistogramFigure& fig) {
  const std::string w = "histogram figure: ";
  const Histogram& h = fig.histogram;
  if (h.bins() == 0) throw std::invalid_argument(w + "histogram has no bins");
  if (h.total == 0) throw std::invalid_argument(w + "histogram is empty (total = 0)");
  if (!std::isfinite(h.lo) || !std::isfinite(h.hi) || !(h.hi > h.lo))
    throw std::invalid_argument(w + "histogram range [lo, hi) is not finite and increasing");
  double sum = 0;
  for (std::size_t i = 0; i < h.bins(); ++i) {
    if (!std::isfinite(h.counts[i]) || h.counts[i] < 0)
      throw std::invalid_argument(w + "count in bin " + std::to_string(i) + " is negative or not finite");
    sum += h.counts[i];
  }
  if (!(sum > 0)) throw std::invalid_argument(w + "histogram has no counts in [lo, hi)");
  if (!std::isfinite(fig.x_scale) || fig.x_scale == 0) throw std::invalid_argument(w + "x_scale is zero or not finite");
  if (!std::isfinite(fig.y_scale) || !(fig.y_scale > 0))
    throw std::invalid_argument(w + "y_scale is not positive and finite");
  for (const auto& c : fig.curves) {
    if (c.x.size() != c.y.size())
      throw std::invalid_argument(w + "curve \"" + c.label + "\" has x and y of different lengths");
    if (c.x.size() < 2) throw std::invalid_argument(w + "curve \"" + c.label + "\" has fewer than 2 points");
    for (std::size_t i = 0; i < c.x.size(); ++i)
      if (!std::isfinite(c.x[i] * fig.x_scale) || !std::isfinite(c.y[i] * fig.y_scale))
        throw std::invalid_argument(w + "curve \"" + c.label + "\" has a non-finite value at point " + std::to_string(i));
  }
}

// Curves after the data: the first solid, then dashed, dash-dotted... in Okabe-Ito colours.
std::vector<LineSeries> law_lines(const std::vector<Curve>& curves, double xs, double ys) {
  constexpr Dash dashes[] = {Dash::solid, Dash::dashed, Dash::dash_dot, Dash::dotted, Dash::long_dash, Dash::dash_dot_dot};
  std::vector<LineSeries> out;
  for (std::size_t k = 0; k < curves.size(); ++k) {
    LineSeries l;
    l.label = curves[k].label;
    l.colour = kOkabeIto[k % std::size(kOkabeIto)];
    l.dash = dashes[k % std::size(dashes)];
    for (std::size_t i = 0; i < curves[k].x.size(); ++i) l.x.push_back(curves[k].x[i] * xs), l.y.push_back(curves[k].y[i] * ys);
    out.push_back(std::move(l));
  }
  return out;
}

PointSeries histogram_points(const HistogramFigure& fig) {
  const Histogram& h = fig.histogram;
  PointSeries p;
  p.label = fig.data_label + " (n = " + format_count(h.total) + ")";
  for (std::size_t i = 0; i < h.bins(); ++i) {
    const double d = h.density(i) * fig.y_scale, e = h.density_se(i) * fig.y_scale;
    if (!std::isfinite(d) || !std::isfinite(e))
      throw std::invalid_argument("histogram figure: density in bin " + std::to_string(i) + " is not finite");
    p.x.push_back(h.centre(i) * fig.x_scale), p.y.push_back(d), p.se.push_back(e), p.count.push_back(h.counts[i]);
  }
  return p;
}

}  // namespace

Figure histogram_figure(const HistogramFigure& fig) {
  validate(fig);
  Figure f;
  f.title = fig.title;
  f.xlabel = fig.xlabel;
  f.x_lo = std::min(fig.histogram.lo * fig.x_scale, fig.histogram.hi * fig.x_scale);
  f.x_hi = std::max(fig.histogram.lo * fig.x_scale, fig.histogram.hi * fig.x_scale);
  Panel lin;
  lin.ylabel = fig.ylabel;
  lin.points = {histogram_points(fig)};
  lin.lines = law_lines(fig.curves, fig.x_scale, fig.y_scale);
  // The data set the ranges; a curve may raise them by at most a factor 2 (a divergent or badly
  // wrong curve must not squash the measurement).
  const PointSeries& pts = lin.points[0];
  double ymax = 0, ymin_pos = std::numeric_limits<double>::infinity(), curve_max = 0;
  for (std::size_t i = 0; i < pts.x.size(); ++i) {
    ymax = std::max(ymax, pts.y[i] + pts.se[i]);
    if (pts.count[i] > 0) ymin_pos = std::min(ymin_pos, pts.y[i]);
  }
  for (const auto& l : lin.lines)
    for (std::size_t i = 0; i < l.x.size(); ++i)
      if (l.x[i] >= f.x_lo && l.x[i] <= f.x_hi) curve_max = std::max(curve_max, l.y[i]);
  const double top = std::max(ymax, std::min(curve_max, 2.0 * ymax));
  // The legend sits in the top panel above everything plotted: headroom for its rows.
  // (~24 px per row in a plot area ~380 px high).
  const double key_frac = std::min(0.55, (24.0 * (1.0 + static_cast<double>(fig.curves.size())) + 30.0) / 380.0);
  lin.y_lo = 0, lin.y_hi = top / (1.0 - key_frac);
  // Log panel: from the decade at or below a third of the smallest non-zero density (a single
  // count sits clearly above the axis), at least two labelled decades. Empty bins are omitted.
  Panel log = lin;
  log.log_y = true, log.legend = LegendAt::none, log.grid = true;
  log.y_lo = std::pow(10.0, std::floor(std::log10(ymin_pos / 3.0)));
  log.y_hi = std::max(std::pow(10.0, std::ceil(std::log10(top * 1.5))), 100.0 * log.y_lo);
  PointSeries& lp = log.points[0];
  PointSeries kept = lp;
  kept.x.clear(), kept.y.clear(), kept.se.clear(), kept.count.clear();
  for (std::size_t i = 0; i < lp.x.size(); ++i)
    if (lp.count[i] > 0) kept.x.push_back(lp.x[i]), kept.y.push_back(lp.y[i]), kept.se.push_back(lp.se[i]), kept.count.push_back(lp.count[i]);
  lp = std::move(kept);
  f.panels = {std::move(lin), std::move(log)};
  return f;
}

Figure band_figure(const BandFigure& fig) {
  if (fig.x.size() != fig.y.size() || fig.x.size() != fig.se.size())
    throw std::invalid_argument("band figure: x, y and se have different lengths");
  Figure f;
  f.title = fig.title, f.xlabel = fig.xlabel;
  f.height = 720;
  Panel p;
  p.ylabel = fig.ylabel;
  p.grid = true;
  PointSeries pts;
  pts.label = fig.data_label;
  pts.colour = {0x1f, 0x4e, 0x9c};
  for (std::size_t i = 0; i < fig.x.size(); ++i)
    pts.x.push_back(fig.x[i] * fig.x_scale), pts.y.push_back(fig.y[i] * fig.y_scale), pts.se.push_back(fig.se[i] * fig.y_scale);
  p.points = {std::move(pts)};
  constexpr Rgb colours[] = {{0xc0, 0x39, 0x2b}, {0x55, 0x55, 0x55}};
  p.lines = law_lines(fig.curves, fig.x_scale, fig.y_scale);
  for (std::size_t k = 0; k < p.lines.size(); ++k) p.lines[k].colour = colours[k % 2], p.lines[k].dash = Dash::solid;
  // y from the data, with headroom above it for the legend's rows (~24 px each of ~580).
  double lo = 0, hi = 0;
  for (std::size_t i = 0; i < p.points[0].y.size(); ++i)
    lo = std::min(lo, p.points[0].y[i] - p.points[0].se[i]), hi = std::max(hi, p.points[0].y[i] + p.points[0].se[i]);
  for (const auto& l : p.lines)
    for (double v : l.y) lo = std::min(lo, v), hi = std::max(hi, v);
  if (hi > lo) {
    const double key_frac = std::min(0.5, (24.0 * (1.0 + static_cast<double>(p.lines.size())) + 30.0) / 580.0);
    p.y_lo = lo - 0.05 * (hi - lo), p.y_hi = hi + (hi - lo) * key_frac / (1.0 - key_frac);
  }
  f.panels = {std::move(p)};
  return f;
}

// ---- formats ----

PlotFormats parse_plot_formats(std::string_view text) {
  PlotFormats f{false, false, false};
  std::string_view rest = text;
  if (const auto at = text.find('@'); at != std::string_view::npos) {
    // A plain decimal number (std::from_chars, fixed or scientific): std::stod also took hex
    // ("png@0x2") and leading spaces ("png@ 2"), which no other number of asperity accepts.
    const std::string_view s = text.substr(at + 1);
    double v = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::general);
    const bool plain = !s.empty() && ((s[0] >= '0' && s[0] <= '9') || s[0] == '.');
    if (!plain || r.ec != std::errc() || r.ptr != s.data() + s.size() || !(v >= 0.25 && v <= 8))
      throw std::invalid_argument("plot format \"" + std::string(text) + "\": the size factor after '@' must be a number in [0.25, 8]");
    f.scale = v;
    rest = text.substr(0, at);
  }
  while (!rest.empty()) {
    const auto plus = rest.find('+');
    const std::string_view part = rest.substr(0, plus);
    bool* flag = part == "png" ? &f.png : part == "svg" ? &f.svg : part == "pdf" ? &f.pdf : nullptr;
    if (!flag || *flag) break;
    *flag = true;
    if (plus == std::string_view::npos) return f;
    rest = rest.substr(plus + 1);
  }
  throw std::invalid_argument("plot format \"" + std::string(text) +
                              "\": expected png, svg, pdf or a combination such as png+svg or png+pdf");
}

std::string to_string(const PlotFormats& f) {
  std::string s;
  for (auto [on, name] : {std::pair{f.png, "png"}, {f.svg, "svg"}, {f.pdf, "pdf"}})
    if (on) {
      if (!s.empty()) s += '+';
      s += name;
    }
  if (f.scale != 1) {
    std::ostringstream o;
    o.imbue(std::locale::classic());
    o << f.scale;
    s += "@" + o.str();
  }
  return s;
}

namespace {

std::vector<std::pair<ImageFormat, const char*>> formats_of(const PlotFormats& f) {
  std::vector<std::pair<ImageFormat, const char*>> out;
  if (f.png) out.emplace_back(ImageFormat::png, ".png");
  if (f.svg) out.emplace_back(ImageFormat::svg, ".svg");
  if (f.pdf) out.emplace_back(ImageFormat::pdf, ".pdf");
  return out;
}

}  // namespace

std::string plotting_problem(const PlotFormats& formats) {
  for (const auto& [format, ext] : formats_of(formats))
    if (std::string p = detail::renderer_problem(format); !p.empty()) return p;
  return "";
}

bool plotting_available() { return plotting_problem().empty(); }

// ---- CSV ----

namespace {

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos && (s.empty() || (s.front() != ' ' && s.back() != ' '))) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string csv_number(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest text that reads back exactly
  return std::string(buf, r.ptr);
}

/// "[1/µm]" of "probability density [1/µm]" ("" if none).
std::string unit_of(const std::string& label) {
  const auto open = label.rfind('[');
  if (open == std::string::npos || label.back() != ']') return "";
  return " " + label.substr(open);
}

/// The data panel's series in long format, one row per point: series, x, y, and the se, count,
/// band columns when a series has them. Columns are named by the axis labels with their units.
std::string figure_csv(const Figure& fig) {
  const Panel& p = fig.panels.at(fig.data_panel);
  const std::string x = detail::plain_text(fig.xlabel), y = detail::plain_text(p.ylabel), unit = unit_of(y);
  bool se = !p.points.empty(), count = false, band = !p.bands.empty();
  for (const auto& s : p.points) count = count || !s.count.empty();
  std::ostringstream o;
  o << "series," << csv_field(x.empty() ? "x" : x) << ',' << csv_field(y.empty() ? "y" : y);
  if (se) o << ',' << csv_field("se" + unit);
  if (count) o << ",count";
  if (band) o << ',' << csv_field("band low" + unit) << ',' << csv_field("band high" + unit);
  o << '\n';
  auto row = [&](const std::string& name, double xv, const std::string& yv, const std::string& sev, const std::string& cv,
                 const std::string& lo, const std::string& hi) {
    o << csv_field(detail::plain_text(name)) << ',' << csv_number(xv) << ',' << yv;
    if (se) o << ',' << sev;
    if (count) o << ',' << cv;
    if (band) o << ',' << lo << ',' << hi;
    o << '\n';
  };
  for (const auto& s : p.points)
    for (std::size_t i = 0; i < s.x.size(); ++i)
      row(s.label, s.x[i], csv_number(s.y[i]), csv_number(s.se[i]), s.count.empty() ? "" : csv_number(s.count[i]), "", "");
  for (const auto& l : p.lines)
    for (std::size_t i = 0; i < l.x.size(); ++i) row(l.label, l.x[i], csv_number(l.y[i]), "", "", "", "");
  for (const auto& b : p.bands)
    for (std::size_t i = 0; i < b.x.size(); ++i) row(b.label, b.x[i], "", "", "", csv_number(b.lo[i]), csv_number(b.hi[i]));
  return o.str();
}

}  // namespace

// ---- files ----

namespace {

/// An open descriptor, closed on every path out.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

[[noreturn]] void fail(const fs::path& file, int err) {
  throw std::runtime_error("cannot write " + file.string() + ": " + std::generic_category().message(err));
}

std::string temporary_name() {
  std::random_device rd;
  std::ostringstream s;
  s << ".plot-" << ::getpid() << '-' << std::hex << rd() << rd() << ".tmp";
  return s.str();
}

void write_all(int fd, const std::string& bytes, const fs::path& file) {
  const char* p = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t w = ::write(fd, p, left);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) fail(file, w < 0 ? errno : EIO);
    p += w, left -= static_cast<std::size_t>(w);
  }
}

/// Writes `bytes` to dir/name: a new file under a name of our own in `dir`, created with
/// O_EXCL | O_NOFOLLOW relative to dir's descriptor (a symlink planted there is refused, never
/// followed), then renamed onto `name` in the same directory. On failure nothing remains.
void write_new_file(const fs::path& dir, const std::string& name, const std::string& bytes) {
  const fs::path file = dir / name;
  Fd d;
  d.fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (d.fd < 0) fail(file, errno);
  const std::string tmp = temporary_name();
  InterruptCleanup on_signal(dir / tmp, InterruptCleanup::Kind::file);
  Fd f;
  f.fd = ::openat(d.fd, tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  on_signal.created();
  if (f.fd < 0) fail(file, errno);
  try {
    write_all(f.fd, bytes, file);
    const int fd = f.fd;
    f.fd = -1;
    if (::close(fd) != 0) fail(file, errno);  // NFS and full disks report here
    if (::renameat(d.fd, tmp.c_str(), d.fd, name.c_str()) != 0) fail(file, errno);
  } catch (...) {
    ::unlinkat(d.fd, tmp.c_str(), 0);
    throw;
  }
}

void remove_written(const fs::path& dir, const std::vector<std::string>& names) {
  for (const auto& n : names) {
    std::error_code ec;
    fs::remove(dir / n, ec);
  }
}

}  // namespace

std::vector<std::string> write_figure(const fs::path& dir, const std::string& stem, const Figure& fig,
                                      const PlotFormats& formats) {
  if (stem.empty() || stem.find('/') != std::string::npos || stem == "." || stem == "..")
    throw std::invalid_argument("write_figure: \"" + stem + "\" is not a plain file name");
  // Everything is drawn first (in memory): a figure PLplot cannot draw writes nothing.
  std::vector<std::pair<std::string, std::string>> files;
  Figure sized = fig;
  sized.width = static_cast<int>(std::lround(fig.width * formats.scale));
  sized.height = static_cast<int>(std::lround(fig.height * formats.scale));
  sized.resolution_scale = formats.scale;
  for (const auto& [format, ext] : formats_of(formats)) files.emplace_back(stem + ext, detail::render_figure(sized, format));
  files.emplace_back(stem + ".csv", figure_csv(fig));
  std::vector<std::string> written;
  try {
    for (const auto& [name, bytes] : files) {
      write_new_file(dir, name, bytes);
      written.push_back(name);
    }
  } catch (...) {
    remove_written(dir, written);
    throw;
  }
  return written;
}

void write_histogram_png(const fs::path& png, const HistogramFigure& fig) {
  if (!png.has_filename()) throw std::invalid_argument("write_histogram_png: output path has no file name");
  write_figure(png.parent_path(), png.stem().string(), histogram_figure(fig));
}

std::vector<std::string> write_figures(const fs::path& dir, const std::vector<NamedFigure>& figures,
                                       const PlotFormats& formats) {
  std::vector<std::string> names;
  try {
    for (const auto& f : figures) {
      const auto files = write_figure(dir, fs::path(f.file).stem().string(), histogram_figure(f.figure), formats);
      names.insert(names.end(), files.begin(), files.end());
    }
  } catch (...) {
    remove_written(dir, names);
    throw;
  }
  return names;
}

std::vector<std::string> image_files(const std::vector<std::string>& files) {
  std::vector<std::string> out;
  for (const auto& f : files)
    if (fs::path(f).extension() != ".csv") out.push_back(f);
  return out;
}

std::vector<std::string> data_files(const std::vector<std::string>& files) {
  std::vector<std::string> out;
  for (const auto& f : files)
    if (fs::path(f).extension() == ".csv") out.push_back(f);
  return out;
}

}  // namespace asperity
