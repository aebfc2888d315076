// SPDX-License-Identifier: GPL-3.0-or-later
// Figures (app/plot.hpp): a Gaussian histogram against its pdf renders to a real PNG (and SVG,
// PDF) with its data as CSV; failures throw and leave nothing behind; invalid figures are rejected
// before anything is drawn; hostile labels draw glyphs and nothing else.
#include "asperity/app/plot.hpp"

#include "app/plot_render.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace asperity;

namespace {

/// A Gaussian (mean 0, sigma 1 µm) histogram filled by hand, with its pdf as the first curve and
/// a deliberately wrong (wider) Gaussian as a second, dashed curve.
HistogramFigure gaussian_figure(std::size_t n = 100000) {
  const double sigma = 1e-6;
  HistogramFigure fig;
  fig.title = "r_{x}, Gaussian test, n = 10^{5}";
  fig.xlabel = "r_x [µm]";
  fig.ylabel = "probability density [µm^{-1}]";
  fig.x_scale = 1e6;
  fig.y_scale = 1e-6;
  Histogram& h = fig.histogram;
  h.lo = -5 * sigma;
  h.hi = 5 * sigma;
  h.counts.assign(60, 0.0);
  std::mt19937_64 rng(12345);
  std::normal_distribution<double> g(0.0, sigma);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = g(rng);
    ++h.total;
    if (x < h.lo) ++h.under;
    else if (x >= h.hi) ++h.over;
    else h.counts[static_cast<std::size_t>((x - h.lo) / h.width())] += 1;
  }
  for (double s : {sigma, 1.15 * sigma}) {
    Curve c;
    c.label = s == sigma ? "Gaussian, σ = 1 µm" : "Gaussian, σ = 1.15 µm";
    for (int i = 0; i <= 400; ++i) {
      const double x = h.lo + (h.hi - h.lo) * i / 400.0;
      c.x.push_back(x);
      c.y.push_back(std::exp(-0.5 * x * x / (s * s)) / (s * std::sqrt(2 * std::numbers::pi)));
    }
    fig.curves.push_back(c);
  }
  return fig;
}

struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() /
           ("asperity-test-plot-" + std::to_string(std::random_device{}()));
    fs::create_directories(path);
  }
  ~TempDir() {
    if (!std::getenv("ASPERITY_KEEP_PLOTS")) {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  }
};

bool dir_has_only(const fs::path& dir, std::size_t n) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator())) == n;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

bool is_png(const fs::path& p) { return slurp(p).rfind(std::string("\x89PNG\r\n\x1a\n", 8), 0) == 0; }

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir)) names.insert(fs::relative(e.path(), dir).string());
  return names;
}

}  // namespace

TEST(Plot, GaussianHistogramPngAndItsData) {
  if (!plotting_available()) GTEST_SKIP() << plotting_problem();
  TempDir dir;
  const fs::path png = dir.path / "gaussian.png";
  // First a smaller figure, then overwrite it with the full one (rename onto an existing file).
  ASSERT_NO_THROW(write_histogram_png(png, gaussian_figure(20000)));
  const auto fig = gaussian_figure();
  ASSERT_NO_THROW(write_histogram_png(png, fig));
  ASSERT_TRUE(fs::is_regular_file(png));
  EXPECT_GT(fs::file_size(png), 10u * 1024u);
  EXPECT_TRUE(is_png(png));
  EXPECT_EQ(listing(dir.path), (std::set<std::string>{"gaussian.png", "gaussian.csv"})) << "temporary file left";
  // The CSV: a header naming the axes with units, one row per bin, then one per curve point.
  const auto rows = lines_of(slurp(dir.path / "gaussian.csv"));
  ASSERT_FALSE(rows.empty());
  EXPECT_EQ(rows[0], "series,r_x [µm],probability density [µm^-1],se [µm^-1],count");
  EXPECT_EQ(rows.size(), 1 + fig.histogram.bins() + fig.curves[0].x.size() + fig.curves[1].x.size());
  // The first bin: centre in µm, density in 1/µm, its se and its count, as plotted.
  std::istringstream first(rows[1]);
  std::vector<std::string> cells;
  for (std::string c; std::getline(first, c, ',');) cells.push_back(c);
  ASSERT_EQ(cells.size(), 5u) << rows[1];
  EXPECT_EQ(cells[0], "explicit geometry (n = 10^5)");
  EXPECT_NEAR(std::stod(cells[1]), fig.histogram.centre(0) * 1e6, 1e-9);
  EXPECT_NEAR(std::stod(cells[2]), fig.histogram.density(0) * 1e-6, 1e-12);
  EXPECT_EQ(std::stod(cells[4]), fig.histogram.counts[0]);
  EXPECT_EQ(rows.back().rfind("\"Gaussian, σ = 1.15 µm\",", 0), 0u) << rows.back();
  if (std::getenv("ASPERITY_KEEP_PLOTS")) std::printf("kept %s\n", png.c_str());
}

TEST(Plot, SvgAndPdfBesideThePng) {
  const std::string problem = plotting_problem(parse_plot_formats("png+svg+pdf"));
  if (!problem.empty()) GTEST_SKIP() << problem;
  TempDir dir;
  const auto files = write_figure(dir.path, "g", histogram_figure(gaussian_figure(5000)), parse_plot_formats("png+svg+pdf"));
  EXPECT_EQ(files, (std::vector<std::string>{"g.png", "g.svg", "g.pdf", "g.csv"}));
  EXPECT_TRUE(is_png(dir.path / "g.png"));
  EXPECT_NE(slurp(dir.path / "g.svg").find("<svg"), std::string::npos);
  EXPECT_EQ(slurp(dir.path / "g.pdf").rfind("%PDF-", 0), 0u);
  EXPECT_EQ(image_files(files), (std::vector<std::string>{"g.png", "g.svg", "g.pdf"}));
  EXPECT_EQ(data_files(files), (std::vector<std::string>{"g.csv"}));
}

TEST(Plot, FormatsParseAndRefuse) {
  EXPECT_EQ(to_string(parse_plot_formats("png")), "png");
  EXPECT_EQ(to_string(parse_plot_formats("png+pdf")), "png+pdf");
  EXPECT_EQ(to_string(parse_plot_formats("svg")), "svg");
  for (const char* bad : {"", "jpg", "png+", "+png", "png+png", "PNG", "png pdf", "png@", "png@0.2", "png@9", "png@2x",
                          "png@nan", "@2", "png@0x2", "png@ 2", "png@+2", "png@2 ", "png@inf"})
    EXPECT_THROW(parse_plot_formats(bad), std::invalid_argument) << bad;
  EXPECT_EQ(parse_plot_formats("png+svg@2.5").scale, 2.5);
  EXPECT_EQ(to_string(parse_plot_formats("png+svg@2.5")), "png+svg@2.5");
  EXPECT_EQ(parse_plot_formats("png").scale, 1);
}

// The size factor: the same figure at twice the pixels (a PNG's IHDR holds width and height).
TEST(Plot, SizeFactorScalesThePage) {
  if (!plotting_available()) GTEST_SKIP() << plotting_problem();
  TempDir dir;
  auto size_of = [](const fs::path& png) {
    const std::string b = slurp(png);
    auto be32 = [&](std::size_t at) {
      return (std::uint32_t(std::uint8_t(b[at])) << 24) | (std::uint32_t(std::uint8_t(b[at + 1])) << 16) |
             (std::uint32_t(std::uint8_t(b[at + 2])) << 8) | std::uint32_t(std::uint8_t(b[at + 3]));
    };
    return std::pair{be32(16), be32(20)};
  };
  const Figure fig = histogram_figure(gaussian_figure(2000));
  write_figure(dir.path, "one", fig, parse_plot_formats("png"));
  write_figure(dir.path, "two", fig, parse_plot_formats("png@2"));
  EXPECT_EQ(size_of(dir.path / "one.png"), (std::pair<std::uint32_t, std::uint32_t>(fig.width, fig.height)));
  EXPECT_EQ(size_of(dir.path / "two.png"), (std::pair<std::uint32_t, std::uint32_t>(2 * fig.width, 2 * fig.height)));
}

TEST(Plot, FailureThrowsAndLeavesNothing) {
  if (!plotting_available()) GTEST_SKIP() << plotting_problem();
  TempDir dir;
  const fs::path png = dir.path / "no-such-dir" / "fig.png";
  try {
    write_histogram_png(png, gaussian_figure(1000));
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(png));
  EXPECT_FALSE(fs::exists(png.parent_path()));
  EXPECT_TRUE(dir_has_only(dir.path, 0));
}

// A symlink planted at the figure's name is replaced, never followed: its target is untouched.
TEST(Plot, APlantedSymlinkIsNotFollowed) {
  if (!plotting_available()) GTEST_SKIP() << plotting_problem();
  TempDir dir, outside;
  std::ofstream(outside.path / "victim") << "keep";
  fs::create_symlink(outside.path / "victim", dir.path / "fig.png");
  fs::create_symlink(outside.path / "victim", dir.path / "fig.csv");
  ASSERT_NO_THROW(write_histogram_png(dir.path / "fig.png", gaussian_figure(1000)));
  EXPECT_EQ(slurp(outside.path / "victim"), "keep");
  EXPECT_FALSE(fs::is_symlink(dir.path / "fig.png"));
  EXPECT_TRUE(is_png(dir.path / "fig.png"));
  EXPECT_FALSE(fs::is_symlink(dir.path / "fig.csv"));
}

// Labels are data: every metacharacter of the shell, of gnuplot and of PLplot's text escapes in
// titles, labels, legends and file names draws glyphs and runs nothing; no file appears but the
// figure's own, and the canary a payload would create does not exist.
TEST(Plot, HostileLabelsRunNothingAndWriteOnlyTheFigure) {
  if (!plotting_available()) GTEST_SKIP() << plotting_problem();
  TempDir dir, outside;
  const std::string canary = (outside.path / "canary").string();
  const std::vector<std::string> payloads = {
      "`touch " + canary + "`", "$(touch " + canary + ")", "'; system 'touch " + canary + "'; print '",
      "\"; system(\"touch " + canary + "\"); print \"", "; touch " + canary + ";", "| touch " + canary,
      "&& touch " + canary + " &", "> " + canary, "< /etc/passwd", "${HOME} $PATH ~ * ? [a-z] ! \\",
      "#u#d#g#f#b#+#-#(123)#(2200)#[0x41]#[0xffffffff]#<0x10>#<sans/>##", "% %n %s %x %p %99999999d",
      "<b>&amp;</b> <span foreground='red'>pango</span> &#38; &lt;", "{/Symbol a} {/=99 big} @x ^{^{^{_{_{}}}}}} \\\\ \\",
      std::string(3000, '#'), std::string(2000, 'x') + "_{" + std::string(2000, 'y'),
      "\xFF\xFE invalid \xC3 utf-8 \xE2\x82", "plot 'x' with lines; set output '" + canary + "'"};
  auto fig = gaussian_figure(3000);
  int k = 0;
  for (const auto& p : payloads) {
    fig.title = "title " + p;
    fig.xlabel = p;
    fig.ylabel = figure_text_literal(p);
    fig.data_label = p;
    fig.curves[0].label = figure_text_literal(p);
    fig.curves[1].label = p + p;
    const std::string stem = "fig" + std::to_string(k++) + " it's \"q\" $(x) `y` ; #";
    ASSERT_NO_THROW(write_figure(dir.path, stem, histogram_figure(fig), parse_plot_formats("png+svg"))) << p;
    EXPECT_TRUE(is_png(dir.path / (stem + ".png"))) << p;
  }
  std::set<std::string> expected;
  for (int i = 0; i < k; ++i)
    for (const char* ext : {".png", ".svg", ".csv"})
      expected.insert("fig" + std::to_string(i) + " it's \"q\" $(x) `y` ; #" + ext);
  EXPECT_EQ(listing(dir.path), expected);
  EXPECT_TRUE(listing(outside.path).empty()) << "a payload created a file";
  EXPECT_FALSE(fs::exists(canary));
  EXPECT_FALSE(fs::exists(fs::current_path() / "canary"));
}

// The conversion to PLplot text emits no escape but #u, #d and ##, and stays inside PLplot's
// fixed text buffers (500 code points in the cairo driver).
TEST(Plot, TextConversionEmitsOnlyGlyphsAndSubSuperscripts) {
  using detail::plain_text;
  using detail::plplot_text;
  EXPECT_EQ(plplot_text("r_{xy} [µm]"), "r#dxy#u [µm]");
  EXPECT_EQ(plplot_text("10^{-6}, V'_z"), "10#u-6#d, V'#dz#u");
  EXPECT_EQ(plplot_text("#u#(123)"), "##u##(123)");
  EXPECT_EQ(plplot_text(figure_text_literal("a_b^c{d}\\e#")), "a_b^c{d}\\e##");
  EXPECT_EQ(plplot_text("tab\there\x01"), "tab?here?");
  EXPECT_EQ(plplot_text("\xFF"), "?");
  EXPECT_EQ(plain_text("r_{xy} [µm^{-1}]"), "r_xy [µm^-1]");
  for (const std::string& s : {std::string(5000, '#'), std::string(5000, 'a'), "^{" + std::string(5000, '_'),
                               std::string(2000, '\\') + "#"}) {
    const std::string t = plplot_text(s);
    EXPECT_LE(t.size(), 440u);
    for (std::size_t i = 0; i < t.size(); ++i)
      if (t[i] == '#') {
        ASSERT_LT(i + 1, t.size()) << "a lone # at the end";
        EXPECT_TRUE(t[i + 1] == '#' || t[i + 1] == 'u' || t[i + 1] == 'd') << t.substr(i, 2);
        ++i;
      }
  }
}

TEST(Plot, InvalidFiguresAreRejected) {
  TempDir dir;
  const fs::path png = dir.path / "bad.png";
  {
    HistogramFigure fig;  // no bins
    EXPECT_THROW(write_histogram_png(png, fig), std::invalid_argument);
  }
  {
    auto fig = gaussian_figure(1000);
    fig.histogram.total = 0;
    EXPECT_THROW(write_histogram_png(png, fig), std::invalid_argument);
  }
  {
    auto fig = gaussian_figure(1000);
    fig.histogram.counts[3] = std::nan("");
    EXPECT_THROW(write_histogram_png(png, fig), std::invalid_argument);
  }
  {
    auto fig = gaussian_figure(1000);
    fig.curves[1].y[7] = INFINITY;
    EXPECT_THROW(write_histogram_png(png, fig), std::invalid_argument);
  }
  {
    auto fig = gaussian_figure(1000);
    fig.curves[0].x.pop_back();
    EXPECT_THROW(write_histogram_png(png, fig), std::invalid_argument);
  }
  {
    auto fig = gaussian_figure(1000);
    fig.histogram.hi = fig.histogram.lo;
    EXPECT_THROW(write_histogram_png(png, fig), std::invalid_argument);
  }
  EXPECT_FALSE(fs::exists(png));
}

// Issue 32: Fig. 4's eps.png had its y title overprinted by 5-digit tick labels (the title sat at a
// fixed 5.2 character heights). The layout rule: the title's centre lies beyond the widest label's
// far end (kTickGap + kGlyphWidth per glyph, measured on the PNGs: a digit is 0.88 character
// heights wide) by at least half a character height plus a gap, for every range a figure of the
// presets draws (probability densities up to 3e4, eps near 0.945, spins in rad/s, 1e-6 scales).
TEST(PlotLayout, YTitleClearsTheWidestTickLabel) {
  using asperity::detail::y_axis_layout;
  const std::pair<double, double> ranges[] = {{0, 30000}, {0, 21000}, {0, 1.5}, {0.9447, 0.9453}, {-6, 6},
                                              {0, 2e6},   {0, 1e-4},  {-3e-6, 3e-6}, {0, 0.012}, {100, 130000}};
  for (const auto& [lo, hi] : ranges) {
    const auto l = y_axis_layout(lo, hi, false);
    ASSERT_GT(l.step, 0) << lo << " " << hi;
    const double intervals = (hi - lo) / l.step;
    EXPECT_GE(intervals, 2.5) << lo << " " << hi;
    EXPECT_LE(intervals, 12.5) << lo << " " << hi;
    const double label_end = asperity::detail::kTickGap + 0.88 * static_cast<double>(l.widest);
    EXPECT_GE(l.title_disp - 0.5, label_end + 0.3) << "range [" << lo << ", " << hi << "]: labels of " << l.widest
                                                   << " glyphs reach " << label_end << ", the title starts at "
                                                   << l.title_disp - 0.5;
  }
  // The rule has teeth: 30000 has 5 glyphs, and the old fixed 5.2 does not clear them.
  const auto l = y_axis_layout(0, 30000, false);
  EXPECT_EQ(l.widest, 5u);
  EXPECT_LT(5.2 - 0.5, asperity::detail::kTickGap + 0.88 * 5 + 0.3);
}
