// Restitution tables (app/cor_table.hpp): quantiles per speed, validation, and the CSV read back by
// the C header a DEM code uses (include/asperity/cor_table.h, C99, compiled here as C++).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "asperity/app/cor_table.hpp"
#include "asperity/app/scene.hpp"
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
  std::filesystem::remove_all(dir);
}
