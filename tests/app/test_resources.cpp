// SPDX-License-Identifier: GPL-3.0-or-later
// Memory refused up front (issue 16 item 11): estimate_memory against the peak RSS that
// validate-geometry really reaches, within 25 %, for each kind of cost (per asperity of an index,
// per concurrently built sphere, per drop, per mesh body, per bounce sequence); runs that do not
// fit are refused before they start.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "app/cli/options.hpp"
#include "asperity/app/resources.hpp"
#include "run_command.hpp"
#include "sanitized.hpp"

namespace fs = std::filesystem;

namespace {

// Peak RSS [bytes] of validate-geometry run with `args` (and -q --no-plots --out DIR).
double measured_peak(const std::vector<std::string>& args, const fs::path& out, int* status) {
  std::fflush(nullptr);  // the child must not repeat our buffered output
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<std::string> all = {VALIDATE_GEOMETRY, "-q", "--no-plots", "--out", out.string()};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    if (!std::freopen("/dev/null", "w", stdout)) ::_exit(99);
    ::execv(argv[0], argv.data());
    ::_exit(98);
  }
  int st = 0;
  struct rusage ru {};
  ::wait4(pid, &st, 0, &ru);
  *status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return double(ru.ru_maxrss) * 1024.0;
}

// A sanitized validate-geometry measures the sanitizer's shadow memory and quarantine, not the
// costs the estimate models: the comparison is made in uninstrumented builds only.

TEST(Resources, EstimateWithin25PercentOfTheMeasuredPeak) {
#ifdef ASPERITY_SANITIZED
  GTEST_SKIP() << "sanitized build: the peak RSS includes shadow memory (the Release pass compares)";
#endif
  const fs::path out = fs::temp_directory_path() / ("asperity-resources-" + std::to_string(::getpid()));
  const std::vector<std::vector<std::string>> cases = {
      // one explicit sphere with its index (per asperity, grid)
      {"--mode", "fixed", "--spheres", "1", "--asperities", "2000000", "--drops", "100", "--threads", "1"},
      // the same with a kd-tree
      {"--mode", "fixed", "--spheres", "1", "--asperities", "2000000", "--drops", "100", "--threads", "1",
       "--backend", "kdtree"},
      // many small spheres: one per busy thread (per thread)
      {"--mode", "fixed", "--spheres", "8", "--asperities", "1000000", "--drops", "64", "--threads", "2"},
      // fresh drops (per drop)
      {"--asperities", "1000", "--drops", "1000000"},
      // a mesh body, one at a time (per asperity of a mesh body)
      {"--scene", std::string(SCENES_DIR) + "/ellipsoid.toml", "--asperities", "800000", "--spheres", "2", "--drops",
       "200", "--threads", "1"},
      // bounce sequences (per sequence)
      {"--preset", "fig6", "--variant", "paper", "--asperities", "10000", "--sequences", "2000", "--threads", "1"},
  };
  for (const auto& args : cases) {
    std::vector<std::string> full = args;
    for (const char* a : {"-q", "--no-plots", "--out"}) full.push_back(a);
    full.push_back(out.string());
    const asperity::Scene scene = asperity::cli::parse_command_line(full).scene;
    const asperity::MemoryEstimate est = asperity::estimate_memory(scene);
    int status = 0;
    const double peak = measured_peak(args, out, &status);
    std::string cmd;
    for (const auto& a : args) cmd += a + " ";
    ASSERT_TRUE(status == 0 || status == 1) << cmd;
    EXPECT_NEAR(est.bytes / peak, 1.0, 0.25) << cmd << ": estimate " << est.bytes / 1e6 << " MB (" << est.detail
                                             << "), measured peak " << peak / 1e6 << " MB";
    std::cout << cmd << ": estimate " << est.bytes / 1e6 << " MB, measured " << peak / 1e6 << " MB\n";
    fs::remove_all(out);
  }
}

TEST(Resources, RunsThatDoNotFitAreRefusedBeforeTheyStart) {
  // 2e9 bounce sequences keep ~7 TB of impacts: refused on any machine, naming the cause.
  auto r = asperity::testing::run_command(std::string(VALIDATE_GEOMETRY) +
                                          " --preset fig6 --sequences 2e9 --out /nonexistent/never 2>&1");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("sequences"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("GB of memory"), std::string::npos) << r.out;
  // With a 2 GB address-space limit, 5e7 asperities of one explicit sphere (~3.7 GB) do not fit.
  // (A sanitized binary cannot start under ulimit -v: its shadow memory alone exceeds the limit.)
#ifndef ASPERITY_SANITIZED
  r = asperity::testing::run_command("ulimit -v 2000000; " + std::string(VALIDATE_GEOMETRY) +
                                     " --mode fixed --asperities 5e7 --drops 1000 --out /nonexistent/never 2>&1");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("50000000 asperities"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("2.05 GB this process may use"), std::string::npos) << r.out;
#endif
}

}  // namespace
