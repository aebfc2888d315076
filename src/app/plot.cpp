// SPDX-License-Identifier: GPL-3.0-or-later
// Histogram-vs-theory figures drawn by gnuplot (pngcairo). The script and its inline data go to a
// private temporary directory, gnuplot renders to a temporary file beside the target, and the
// result is renamed onto the target only when gnuplot succeeded: a failure never leaves a partial
// PNG, and temporaries are always removed (also on a signal: interrupt.hpp). gnuplot runs as a
// child in its own process group (posix_spawn, no shell), so a signal to us is not blocked while
// it runs (as system() would) and the handler kills it.
#include "asperity/app/plot.hpp"

#include <signal.h>
#include <spawn.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>
#include <fcntl.h>

#include <cerrno>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <limits>
#include <locale>
#include <random>
#include <exception>
#include <sstream>
#include <thread>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "asperity/app/interrupt.hpp"

extern char** environ;

namespace asperity {
namespace fs = std::filesystem;

namespace {

/// A gnuplot single-quoted string (no backslash processing; ' is doubled). Used for paths.
std::string gp_path(const fs::path& p) {
  std::string out = "'";
  for (char c : p.string()) {
    if (c == '\'') out += "''";
    else out += c;
  }
  out += '\'';
  return out;
}

/// A gnuplot double-quoted string for labels (enhanced text is kept: r_{xy}, 10^{6}).
/// Backslashes and double quotes are escaped; control characters become spaces.
std::string gp_text(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n' || c == '\r' || c == '\t') {
      out += ' ';
    } else {
      out += c;
    }
  }
  out += '"';
  return out;
}

/// Runs gnuplot with `args` (no shell), stdin and stdout on /dev/null, stderr into `err_file`
/// (or /dev/null), in its own process group, registered for the interrupt handler. True when it
/// exited normally with status 0; `spawn_error` gets errno when it could not be started.
bool run_gnuplot_process(const std::vector<std::string>& args, const fs::path& err_file, int* spawn_error = nullptr) {
  posix_spawn_file_actions_t fa;
  posix_spawnattr_t at;
  posix_spawn_file_actions_init(&fa);
  posix_spawnattr_init(&at);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, err_file.empty() ? "/dev/null" : err_file.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0600);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  for (int sg : {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGQUIT}) sigaddset(&defaults, sg);
  posix_spawnattr_setsigmask(&at, &none);
  posix_spawnattr_setsigdefault(&at, &defaults);
  posix_spawnattr_setpgroup(&at, 0);  // its own group: the terminal's ^C reaches us, we kill it
  posix_spawnattr_setflags(&at, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  InterruptChild on_signal;
  const int rc = posix_spawnp(&pid, argv[0], &fa, &at, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&at);
  if (rc != 0) {
    if (spawn_error) *spawn_error = rc;
    return false;
  }
  on_signal.started(pid);
  int status = 0;
  pid_t w;
  do {
    w = ::waitpid(pid, &status, 0);
  } while (w == -1 && errno == EINTR);
  return w == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

/// " (no space left on device: N bytes free)" when the file system of `dir` is (nearly) full.
std::string space_note(const fs::path& dir) {
  struct statvfs v {};
  if (::statvfs(dir.empty() ? "." : dir.c_str(), &v) != 0) return "";
  const double free_bytes = double(v.f_bavail) * double(v.f_frsize);
  if (free_bytes >= 1024.0 * 1024.0) return "";
  return ": no space left on device (" + std::to_string(static_cast<long long>(free_bytes)) + " bytes free in " +
         (dir.empty() ? std::string(".") : dir.string()) + ")";
}

/// The first lines of gnuplot's messages (a full disk makes two screens of warnings).
std::string first_lines(const std::string& text, int lines = 6) {
  std::size_t pos = 0;
  for (int i = 0; i < lines; ++i) {
    pos = text.find('\n', pos);
    if (pos == std::string::npos) return text;
    ++pos;
  }
  return text.substr(0, pos) + "... (more gnuplot messages not shown)";
}

std::string random_suffix() {
  std::random_device rd;
  std::ostringstream s;
  s << ::getpid() << '-' << std::hex << rd() << rd();
  return s.str();
}

std::string read_file_text(const fs::path& p, std::size_t max_chars = 4000) {
  std::ifstream in(p, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.size() > max_chars) text = text.substr(0, max_chars) + "...";
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

/// Removes its paths (recursively) when it goes out of scope, ignoring errors.
struct Cleanup {
  std::vector<fs::path> paths;
  ~Cleanup() {
    for (const auto& p : paths) {
      std::error_code ec;
      fs::remove_all(p, ec);
    }
  }
};

/// Sample count for the legend: exact powers of ten >= 1000 as enhanced-text "10^{5}", anything
/// else as the plain integer (never rounded: the legend states the exact n).
std::string format_count(std::size_t n) {
  if (n >= 1000) {
    std::size_t k = n;
    int e = 0;
    while (k % 10 == 0) {
      k /= 10;
      ++e;
    }
    if (k == 1) return "10^{" + std::to_string(e) + "}";
  }
  return std::to_string(n);
}

void validate(const HistogramFigure& fig) {
  const Histogram& h = fig.histogram;
  if (h.bins() == 0) throw std::invalid_argument("write_histogram_png: histogram has no bins");
  if (h.total == 0) throw std::invalid_argument("write_histogram_png: histogram is empty (total = 0)");
  if (!std::isfinite(h.lo) || !std::isfinite(h.hi) || !(h.hi > h.lo))
    throw std::invalid_argument("write_histogram_png: histogram range [lo, hi) is not finite and increasing");
  double sum = 0;
  for (std::size_t i = 0; i < h.bins(); ++i) {
    if (!std::isfinite(h.counts[i]) || h.counts[i] < 0)
      throw std::invalid_argument("write_histogram_png: histogram count in bin " + std::to_string(i) +
                                  " is negative or not finite");
    sum += h.counts[i];
  }
  if (!(sum > 0)) throw std::invalid_argument("write_histogram_png: histogram has no counts in [lo, hi)");
  if (!std::isfinite(fig.x_scale) || fig.x_scale == 0)
    throw std::invalid_argument("write_histogram_png: x_scale is zero or not finite");
  if (!std::isfinite(fig.y_scale) || !(fig.y_scale > 0))
    throw std::invalid_argument("write_histogram_png: y_scale is not positive and finite");
  for (const auto& c : fig.curves) {
    if (c.x.size() != c.y.size())
      throw std::invalid_argument("write_histogram_png: curve \"" + c.label + "\" has x and y of different lengths");
    if (c.x.size() < 2)
      throw std::invalid_argument("write_histogram_png: curve \"" + c.label + "\" has fewer than 2 points");
    for (std::size_t i = 0; i < c.x.size(); ++i)
      if (!std::isfinite(c.x[i]) || !std::isfinite(c.y[i]))
        throw std::invalid_argument("write_histogram_png: curve \"" + c.label + "\" has a non-finite value at point " +
                                    std::to_string(i));
  }
}

struct Style {
  const char* colour;
  const char* dash;  // gnuplot dashtype
};
// Colour-blind-safe (Okabe-Ito) line colours; the first curve solid, then dashed, dash-dotted...
constexpr Style kCurveStyles[] = {
    {"#D55E00", "solid"}, {"#0072B2", "(14,8)"}, {"#009E73", "(18,7,3,7)"},
    {"#CC79A7", "(3,6)"}, {"#E69F00", "(8,8)"}, {"#56B4E9", "(24,8)"},
};

// What the data blocks found: the x range and the largest/smallest values the panels must show.
struct ScriptRanges {
  double xa = 0, xb = 0;                                          ///< x range (scaled, increasing)
  double ymax = 0;                                                ///< largest density + se
  double ymin_pos = std::numeric_limits<double>::infinity();      ///< smallest density of a non-empty bin
  double curve_max = 0;                                           ///< largest curve value inside [xa, xb]
};

// $hist: x, density, se, count per bin (scaled).
void write_histogram_block(std::ostream& s, const HistogramFigure& fig, ScriptRanges& r) {
  const Histogram& h = fig.histogram;
  const double xs = fig.x_scale, ys = fig.y_scale;
  s << "$hist << EOD\n";
  for (std::size_t i = 0; i < h.bins(); ++i) {
    const double d = h.density(i) * ys, e = h.density_se(i) * ys;
    if (!std::isfinite(d) || !std::isfinite(e))
      throw std::invalid_argument("write_histogram_png: density in bin " + std::to_string(i) + " is not finite");
    s << h.centre(i) * xs << ' ' << d << ' ' << e << ' ' << h.counts[i] << '\n';
    r.ymax = std::max(r.ymax, d + e);
    if (h.counts[i] > 0) r.ymin_pos = std::min(r.ymin_pos, d);
  }
  s << "EOD\n";
  r.xa = h.lo * xs, r.xb = h.hi * xs;
  if (r.xa > r.xb) std::swap(r.xa, r.xb);
}

// $curve0, $curve1, ...: x, y per point (scaled).
void write_curve_blocks(std::ostream& s, const HistogramFigure& fig, ScriptRanges& r) {
  for (std::size_t k = 0; k < fig.curves.size(); ++k) {
    const Curve& c = fig.curves[k];
    s << "$curve" << k << " << EOD\n";
    for (std::size_t i = 0; i < c.x.size(); ++i) {
      const double x = c.x[i] * fig.x_scale, y = c.y[i] * fig.y_scale;
      if (!std::isfinite(x) || !std::isfinite(y))
        throw std::invalid_argument("write_histogram_png: scaled curve \"" + c.label + "\" is not finite");
      s << x << ' ' << y << '\n';
      if (x >= r.xa && x <= r.xb) r.curve_max = std::max(r.curve_max, y);
    }
    s << "EOD\n";
  }
}

void write_common_style(std::ostream& s, const HistogramFigure& fig, const fs::path& out, const ScriptRanges& r) {
  s << "set encoding utf8\n"
    << "set terminal pngcairo size 900,1000 enhanced font 'sans,12' linewidth 1.2 rounded\n"
    << "set output " << gp_path(out) << "\n"
    << "set border 31 linewidth 1.0\n"
    << "set minussign\n"
    << "set pointintervalbox 0.01\n"  // no white halo around points with error bars (0 = default)
    << "set errorbars 0.7\n"
    << "set xtics in mirror scale 1.2,0.6\n"
    << "set ytics in mirror scale 1.2,0.6\n"
    << "unset x2tics\nunset y2tics\n"
    << "set mxtics\n"
    << "set xrange [" << r.xa << ":" << r.xb << "]\n"
    << "set xlabel " << gp_text(fig.xlabel) << "\n"
    << "set ylabel " << gp_text(fig.ylabel) << " offset 0.5,0\n"
    << "set key top right reverse Left samplen 3.5 spacing 1.25 width 1 nobox\n"
    << "set style line 100 linecolor rgb '#E2E2E2' linewidth 0.8 dashtype solid\n"
    << "set lmargin 12\nset rmargin 4\n"
    << "set multiplot layout 2,1 title " << gp_text(fig.title) << " font 'sans,14'\n";
}

// Legend entry for the data first, then the curves, then the data drawn on top without a title.
void write_plot_command(std::ostream& s, const HistogramFigure& fig, bool log_panel) {
  const std::string data_title = fig.data_label + " (n = " + format_count(fig.histogram.total) + ")";
  s << "plot NaN with yerrorbars pointtype 7 pointsize 0.6 linecolor rgb '#000000' linewidth 1 title "
    << gp_text(data_title);
  for (std::size_t k = 0; k < fig.curves.size(); ++k) {
    const Style& st = kCurveStyles[k % std::size(kCurveStyles)];
    s << ", \\\n     $curve" << k << " using 1:"
      << (log_panel ? "($2 > 0 ? $2 : NaN)" : "2")
      << " with lines linewidth 2.2 linecolor rgb '" << st.colour << "' dashtype " << st.dash << " title "
      << gp_text(fig.curves[k].label);
  }
  s << ", \\\n     $hist using 1:"
    << (log_panel ? "($4 > 0 ? $2 : NaN):($2 - $3 > LOGFLOOR ? $2 - $3 : LOGFLOOR):($2 + $3)" : "2:3")
    << " with yerrorbars pointtype 7 pointsize 0.6 linecolor rgb '#000000' linewidth 1 notitle\n";
}

// Top panel, linear. The legend sits in it above everything plotted: leave headroom for its rows
// (~21 px each at 12 pt, in a plot area ~400 px high).
void write_linear_panel(std::ostream& s, const HistogramFigure& fig, const ScriptRanges& r) {
  const double key_rows = 1.0 + static_cast<double>(fig.curves.size());
  const double key_frac = std::min(0.5, (21.0 * key_rows + 24.0) / 400.0);
  const double ytop = std::max(r.ymax, r.curve_max) / (1.0 - key_frac);
  s << "set yrange [0:" << ytop << "]\n"
    << "set mytics\n"
    << "set format y '%g'\n"
    << "set grid noxtics noytics\n";
  write_plot_command(s, fig, false);
}

// Bottom panel, logarithmic. Lower bound: the decade at or below a third of the smallest non-zero
// density, so the lowest point (a single count) sits clearly above the axis. No legend here.
void write_log_panel(std::ostream& s, const HistogramFigure& fig, const ScriptRanges& r) {
  const double lo_decade = std::pow(10.0, std::floor(std::log10(r.ymin_pos / 3.0)));
  const double hi_decade = std::max(std::pow(10.0, std::ceil(std::log10(std::max(r.ymax, r.curve_max) * 1.5))),
                                    100.0 * lo_decade);  // at least two labelled decades
  s << "LOGFLOOR = " << lo_decade / 10.0 << "\n"
    << "set logscale y 10\n"
    << "set yrange [" << lo_decade << ":" << hi_decade << "]\n"
    << "set format y '10^{%L}'\n"
    << "set mytics 10\n"
    << "unset key\n"
    << "set grid ytics linestyle 100\n";
  write_plot_command(s, fig, true);
}

std::string build_script(const HistogramFigure& fig, const fs::path& out) {
  std::ostringstream s;
  s.imbue(std::locale::classic());
  s << std::setprecision(17);
  ScriptRanges r;
  write_histogram_block(s, fig, r);
  write_curve_blocks(s, fig, r);
  write_common_style(s, fig, out, r);
  // The data set the ranges; a curve may raise them by at most a factor 2 (a divergent or badly
  // wrong curve must not squash the measurement).
  r.curve_max = std::min(r.curve_max, 2.0 * r.ymax);
  write_linear_panel(s, fig, r);
  write_log_panel(s, fig, r);
  s << "unset multiplot\n"
    << "unset output\n";
  return s.str();
}

}  // namespace


bool plotting_available() {
  return run_gnuplot_process({"gnuplot", "-e", "set terminal pngcairo"}, {});
}

namespace {

// Renders the script `script_for(out)` with gnuplot into `png`: script and gnuplot's stderr in a
// private temporary directory, the image beside the target, renamed onto it only on success.
// `who` prefixes every message.
void run_gnuplot(const char* who, const fs::path& png, const std::function<std::string(const fs::path& out)>& script_for) {
  const std::string w = who;
  if (png.empty()) throw std::invalid_argument(w + ": empty output path");
  if (!png.has_filename()) throw std::invalid_argument(w + ": output path has no file name");
  const std::string suffix = random_suffix();

  // Private work directory for script and gnuplot's stderr.
  std::error_code ec;
  const fs::path tmp_root = fs::temp_directory_path(ec);
  if (ec) throw std::runtime_error(w + ": no temporary directory: " + ec.message());
  std::string stem = png.stem().string();
  for (char& c : stem)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  if (stem.size() > 64) stem.resize(64);
  const fs::path work = tmp_root / ("asperity-plot-" + stem + "-" + suffix);
  // Gnuplot renders beside the target so the final rename is atomic (same filesystem).
  const fs::path out = png.parent_path() / (png.filename().string() + "." + suffix + ".tmp");
  // Registered before they exist, and released only after `cleanup` (declared after them, so
  // destroyed first) removed them: a signal in between still finds them (interrupt.hpp).
  InterruptCleanup work_on_signal(work);
  InterruptCleanup out_on_signal(out, InterruptCleanup::Kind::file);
  out_on_signal.created();  // gnuplot creates it: the handler kills gnuplot before removing it
  Cleanup cleanup;
  cleanup.paths.push_back(out);
  const bool made = fs::create_directory(work, ec);
  work_on_signal.created();
  if (!made || ec)
    throw std::runtime_error(w + ": cannot create " + work.string() +
                             (ec ? ": " + ec.message() : std::string(": already exists")));
  cleanup.paths.push_back(work);

  const fs::path script = work / "figure.gp";
  const fs::path err = work / "gnuplot.err";
  {
    const std::string text = script_for(out);
    std::ofstream f(script, std::ios::binary);
    f << text;
    f.close();
    if (!f) throw std::runtime_error(w + ": cannot write " + script.string() + space_note(work));
  }

  int spawn_error = 0;
  const bool ok = run_gnuplot_process({"gnuplot", script.string()}, err, &spawn_error);
  const std::string messages = first_lines(read_file_text(err));
  if (spawn_error != 0)
    throw std::runtime_error(w + ": cannot run gnuplot: " + std::generic_category().message(spawn_error) +
                             " (is gnuplot installed? scripts/setup)");
  const bool produced = fs::is_regular_file(out, ec) && fs::file_size(out, ec) > 0 && !ec;
  if (!ok || !produced) {
    // A full disk explains itself; gnuplot's warnings would only hide it.
    if (const std::string full = space_note(png.parent_path()); !full.empty())
      throw std::runtime_error(w + ": cannot write " + png.string() + full);
    if (!ok)
      throw std::runtime_error(w + ": gnuplot failed writing " + png.string() +
                               (messages.empty() ? std::string(" (no message)") : ":\n" + messages));
    throw std::runtime_error(w + ": gnuplot produced no output for " + png.string() +
                             (messages.empty() ? std::string() : ":\n" + messages));
  }

  fs::rename(out, png, ec);
  if (ec) throw std::runtime_error(w + ": cannot rename onto " + png.string() + ": " + ec.message());
}

}  // namespace

void write_histogram_png(const fs::path& png, const HistogramFigure& fig) {
  if (png.empty()) throw std::invalid_argument("write_histogram_png: empty output path");
  if (!png.has_filename()) throw std::invalid_argument("write_histogram_png: output path has no file name");
  validate(fig);
  run_gnuplot("write_histogram_png", png, [&](const fs::path& out) { return build_script(fig, out); });
}

void write_gnuplot_png(const fs::path& png, const std::function<std::string(const fs::path& out)>& script_for) {
  run_gnuplot("write_gnuplot_png", png, script_for);
}

std::vector<std::string> write_figures(const fs::path& dir, const std::vector<NamedFigure>& figures) {
  // Each figure is its own gnuplot process: run them concurrently (gnuplot is single-threaded and
  // spends most of its time starting up and rendering), then report the first failure in order.
  std::vector<std::exception_ptr> errors(figures.size());
  {
    std::vector<std::thread> workers;
    for (std::size_t i = 0; i < figures.size(); ++i)
      workers.emplace_back([&, i] {
        try {
          write_histogram_png(dir / figures[i].file, figures[i].figure);
        } catch (...) {
          errors[i] = std::current_exception();
        }
      });
    for (auto& w : workers) w.join();
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);  // the run's own cleanup removes the figures it wrote
  std::vector<std::string> names;
  for (const auto& f : figures) names.push_back(f.file);
  return names;
}

}  // namespace asperity
