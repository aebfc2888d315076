// SPDX-License-Identifier: GPL-3.0-or-later
// write_histogram_png: a Gaussian histogram against its pdf renders to a real PNG; failures throw
// and leave nothing behind; invalid figures are rejected before gnuplot runs.
#include "asperity/app/plot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

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

}  // namespace

TEST(Plot, GaussianHistogramPng) {
  if (!plotting_available()) GTEST_SKIP() << "gnuplot with pngcairo not available";
  TempDir dir;
  const fs::path png = dir.path / "gaussian.png";
  // First a smaller figure, then overwrite it with the full one (rename onto an existing file).
  ASSERT_NO_THROW(write_histogram_png(png, gaussian_figure(20000)));
  ASSERT_NO_THROW(write_histogram_png(png, gaussian_figure()));
  ASSERT_TRUE(fs::is_regular_file(png));
  EXPECT_GT(fs::file_size(png), 10u * 1024u);
  std::ifstream in(png, std::ios::binary);
  char sig[8] = {};
  in.read(sig, 8);
  const unsigned char expected[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(static_cast<unsigned char>(sig[i]), expected[i]) << "byte " << i;
  EXPECT_TRUE(dir_has_only(dir.path, 1)) << "temporary file left beside the PNG";
  if (std::getenv("ASPERITY_KEEP_PLOTS")) std::printf("kept %s\n", png.c_str());
}

TEST(Plot, FailureThrowsAndLeavesNothing) {
  if (!plotting_available()) GTEST_SKIP() << "gnuplot with pngcairo not available";
  TempDir dir;
  const fs::path png = dir.path / "no-such-dir" / "fig.png";
  try {
    write_histogram_png(png, gaussian_figure(1000));
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("gnuplot"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(png));
  EXPECT_FALSE(fs::exists(png.parent_path()));
  EXPECT_TRUE(dir_has_only(dir.path, 0));
}

TEST(Plot, QuotesInLabelsAreEscaped) {
  if (!plotting_available()) GTEST_SKIP() << "gnuplot with pngcairo not available";
  TempDir dir;
  auto fig = gaussian_figure(5000);
  fig.title = "a \"quoted\" title with a backslash \\ and 'single' quotes";
  fig.curves[0].label = "say \"hi\"";
  const fs::path png = dir.path / "it's \"quoted\".png";
  ASSERT_NO_THROW(write_histogram_png(png, fig));
  EXPECT_TRUE(fs::is_regular_file(png));
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
