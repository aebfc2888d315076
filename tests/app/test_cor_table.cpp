// SPDX-License-Identifier: GPL-3.0-or-later
// Restitution tables (app/cor_table.hpp): quantiles per speed, validation, and the CSV read back by
// the C header a DEM code uses (include/asperity/cor_table.h, C99, compiled here as C++).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <cmath>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <stdexcept>

#include "asperity/app/cor_table.hpp"
#include "asperity/app/run.hpp"
#include "asperity/app/scene.hpp"
#include "asperity/app/scene_file.hpp"
#include "asperity/cor_table.h"

using namespace asperity;

namespace {
CorTableSpec small_spec() {
  CorTableSpec s = cor_table_spec(preset("fig4"), 3);
  s.drops = 4000;
  s.probabilities = 21;
  s.sphere.asperities = 1000;
  return s;
}
}  // namespace

TEST(CorTable, QuantilesAscendAlongRowsAndTheMedianFallsWithSpeed) {
  const CorTable t = make_cor_table(small_spec());
  ASSERT_EQ(t.rows.size(), 3u);
  EXPECT_DOUBLE_EQ(t.rows[1].speed, 1.3);  // the scene's speed is the middle of the default grid
  for (const auto& r : t.rows) {
    EXPECT_EQ(r.quantiles.size(), 21u);
    EXPECT_TRUE(std::is_sorted(r.quantiles.begin(), r.quantiles.end()));
    EXPECT_EQ(r.samples, 4000u);
    EXPECT_TRUE(r.fitted) << r.fit_note;
  }
  EXPECT_GT(t.rows[0].quantiles[10], t.rows[2].quantiles[10]);
}

TEST(CorTable, BadSpecsNameTheField) {
  CorTableSpec s = small_spec();
  s.speeds = {1.0, 0.5};
  EXPECT_THROW(
      try { validate(s); } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("speeds[1] = 0.5"), std::string::npos) << e.what();
        throw;
      },
      std::invalid_argument);
  s = small_spec();
  s.probabilities = 1;
  EXPECT_THROW(validate(s), std::invalid_argument);
  EXPECT_THROW(cor_table_spec(preset("fig6")), std::invalid_argument);
}

TEST(CorTable, TheCHeaderReadsTheCsvAndSamplesItsNodes) {
  const CorTable t = make_cor_table(small_spec());
  const auto dir = std::filesystem::temp_directory_path() / "asperity-test-cor-table";
  std::filesystem::create_directories(dir);
  const auto files = write_cor_table(dir / "t.csv", t);
  ASSERT_EQ(files.size(), 2u);
  EXPECT_TRUE(std::filesystem::exists(dir / "t.json"));
  asperity_cor_table c;
  char err[256] = "";
  ASSERT_EQ(asperity_cor_load(&c, (dir / "t.csv").c_str(), err, sizeof err), 0) << err;
  ASSERT_EQ(c.n_speeds, 3);
  ASSERT_EQ(c.n_probs, 21);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 21; ++j) {
      EXPECT_EQ(c.eps[i * 21 + j], t.rows[i].quantiles[j]);  // shortest round-trip text: exact
      EXPECT_EQ(asperity_cor_sample(&c, t.rows[i].speed, t.probabilities[j]), t.rows[i].quantiles[j]);
    }
  asperity_cor_free(&c);
  // Line 1 states the counts the reader checks: the written table loses its last row -> refused.
  const std::string csv = cor_table_csv(t);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "# asperity-cor-table format=1 speeds=3 probabilities=21");
  const std::string cut = csv.substr(0, csv.rfind('\n', csv.size() - 2) + 1);
  ASSERT_EQ(asperity_cor_parse(&c, csv.c_str(), err, sizeof err), 0) << err;
  asperity_cor_free(&c);
  ASSERT_EQ(asperity_cor_parse(&c, cut.c_str(), err, sizeof err), -1);
  EXPECT_NE(std::string(err).find("ends early"), std::string::npos) << err;
  std::filesystem::remove_all(dir);
}

// outputs.cor_table in a scene file: read, validated with the key named, written back by to_toml,
// and run with the scene: the table lands beside the report, which names its ensemble.
namespace {
std::string fig4_with_table(const std::string& table) {
  std::string text(preset_text("fig4"));
  return text + "\n[outputs.cor_table]\n" + table;
}

void expect_scene_error(const std::string& text, const std::string& key, const std::string& also) {
  try {
    parse_scene(text, "t.toml");
    ADD_FAILURE() << "accepted, expected an error naming " << key;
  } catch (const SceneError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_NE(std::string(e.what()).find(also), std::string::npos) << e.what();
  }
}
}  // namespace

TEST(CorTableScene, ReadValidatedAndWrittenBack) {
  const Scene s = parse_scene(
      fig4_with_table("file = \"steel.csv\"\nspeeds = [0.5, 2]\nprobabilities = 11\ndrops = 300\nspins = [-1, 0.5]\nomega_bands = 4\n"),
      "t.toml");
  ASSERT_TRUE(s.cor_table);
  EXPECT_EQ(s.cor_table->file, "steel.csv");
  EXPECT_EQ(s.cor_table->speeds, (std::vector<double>{0.5, 2.0}));
  EXPECT_EQ(s.cor_table->probabilities, 11u);
  EXPECT_EQ(s.cor_table->drops, 300u);
  EXPECT_EQ(parse_scene(to_toml(s), "again.toml"), s);
  EXPECT_EQ(s.cor_table->spins, (std::vector<double>{-1.0, 0.5}));
  EXPECT_EQ(s.cor_table->omega_bands, 4u);
  EXPECT_EQ(cor_table_spec(s, *s.cor_table).speeds, s.cor_table->speeds);
  EXPECT_EQ(cor_table_spec(s, *s.cor_table).spins, s.cor_table->spins);
  expect_scene_error(fig4_with_table("file = \"t.csv\"\nspins = [1, 1]\n"), "outputs.cor_table.spins", "ascend");
  expect_scene_error(fig4_with_table("file = \"t.csv\"\ndrops = 10\nomega_bands = 6\n"), "outputs.cor_table.omega_bands", "drops / 2");
  expect_scene_error(fig4_with_table("file = \"t.csv\"\nomega_bands = 1001\n"), "outputs.cor_table.omega_bands", "<= 1000");

  expect_scene_error(fig4_with_table("speeds = [1]\n"), "outputs.cor_table.file", "missing");
  expect_scene_error(fig4_with_table("file = \"t.csv\"\nspeeds = [2, 1]\n"), "outputs.cor_table.speeds", "ascend");
  expect_scene_error(fig4_with_table("file = \"t.csv\"\nspeeds = [0, 1]\n"), "outputs.cor_table.speeds", "> 0");
  expect_scene_error(fig4_with_table("file = \"t.csv\"\nprobabilities = 1\n"), "outputs.cor_table.probabilities", ">= 2");
  expect_scene_error(fig4_with_table("file = \"t.csv\"\ndrops = 2\n"), "outputs.cor_table.drops", ">= 3");
  expect_scene_error(fig4_with_table("file = \"t.csv\"\ncolour = 1\n"), "outputs.cor_table.colour", "unknown");
  expect_scene_error(fig4_with_table("file = \"../t.csv\"\n"), "outputs.cor_table.file", "'/'");
  expect_scene_error(fig4_with_table("file = \"t.txt\"\n"), "outputs.cor_table.file", ".csv");
  expect_scene_error(fig4_with_table("file = \"report.csv\"\n"), "outputs.cor_table.file", "report.json");
  std::string contact(preset_text("fig3"));
  expect_scene_error(contact + "\n[outputs.cor_table]\nfile = \"t.csv\"\n", "outputs.cor_table", "sphere impact scene");
}

TEST(CorTableScene, TheRunWritesTheTableBesideTheReport) {
  Scene s = parse_scene(fig4_with_table("file = \"steel.csv\"\nspeeds = [0.5, 2]\nprobabilities = 11\ndrops = 300\n"), "t.toml");
  s.ensemble.sphere.asperities = 1000;
  s.ensemble.drops = 2000;
  s.plots = false;
  const auto out = std::filesystem::temp_directory_path() / "asperity-test-cor-table-scene";
  std::filesystem::remove_all(out);
  s.out = out;
  const SceneOutput o = run_scene_output(s, {}, nullptr, {});
  EXPECT_NE(std::find(o.files.begin(), o.files.end(), "steel.csv"), o.files.end());
  EXPECT_TRUE(std::filesystem::exists(out / "steel.csv"));
  EXPECT_TRUE(std::filesystem::exists(out / "steel.json"));
  EXPECT_NE(o.json.find("\"cor_table\""), std::string::npos);
  EXPECT_NE(o.json.find(kCorTableEnsemble), std::string::npos) << "the report says the table is sampled, not geometric";
  EXPECT_NE(o.table.find("restitution table: steel.csv"), std::string::npos) << o.table;
  asperity_cor_table c;
  char err[256] = "";
  ASSERT_EQ(asperity_cor_load(&c, (out / "steel.csv").c_str(), err, sizeof err), 0) << err;
  EXPECT_EQ(c.n_speeds, 2);
  EXPECT_EQ(c.n_probs, 11);
  asperity_cor_free(&c);
  std::filesystem::remove_all(out);
}

// Format 2: a spin grid and Omega'_x per eps band. The C header reads back every node, and the
// joint draw (eps with u, Omega'_x with u2 in the band of u) reproduces the correlation of eps and
// Omega'_x of the drops themselves -- which independent draws (the marginal Omega'_x law, what a
// format-1 table offers) cannot: the deliberately wrong sampler must miss it.
namespace {
double correlation(const std::vector<double>& x, const std::vector<double>& y) {
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= double(x.size()), my /= double(y.size());
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx), syy += (y[i] - my) * (y[i] - my);
  return sxy / std::sqrt(sxx * syy);
}
std::vector<double> ranks(const std::vector<double>& x) {
  std::vector<std::size_t> order(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return x[a] < x[b]; });
  std::vector<double> r(x.size());
  for (std::size_t i = 0; i < x.size();) {  // ties share their mean rank
    std::size_t j = i;
    while (j < x.size() && x[order[j]] == x[order[i]]) ++j;
    for (std::size_t k = i; k < j; ++k) r[order[k]] = 0.5 * double(i + j - 1);
    i = j;
  }
  return r;
}
// Spearman's rank correlation: what a copula of bands keeps (a Pearson correlation of the skewed
// eps is carried by its far tail, which one band of 5 % mixes).
double rank_correlation(const std::vector<double>& x, const std::vector<double>& y) { return correlation(ranks(x), ranks(y)); }
}  // namespace

TEST(CorTable, SpinGridAndJointOmegaDrawsThroughTheCHeader) {
  CorTableSpec spec = small_spec();
  spec.speeds = {0.5, 1.3};
  spec.spins = {-2.0, 0.0, 2.0};
  spec.omega_bands = 20;
  spec.drops = 20000;
  spec.probabilities = 101;
  spec.sphere.asperities = 100000;  // fig4's sphere: at N = 1e3 most drops touch with the core (all alike)
  const CorTable t = make_cor_table(spec);
  ASSERT_EQ(t.format(), 2);
  ASSERT_EQ(t.rows.size(), 6u);
  const auto dir = std::filesystem::temp_directory_path() / "asperity-test-cor-table-spins";
  std::filesystem::create_directories(dir);
  write_cor_table(dir / "t.csv", t);
  asperity_cor_table c;
  char err[256] = "";
  ASSERT_EQ(asperity_cor_load(&c, (dir / "t.csv").c_str(), err, sizeof err), 0) << err;
  ASSERT_EQ(c.format, 2);
  ASSERT_EQ(c.n_spins, 3);
  ASSERT_EQ(c.n_speeds, 2);
  ASSERT_EQ(c.n_bands, 20);
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 2; ++i) {
      const CorTableRow& r = t.rows[std::size_t(k * 2 + i)];
      EXPECT_EQ(r.spin, spec.spins[std::size_t(k)]);
      for (int j = 0; j < 101; j += 10) {
        EXPECT_EQ(asperity_cor_sample_spin(&c, r.spin, r.speed, t.probabilities[std::size_t(j)]), r.quantiles[std::size_t(j)]);
        EXPECT_EQ(asperity_cor_sample_omega(&c, r.spin, r.speed, 0.5 / 20, t.probabilities[std::size_t(j)]),
                  r.omega_x_band_quantiles[0][std::size_t(j)]);
      }
    }
  // The drops of one grid node, and 20000 draws from the table at that node.
  EnsembleConfig e;
  e.sphere = spec.sphere;
  e.mode = Mode::sampled;
  e.drops = spec.drops;
  e.seed = 77;
  e.impact = spec.impact;
  e.impact.enabled = true;
  e.impact.speed = 1.3;
  e.impact.omega = Vec3(2.0, 0, 0);
  const ContactSamples s = run_contact_ensemble(e);
  const double direct = rank_correlation(s.eps, s.omega_x_after);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<double> eps, joint, independent;
  for (int n = 0; n < 20000; ++n) {
    const double u = U(rng), u2 = U(rng), u3 = U(rng);
    eps.push_back(asperity_cor_sample_spin(&c, 2.0, 1.3, u));
    joint.push_back(asperity_cor_sample_omega(&c, 2.0, 1.3, u, u2));
    independent.push_back(asperity_cor_sample_omega(&c, 2.0, 1.3, u3, u2));
  }
  // Standard error of a correlation from 2e4 pairs: <= 1/sqrt(2e4) = 0.007 (twice: drops and draws),
  // plus the band discretisation; 0.05 is ~5 standard errors, far below |direct|.
  const double rj = rank_correlation(eps, joint), ri = rank_correlation(eps, independent);
  std::cout << "Spearman(eps, Omega'_x): drops " << direct << ", joint table draws " << rj << ", independent draws " << ri << "\n";
  ASSERT_GT(std::abs(direct), 0.3) << "the check needs a correlated pair";
  EXPECT_NEAR(rj, direct, 0.05);
  EXPECT_GT(std::abs(ri - direct), 0.2) << "the wrong (independent) sampler must miss the correlation";
  asperity_cor_free(&c);
  std::filesystem::remove_all(dir);
}
