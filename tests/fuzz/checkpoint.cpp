// SPDX-License-Identifier: GPL-3.0-or-later
// Fuzz target: checkpoint files (issue 24, item 4). The input is a list of edits applied to a valid
// checkpoint of a small run cut after its first sphere (checkpoint_fixture.hpp), so that every
// mutation is a mutation of a real checkpoint; the empty input is the file unchanged.
//   input = [flags byte if the size is odd] then 6-byte records: u32 offset (little endian), op, value
//   op % 4: 0 xor the byte at offset with value (0 counts as 1), 1 cut the file at offset,
//           2 insert value at offset, 3 append (offset % 4096 + 1) bytes of value;
//   op & 4: the offset counts from the end of the file
//   flags bit 0: recompute the checksum after the edits (reaches the consistency checks).
// Property: a file is refused (std::invalid_argument), or the run it continues ends with exactly the
// state of the uninterrupted run. With the checksum recomputed an accepted file need not give that
// state (counts moved between bins keep every total): then it must pass stream_state_problem and
// continue without any error.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "../checkpoint_fixture.hpp"
#include "app/checkpoint.hpp"

namespace {

using namespace asperity;

struct Fixture {
  Plan scene = testing::checkpoint_plan(testing::small_stream_scene());
  StreamState cut, whole;
  std::string bytes;
  Fixture() {
    whole = testing::run_stream(scene, [&](const StreamState& st) { cut = st; });
    bytes = stream_state_bytes(scene, cut);
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

void edit(std::string& b, std::uint32_t offset, std::uint8_t op, std::uint8_t value) {
  std::size_t at = offset % (b.size() + 1);
  if (op & 4) at = b.size() - at;  // counted from the end
  switch (op % 4) {
    case 0:
      if (at < b.size()) b[at] = static_cast<char>(b[at] ^ (value ? value : 1));
      break;
    case 1: b.resize(at); break;
    case 2: b.insert(at, 1, static_cast<char>(value)); break;
    default: b.append(offset % 4096 + 1, static_cast<char>(value));
  }
}

[[noreturn]] void fail(const char* why) {
  std::fprintf(stderr, "checkpoint fuzz: %s\n", why);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Fixture& f = fixture();
  const bool odd = size % 2 == 1;
  const bool fix_checksum = odd && (data[0] & 1);
  std::string b = f.bytes;
  for (std::size_t i = odd ? 1 : 0; i + 6 <= size && b.size() < (std::size_t{1} << 22); i += 6) {
    std::uint32_t offset;
    std::memcpy(&offset, data + i, 4);
    edit(b, offset, data[i + 4], data[i + 5]);
  }
  if (fix_checksum && b.size() >= 8) {
    const std::uint64_t c = checkpoint_checksum(std::string_view(b).substr(0, b.size() - 8));
    std::memcpy(b.data() + b.size() - 8, &c, 8);
  }
  StreamState st;
  try {
    st = stream_state_from_bytes(b, f.scene, "checkpoint.bin");
  } catch (const std::invalid_argument&) {
    return 0;  // refused, with a message naming the file
  }
  if (!stream_state_problem(f.scene.scene.ensemble, f.scene.control.share, st).empty())
    fail("an inconsistent checkpoint was accepted");
  const StreamState end = testing::run_stream(f.scene, {}, 0, &st);  // throws (a crash here) on any error
  if (!fix_checksum && !(end == f.whole)) fail("an accepted checkpoint continued to another state");
  return 0;
}
