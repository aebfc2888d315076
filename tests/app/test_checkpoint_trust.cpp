// SPDX-License-Identifier: GPL-3.0-or-later
// Checkpoints you can trust (issue 24, items 2 and 4), in-process and cheap:
//  - every streaming run resumes to the same bits as the uninterrupted run, from a checkpoint at
//    any wave, with another thread count, for spheres = "auto" (the default; it failed before:
//    the reader shaped the state from the unresolved scene) and other statistics settings;
//  - a checkpoint that was changed, cut, padded, linked, of another format or of another scene
//    is refused naming the file, and so is one whose counts disagree (even with a valid checksum);
//  - writes never leave the directory: links planted at every temporary name and at the final
//    names are replaced or skipped, never followed; a write that fails at any system call leaves
//    the previous complete checkpoint or none;
//  - no output may be named like a checkpoint file.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/io/atomic_file.hpp"
#include "app/checkpoint.hpp"
#include "app/io/output_staging.hpp"
#include "asperity/app/scene_file.hpp"
#include "checkpoint_fixture.hpp"
#include "run_command.hpp"

namespace fs = std::filesystem;
using namespace asperity;
using asperity::testing::checkpoint_plan;
using asperity::testing::run_stream;
using asperity::testing::slurp;
using asperity::testing::small_stream_scene;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = asperity::testing::fresh_dir("ckpt-trust", name);
  fs::create_directories(d);
  return d;
}

// The message of the std::invalid_argument `f` throws ("" if it throws none).
template <class F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// As --resume takes it: the scene from checkpoint.toml, the directory, another thread count.
Plan resumed_plan(const fs::path& dir, int threads) {
  Scene r = load_scene(dir / kCheckpointScene);
  r.ensemble.threads = threads;
  return checkpoint_plan(std::move(r), dir, true);
}

// A checkpoint written after every wave of a run with one thread (each into its own directory),
// each resumed with two threads from its files: the same final state as the run itself.
void expect_every_resume_bit_identical(Scene s, const std::string& name) {
  const fs::path root = fresh_dir(name);
  std::vector<fs::path> dirs;
  s.ensemble.threads = 1;
  Plan p = checkpoint_plan(s);
  const StreamState whole = run_stream(p, [&](const StreamState& st) {
    dirs.push_back(root / std::to_string(dirs.size()));
    fs::create_directory(dirs.back());
    p.given.out = p.scene.out = dirs.back();
    write_checkpoint(dirs.back(), p, st);
  });
  ASSERT_GE(dirs.size(), 2u) << "too few waves to cut the run";
  for (const fs::path& d : {dirs.front(), dirs[dirs.size() / 2], dirs.back()}) {
    const Plan r = resumed_plan(d, 2);
    const StreamState st = read_checkpoint(d, r);
    EXPECT_LT(st.next_unit, whole.next_unit);
    EXPECT_EQ(run_stream(r, {}, 0, &st), whole) << name << ": resumed from " << d;
  }
  fs::remove_all(root);
}

}  // namespace

TEST(CheckpointTrust, EveryStreamingRunResumesToTheSameBits) {
  Scene s = preset("fig3");  // the default scene, at N = 10^3 and 10^6 drops: 625 spheres (auto), 4 waves
  ASSERT_TRUE(s.spheres_auto && s.backend_auto);
  s.ensemble.sphere.asperities = 1000;
  s.ensemble.drops = 1'000'000;
  s.ensemble.statistics = Statistics::streaming;
  s.plots = false;
  expect_every_resume_bit_identical(s, "auto");
  Scene bins = s;  // another resolution, explicit spheres
  bins.ensemble.bins_log2 = 12, bins.ensemble.spheres = 800, bins.spheres_auto = false;
  expect_every_resume_bit_identical(bins, "bins");
  Scene sampled = s;  // one drop per unit, 256 blocks of drops
  sampled.ensemble.mode = Mode::sampled, sampled.ensemble.drops = 60'000, sampled.ensemble.sphere.asperities = 100;
  sampled.ensemble.bins_log2 = 20;
  expect_every_resume_bit_identical(sampled, "sampled");
  Scene big = small_stream_scene();  // big spheres, one per wave
  big.ensemble.spheres = 3, big.ensemble.drops = 3 * 65536;
  expect_every_resume_bit_identical(big, "big");
}

TEST(CheckpointTrust, EverySingleByteFlipIsRefused) {
  const Plan s = checkpoint_plan(small_stream_scene());
  StreamState cut;
  run_stream(s, [&](const StreamState& st) { cut = st; }, 1);
  const std::string good = stream_state_bytes(s, cut);
  ASSERT_EQ(good.size(), checkpoint_state_size(s));
  ASSERT_EQ(stream_state_from_bytes(good, s, "checkpoint.bin"), cut) << "the unchanged file is accepted";
  // The header, key and counters whole; 200 places spread over the histograms; the checksum.
  std::vector<std::size_t> at;
  for (std::size_t i = 0; i < std::min<std::size_t>(good.size(), 2048); ++i) at.push_back(i);
  for (std::size_t i = 0; i < 200; ++i) at.push_back(2048 + i * (good.size() - 2056) / 200);
  for (std::size_t i = good.size() - 8; i < good.size(); ++i) at.push_back(i);
  for (std::size_t i : at)
    for (const unsigned char x : {0xffu, 1u << (i % 8)}) {
      std::string bad = good;
      bad[i] = static_cast<char>(bad[i] ^ x);
      const std::string why = refusal([&] { stream_state_from_bytes(bad, s, "dir/checkpoint.bin"); });
      ASSERT_NE(why, "") << "byte " << i << " ^ " << unsigned(x) << " was accepted";
      ASSERT_NE(why.find("dir/checkpoint.bin"), std::string::npos) << why;
    }
}

TEST(CheckpointTrust, InconsistentCountsAreRefusedEvenWithAValidChecksum) {
  const Plan s = checkpoint_plan(small_stream_scene());
  StreamState cut;
  run_stream(s, [&](const StreamState& st) { cut = st; }, 1);
  const EnsembleConfig e = s.scene.ensemble;
  ASSERT_EQ(stream_state_problem(e, s.control.share, cut), "");
  const std::vector<std::pair<std::string, std::function<void(StreamState&)>>> faults{
      {"fine histogram", [](StreamState& t) { ++t.stats[1].fine[7]; }},
      {"block 0", [](StreamState& t) { ++t.stats[0].coarse[3]; }},
      {"block 1", [](StreamState& t) { ++t.stats[2].coarse[1024 + 3]; }},  // sphere 1 has no drops yet
      {"moments", [](StreamState& t) { ++t.stats[0].block_moments[0].n; }},
      {"out of range", [](StreamState& t) { t.stats[1].block_moments[0].mean = std::nan(""); }},
      {"out of range", [](StreamState& t) { t.stats[0].block_moments[0].m2 = -1; }},
      {"out of range", [](StreamState& t) { t.stats[0].block_moments[0].mean = 1e18; }},
      {"outside", [](StreamState& t) { t.next_unit = 1u << 20; }},
      {"fine histogram", [](StreamState& t) { ++t.next_unit; }},  // the counts are for fewer drops
      {"core contacts", [](StreamState& t) { t.core_contacts = 1u << 30; }},
      {"cross-check", [](StreamState& t) { t.check_agreed = t.check_queries + 1; }},
      {"fine histogram", [](StreamState& t) {  // wraps around to the right total
         t.stats[0].fine[0] += ~std::uint64_t{0} / 2 + 1, t.stats[0].fine[1] += ~std::uint64_t{0} / 2 + 1;
       }},
  };
  for (const auto& [what, fault] : faults) {
    StreamState bad = cut;
    fault(bad);
    EXPECT_NE(stream_state_problem(e, s.control.share, bad).find(what), std::string::npos)
        << what << ": " << stream_state_problem(e, s.control.share, bad);
    // Written with a valid checksum, as a careless tool might: still refused, naming the file.
    const std::string why = refusal([&] { stream_state_from_bytes(stream_state_bytes(s, bad), s, "d/checkpoint.bin"); });
    EXPECT_NE(why.find("d/checkpoint.bin: inconsistent checkpoint"), std::string::npos) << why;
  }
}

TEST(CheckpointTrust, OnlyARegularFileOfTheRightSizeAndSceneIsRead) {
  const fs::path dir = fresh_dir("files");
  const Plan s = checkpoint_plan(small_stream_scene(), dir, true);
  StreamState cut;
  run_stream(s, [&](const StreamState& st) { cut = st; }, 1);
  write_checkpoint(dir, s, cut);
  ASSERT_EQ(read_checkpoint(dir, s), cut);
  const fs::path bin = dir / kCheckpointState;
  const std::string good = slurp(bin);
  auto refused = [&](const std::string& expect) {
    const std::string why = refusal([&] { read_checkpoint(dir, s); });
    EXPECT_NE(why.find(bin.string()), std::string::npos) << why;
    EXPECT_NE(why.find(expect), std::string::npos) << why;
  };
  auto put = [&](const std::string& bytes) {
    fs::remove(bin);
    std::ofstream(bin, std::ios::binary) << bytes;
  };
  put(good.substr(0, good.size() - 1)), refused("truncated");
  put(good + "x"), refused("oversized");
  put(good + std::string(1 << 20, '\0')), refused("oversized");
  std::string v2 = good;
  v2[std::strlen("asperity-stream-checkpoint-")] = '2';
  put(v2.substr(0, 5000)), refused("format 2");
  put(v2), refused("format 2");
  fs::remove(bin), fs::create_symlink("/dev/zero", bin), refused("symbolic link");
  fs::remove(bin);
  ASSERT_EQ(::mkfifo(bin.c_str(), 0600), 0);
  refused("not a regular file");  // a blocking open would hang here
  fs::remove(bin), fs::create_directory(bin), refused("not a regular file");
  // A state of another scene beside this checkpoint.toml (a mismatched pair).
  fs::remove(bin);
  Scene o = small_stream_scene();
  o.ensemble.seed += 1;
  const Plan other = checkpoint_plan(o, dir, true);
  put(stream_state_bytes(other, cut)), refused("another scene");
  put(good);
  EXPECT_EQ(read_checkpoint(dir, s), cut) << "the good file again: accepted";
  fs::remove_all(dir);
}

TEST(CheckpointTrust, LinksPlantedAtEveryTemporaryAndFinalNameAreNeverFollowed) {
  const fs::path dir = fresh_dir("links"), outside = fresh_dir("links-outside");
  Plan s = checkpoint_plan(small_stream_scene(), dir);
  StreamState cut;
  run_stream(s, [&](const StreamState& st) { cut = st; }, 1);
  // The names the writer will try, planted first: links to files outside, and dangling ones.
  // The scene file's temporary skips names 0-6 and takes 7, the state's skips 8-10 and takes 11.
  auto name = [](int i) { return std::string(kTemporaryPrefix) + "planted-" + std::to_string(i); };
  int next = 0;
  set_atomic_file_seams({{}, [&] { return name(next++); }});
  const std::vector<int> planted{0, 1, 2, 3, 4, 5, 6, 8, 9, 10};
  for (int i : planted) {
    if (i == 6 || i == 10) {
      fs::create_symlink(outside / ("dangling" + std::to_string(i)), dir / name(i));
      continue;
    }
    std::ofstream(outside / ("victim" + std::to_string(i))) << "victim";
    fs::create_symlink(outside / ("victim" + std::to_string(i)), dir / name(i));
  }
  std::ofstream(outside / "victim-toml") << "victim";
  fs::create_symlink(outside / "victim-toml", dir / kCheckpointScene);
  fs::create_symlink(outside / "dangling-bin", dir / kCheckpointState);
  write_checkpoint(dir, s, cut);
  set_atomic_file_seams({});
  EXPECT_EQ(next, 12) << "every planted name was tried";
  for (int i : planted) {
    EXPECT_TRUE(fs::is_symlink(dir / name(i))) << "not ours: left alone";
    if (i != 6 && i != 10) {
      EXPECT_EQ(slurp(outside / ("victim" + std::to_string(i))), "victim");
    }
  }
  EXPECT_EQ(slurp(outside / "victim-toml"), "victim");
  EXPECT_FALSE(fs::exists(outside / "dangling6") || fs::exists(outside / "dangling10") ||
               fs::exists(outside / "dangling-bin"));
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir / kCheckpointScene)));
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir / kCheckpointState)));
  s.control.resume = true;
  EXPECT_EQ(read_checkpoint(dir, s), cut);
  fs::remove_all(dir), fs::remove_all(outside);
}

TEST(CheckpointTrust, AFailedWriteLeavesThePreviousCheckpointOrNone) {
  const fs::path dir = fresh_dir("fail");
  const Plan s = checkpoint_plan(small_stream_scene(), dir);
  std::vector<StreamState> states;
  run_stream(s, [&](const StreamState& st) { states.push_back(st); });  // 1 checkpoint: after sphere 0
  ASSERT_EQ(states.size(), 1u);
  StreamState first = states[0], second = first;
  second.index_bytes += 1;  // another complete state of the same run
  Plan r = s;
  r.control.resume = true;
  // The n-th system call of the write fails (ENOSPC), for every n until a write goes through.
  for (const bool previous : {false, true}) {
    for (int n = 1;; ++n) {
      fs::remove_all(dir), fs::create_directory(dir);
      if (previous) write_checkpoint(dir, s, first);
      int calls = 0;
      set_atomic_file_seams({[&](std::string_view) { return ++calls == n ? ENOSPC : 0; }, {}});
      bool threw = false;
      try {
        write_checkpoint(dir, s, second);
      } catch (const std::runtime_error& e) {
        threw = true;
        EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos) << e.what();
      }
      set_atomic_file_seams({});
      for (const auto& f : fs::directory_iterator(dir))
        EXPECT_TRUE(is_checkpoint_name(f.path().filename().string())) << "left behind: " << f.path();
      if (fs::exists(dir / kCheckpointScene) || fs::exists(dir / kCheckpointState)) {
        const StreamState got = read_checkpoint(dir, r);  // a complete pair: throws otherwise
        EXPECT_TRUE(got == second || (previous && got == first)) << "call " << n;
      } else {
        EXPECT_FALSE(previous) << "call " << n << ": the previous checkpoint is gone";
      }
      if (!threw) break;
      ASSERT_LT(n, 50);
    }
  }
  fs::remove_all(dir);
}

TEST(CheckpointTrust, ALoneSceneFileSaysWhatToDo) {
  const fs::path dir = fresh_dir("lone");
  Plan s = checkpoint_plan(small_stream_scene(), dir);
  write_file_atomic(dir / kCheckpointScene, to_toml(s.given));
  std::string why = refusal([&] { check_checkpoint_files(s); });
  EXPECT_NE(why.find("without its state"), std::string::npos) << why;
  EXPECT_NE(why.find("remove it"), std::string::npos) << why;
  s.control.resume = true;
  why = refusal([&] { check_checkpoint_files(s); });
  EXPECT_NE(why.find("nothing to continue"), std::string::npos) << why;
  fs::remove_all(dir);
}

TEST(CheckpointTrust, NoOutputIsNamedLikeACheckpointFile) {
  for (const char* name : {"checkpoint.toml", "checkpoint.bin", "checkpoint.rank-1-of-4.bin", "checkpoint.rank-x-of-y.bin",
                           ".asperity-tmp-123-abc"}) {
    EXPECT_NE(output_name_problem(name), "") << name;
    Scene s = preset("fig3");
    s.report = name;
    const std::string why = refusal([&] { validate(s); });
    EXPECT_NE(why.find("outputs.report"), std::string::npos) << name << ": " << why;
  }
  for (const char* name : {"checkpoint.json", "checkpoint", "my-checkpoint.toml", "checkpoint.rank-1.bin"})
    EXPECT_EQ(output_name_problem(name), "") << name;
  EXPECT_TRUE(is_checkpoint_name(checkpoint_state_name({3, 7})));
}
