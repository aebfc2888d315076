// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/app/checkpoint.hpp"

#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "asperity/app/atomic_file.hpp"
#include "asperity/app/scene_file.hpp"

namespace asperity {

namespace {

// Version 2 adds a byte-order mark after the magic: a checkpoint carried to a machine of the other
// byte order is refused by name instead of read as garbage. Version 1 (no mark) is still read.
constexpr char kMagic[] = "asperity-stream-checkpoint-2\n";
constexpr char kMagicV1[] = "asperity-stream-checkpoint-1\n";
constexpr std::uint32_t kByteOrderMark = 0x01020304;

template <class T>
void put(std::string& out, const T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

void put_text(std::string& out, const std::string& s) {
  put(out, std::uint64_t(s.size()));
  out += s;
}

template <class T>
void put_vector(std::string& out, const std::vector<T>& v) {
  put(out, std::uint64_t(v.size()));
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

// Reads from a byte string; any overrun is a damaged file.
struct Reader {
  const std::string& in;
  std::size_t at = 0;
  std::string file;
  void need(std::size_t n) {
    if (in.size() - at < n) throw std::invalid_argument(file + ": damaged or truncated checkpoint");
  }
  template <class T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, in.data() + at, sizeof v);
    at += sizeof v;
    return v;
  }
  std::string text() {
    const auto n = get<std::uint64_t>();
    need(n);
    std::string s = in.substr(at, n);
    at += n;
    return s;
  }
  template <class T>
  std::vector<T> vector(std::size_t expected) {
    const auto n = get<std::uint64_t>();
    if (n != expected) throw std::invalid_argument(file + ": damaged checkpoint (a histogram has the wrong size)");
    need(n * sizeof(T));
    std::vector<T> v(n);
    std::memcpy(v.data(), in.data() + at, n * sizeof(T));
    at += n * sizeof(T);
    return v;
  }
};

std::string serialise(const std::string& key, const StreamState& st) {
  std::string out(kMagic);
  put(out, kByteOrderMark);
  put_text(out, key);
  put(out, st.next_unit), put(out, st.core_contacts), put(out, st.check_queries), put(out, st.check_agreed);
  put(out, st.index_bytes);
  put(out, std::uint64_t(st.stats.size()));
  for (const auto& b : st.stats) {
    put(out, b.ref.kind), put(out, b.ref.sigma), put(out, b.fine_log2), put(out, b.coarse_log2), put(out, b.blocks);
    put_vector(out, b.fine);
    put_vector(out, b.coarse);
    put_vector(out, b.block_moments);
  }
  return out;
}

}  // namespace

std::string checkpoint_key(const Scene& s) {
  Scene k = s;
  k.ensemble.threads = 0;
  k.plots = true;
  k.plot_format = "png";  // figures change no result
  k.out = "DIR";  // the directory may be named differently (relative, absolute) when resumed
  return to_toml(k);
}

std::string checkpoint_state_name(const StreamShare& share) {
  if (share.ranks <= 1) return kCheckpointState;
  return "checkpoint.rank-" + std::to_string(share.rank) + "-of-" + std::to_string(share.ranks) + ".bin";
}

void write_checkpoint(const std::filesystem::path& dir, const Scene& s, const StreamState& st) {
  if (s.share.rank == 0) write_file_atomic(dir / kCheckpointScene, to_toml(s));
  write_file_atomic(dir / checkpoint_state_name(s.share), stream_state_bytes(s, st));
}

std::string stream_state_bytes(const Scene& s, const StreamState& st) { return serialise(checkpoint_key(s), st); }

StreamState read_checkpoint(const std::filesystem::path& dir, const Scene& s) {
  const auto path = dir / checkpoint_state_name(s.share);
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    std::string why = "--resume: no checkpoint " + path.string();
    if (s.share.ranks > 1 && std::filesystem::exists(dir / kCheckpointState))
      why += " (" + (dir / kCheckpointState).string() + " was written by one process: resume it without mpirun)";
    else if (s.share.ranks == 1)
      why += " (a run split across P processes writes checkpoint.rank-R-of-P.bin: resume it with mpirun -np P)";
    throw std::invalid_argument(why);
  }
  const std::string in((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  return stream_state_from_bytes(in, s, path.string());
}

StreamState stream_state_from_bytes(const std::string& in, const Scene& s, const std::string& what) {
  Reader r{in, 0, what};
  r.need(sizeof kMagic - 1);
  const bool v2 = in.compare(0, sizeof kMagic - 1, kMagic) == 0;
  if (!v2 && in.compare(0, sizeof kMagicV1 - 1, kMagicV1) != 0)
    throw std::invalid_argument(what + ": not a checkpoint of this version");
  r.at = sizeof kMagic - 1;
  if (v2 && r.get<std::uint32_t>() != kByteOrderMark)
    throw std::invalid_argument(what + ": written on a machine of another byte order (or damaged); resume it there");
  if (r.text() != checkpoint_key(s))
    throw std::invalid_argument(what + ": written for another scene than " + kCheckpointScene +
                                " with these options (only --threads, --quiet, --no-plots and --checkpoint-every may change)");
  StreamState st = initial_stream_state(s.ensemble);
  st.next_unit = r.get<std::uint64_t>(), st.core_contacts = r.get<std::uint64_t>();
  st.check_queries = r.get<std::uint64_t>(), st.check_agreed = r.get<std::uint64_t>();
  st.index_bytes = r.get<std::uint64_t>();
  if (r.get<std::uint64_t>() != st.stats.size()) throw std::invalid_argument(what + ": damaged checkpoint");
  for (auto& b : st.stats) {
    const auto kind = r.get<Reference::Kind>();
    const auto sigma = r.get<double>();
    const auto fine = r.get<unsigned>(), coarse = r.get<unsigned>();
    const auto blocks = r.get<std::size_t>();
    if (kind != b.ref.kind || sigma != b.ref.sigma || fine != b.fine_log2 || coarse != b.coarse_log2 || blocks != b.blocks)
      throw std::invalid_argument(what + ": its histograms do not match this scene");
    b.fine = r.vector<std::uint64_t>(b.fine.size());
    b.coarse = r.vector<std::uint64_t>(b.coarse.size());
    b.block_moments = r.vector<Moments>(b.block_moments.size());
  }
  if (r.at != in.size()) throw std::invalid_argument(what + ": damaged checkpoint (trailing bytes)");
  return st;
}

void remove_checkpoint(const std::filesystem::path& dir, const StreamShare& share) {
  std::error_code ec;
  for (int r = 0; r < share.ranks; ++r) std::filesystem::remove(dir / checkpoint_state_name({r, share.ranks}), ec);
  std::filesystem::remove(dir / kCheckpointScene, ec);
}

}  // namespace asperity
