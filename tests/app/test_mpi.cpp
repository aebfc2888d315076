// SPDX-License-Identifier: GPL-3.0-or-later
// Beyond one machine (issue 14, item 5): `mpirun -np 2 validate-geometry ...` splits a streaming run
// across processes and writes the report of one process (timings aside); SIGTERM ends every process
// with its checkpoint, and `mpirun -np 2 validate-geometry --resume DIR` continues to the same report.
// Built when validate-geometry is built with MPI (ASPERITY_WITH_MPI); mpirun runs as CI does (root,
// more processes than cores).
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "comparable_report.hpp"
#include "run_command.hpp"

namespace fs = std::filesystem;
using asperity::testing::comparable_report;
using asperity::testing::run_command;
using asperity::testing::slurp;

namespace {

const std::string kMpirun = std::string(MPIEXEC) + " --allow-run-as-root --oversubscribe --mca btl self,vader";

fs::path fresh_dir(const std::string& name) { return asperity::testing::fresh_dir("mpi", name); }

// 8e6 explicit drops at N = 10^3, spheres "auto" (the default: 5000 spheres x 1600 rotations, 256
// blocks; before issue 24 no such run could be resumed): ~16 waves of <= 2^18 drops per process,
// so that a SIGTERM sent once both processes wrote their first checkpoint finds them running (with 2e6 drops, 4 waves, the faster drop loop of 2026-11-24 sometimes finished first).
std::string run_args(const fs::path& out) {
  return " -q --asperities 1000 --drops 8000000 --statistics streaming --no-plots --out " + out.string();
}

}  // namespace

TEST(Mpi, TwoProcessesWriteTheReportOfOneAndResumeFromTheirCheckpoints) {
  const fs::path one = fresh_dir("one"), two = fresh_dir("two"), cut = fresh_dir("cut");
  auto r = run_command(std::string(VALIDATE_GEOMETRY) + run_args(one) + " 2>&1");
  const int status = r.status;
  ASSERT_TRUE(status == 0 || status == 1) << r.out;
  r = run_command(kMpirun + " -np 2 " + VALIDATE_GEOMETRY + run_args(two) + " --threads 1 2>&1");
  ASSERT_EQ(r.status, status) << r.out;
  EXPECT_EQ(comparable_report(two / "report.json"), comparable_report(one / "report.json"));
  EXPECT_FALSE(fs::exists(two / "checkpoint.toml")) << "a completed run leaves no checkpoint";

  // Interrupted: each process writes its share's checkpoint once SIGTERM reaches it through mpirun.
  const fs::path log = cut.string() + ".log";
  std::vector<std::string> args{"--allow-run-as-root", "--oversubscribe", "--mca", "btl", "self,vader", "-np", "2",
                                VALIDATE_GEOMETRY, "-q", "--asperities", "1000", "--drops", "8000000",
                                "--statistics", "streaming", "--no-plots", "--threads", "1",
                                "--checkpoint-every", "0.000001", "--out", cut.string()};
  const pid_t pid = asperity::testing::spawn_cli(MPIEXEC, args, log);
  const fs::path r0 = cut / "checkpoint.rank-0-of-2.bin", r1 = cut / "checkpoint.rank-1-of-2.bin";
  for (int i = 0; i < 6000 && !(fs::exists(r0) && fs::exists(r1)); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ::kill(pid, SIGTERM);
  EXPECT_NE(asperity::testing::wait_status(pid), 0) << slurp(log);
  ASSERT_FALSE(fs::exists(cut / "report.json")) << "the run ended before the signal? " << slurp(log);
  ASSERT_TRUE(fs::exists(r0) && fs::exists(r1) && fs::exists(cut / "checkpoint.toml")) << slurp(log);

  // One process cannot continue the shares of two; two can, to the same report.
  r = run_command(std::string(VALIDATE_GEOMETRY) + " -q --resume " + cut.string() + " 2>&1");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("mpirun -np P"), std::string::npos) << r.out;
  r = run_command(kMpirun + " -np 2 " + VALIDATE_GEOMETRY + " -q --resume " + cut.string() + " --threads 1 2>&1");
  EXPECT_EQ(r.status, status) << r.out;
  EXPECT_EQ(comparable_report(cut / "report.json"), comparable_report(one / "report.json"));
  EXPECT_FALSE(fs::exists(r0) || fs::exists(r1) || fs::exists(cut / "checkpoint.toml"));
  for (const auto& d : {one, two, cut}) fs::remove_all(d);
  fs::remove(log);
}

TEST(Mpi, BadInputIsOneErrorAndARawSceneRunsOnRankZero) {
  auto r = run_command(kMpirun + " -np 2 " + VALIDATE_GEOMETRY + " --asperities 0 --no-plots 2>&1");
  EXPECT_NE(r.status, 0) << r.out;
  const auto first = r.out.find("--asperities");
  ASSERT_NE(first, std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("validate-geometry: error", r.out.find("validate-geometry: error") + 1), std::string::npos)
      << "printed by rank 0 only:\n" << r.out;

  const fs::path out = fresh_dir("raw");
  r = run_command(kMpirun + " -np 2 " + VALIDATE_GEOMETRY + " -q --asperities 1000 --drops 20000 --no-plots --out " +
                  out.string() + " 2>&1");
  EXPECT_TRUE(r.status == 0 || r.status == 1) << r.out;
  EXPECT_NE(r.out.find("rank 0 runs it alone"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(out / "report.json"));
  fs::remove_all(out);
}
