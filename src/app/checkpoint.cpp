// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/checkpoint.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <boost/crc.hpp>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <system_error>
#include <type_traits>

#include "app/io/atomic_file.hpp"
#include "asperity/app/plan.hpp"
#include "asperity/app/scene_file.hpp"

namespace asperity {

namespace fs = std::filesystem;

namespace {

// Version 3 adds the checksum, the planned design in the key and the consistency checks; older
// checkpoints are refused by name (their counts were never checked). Version 2 added the
// byte-order mark after the magic: a checkpoint carried to a machine of the other byte order is
// refused by name instead of read as garbage.
constexpr std::string_view kMagicPrefix = "asperity-stream-checkpoint-";
constexpr std::string_view kMagic = "asperity-stream-checkpoint-3\n";
constexpr std::uint32_t kByteOrderMark = 0x01020304;
// CRC-64/XZ (ECMA-182 polynomial, reflected): Boost.CRC's table-driven implementation.
using Crc64 = boost::crc_optimal<64, 0x42F0E1EBA9EA3693ULL, ~0ULL, ~0ULL, true, true>;

std::uint64_t crc64(const char* p, std::size_t n) {
  Crc64 crc;
  crc.process_bytes(p, n);
  return crc.checksum();
}

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

// The bytes of one quantity's header (kind, sigma, fine and coarse log2, blocks).
constexpr std::size_t kStatHeader = sizeof(Reference::Kind) + sizeof(double) + 2 * sizeof(unsigned) + sizeof(std::size_t);

// Reads from a byte string; any overrun is a damaged file.
struct Reader {
  const std::string& in;
  std::size_t at = 0, end = 0;
  std::string file;
  void need(std::size_t n) {
    if (end - at < n) throw std::invalid_argument(file + ": damaged or truncated checkpoint");
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
  void vector(std::vector<T>& v) {
    if (get<std::uint64_t>() != v.size()) throw std::invalid_argument(file + ": damaged checkpoint (a histogram has the wrong size)");
    need(v.size() * sizeof(T));
    std::memcpy(v.data(), in.data() + at, v.size() * sizeof(T));
    at += v.size() * sizeof(T);
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
  put(out, crc64(out.data(), out.size()));
  return out;
}

// What the user can do about a checkpoint this version cannot continue.
std::string start_afresh(const fs::path& dir) {
  return "; to start afresh, remove " + (dir / kCheckpointScene).string() + " and the checkpoint*.bin files beside it";
}

// The magic line and the byte-order mark: this version's on this machine's order, or refused:
// another version's (by name), another order's, or not a checkpoint.
void check_header(const std::string& in, const std::string& what, const fs::path& dir) {
  if (in.compare(0, kMagicPrefix.size(), kMagicPrefix) != 0) throw std::invalid_argument(what + ": not a checkpoint");
  if (in.compare(0, kMagic.size(), kMagic) != 0) {
    std::string version = in.substr(kMagicPrefix.size(), std::min<std::size_t>(in.find('\n', kMagicPrefix.size()), 40) - kMagicPrefix.size());
    if (version.empty() || !std::all_of(version.begin(), version.end(), [](unsigned char c) { return std::isdigit(c); }))
      version = "unknown";
    throw std::invalid_argument(what + ": a checkpoint of format " + version +
                                " (another version of asperity; this one reads format 3 only)" + start_afresh(dir));
  }
  std::uint32_t mark = 0;
  if (in.size() < kMagic.size() + sizeof mark) throw std::invalid_argument(what + ": damaged or truncated checkpoint");
  std::memcpy(&mark, in.data() + kMagic.size(), sizeof mark);
  if (mark != kByteOrderMark)
    throw std::invalid_argument(what + ": written on a machine of another byte order (or damaged); resume it there");
}

// Reads the quantities' headers and histograms into st (shaped for this scene).
void read_stats(Reader& r, StreamState& st) {
  if (r.get<std::uint64_t>() != st.stats.size()) throw std::invalid_argument(r.file + ": damaged checkpoint");
  for (auto& b : st.stats) {
    const auto kind = r.get<Reference::Kind>();
    const auto sigma = r.get<double>();
    const auto fine = r.get<unsigned>(), coarse = r.get<unsigned>();
    const auto blocks = r.get<std::size_t>();
    if (kind != b.ref.kind || sigma != b.ref.sigma || fine != b.fine_log2 || coarse != b.coarse_log2 || blocks != b.blocks)
      throw std::invalid_argument(r.file + ": its histograms do not match this scene");
    r.vector(b.fine);
    r.vector(b.coarse);
    r.vector(b.block_moments);
  }
}

// The names in `dir` that are checkpoint files, or an empty list (also when it cannot be listed).
std::vector<std::string> checkpoint_files(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (const std::string n = it->path().filename().string(); is_checkpoint_name(n)) names.push_back(n);
  return names;
}

// No state file for s.share: why, and what to do.
[[noreturn]] void missing_state(const fs::path& dir, const StreamShare& share, const fs::path& path) {
  std::string why = "--resume: no checkpoint " + path.string();
  const auto present = checkpoint_files(dir);
  const bool any_state = std::any_of(present.begin(), present.end(), [](const std::string& n) { return n != kCheckpointScene; });
  if (!any_state && !present.empty())
    why += ": " + (dir / kCheckpointScene).string() +
           " is there without its state (a checkpoint cut off while being written, or by an older version): there is "
           "nothing to continue; remove it and run the scene again";
  else if (share.ranks > 1 && fs::exists(dir / kCheckpointState))
    why += " (" + (dir / kCheckpointState).string() + " was written by one process: resume it without mpirun)";
  else if (share.ranks == 1)
    why += " (a run split across P processes writes checkpoint.rank-R-of-P.bin: resume it with mpirun -np P)";
  throw std::invalid_argument(why);
}

// The file's bytes: a regular file (a link, FIFO or device is never opened or read) of exactly
// `size` bytes, checked before reading. Another size: its magic line says whether it is of another
// format (refused by name) or damaged.
std::string read_state_file(const fs::path& path, std::size_t size, const StreamShare& share, const fs::path& dir) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    if (err == ENOENT) missing_state(dir, share, path);
    if (err == ELOOP) throw std::invalid_argument(path.string() + ": a symbolic link; a checkpoint is read from a regular file only");
    throw std::invalid_argument("cannot read " + path.string() + ": " + std::generic_category().message(err));
  }
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
    throw std::invalid_argument(path.string() + ": not a regular file; a checkpoint is read from a regular file only");
  const auto have = static_cast<std::size_t>(st.st_size);
  std::string in(std::min(have, size), '\0');
  std::size_t got = 0;
  while (got < in.size()) {
    const ssize_t r = ::read(fd, in.data() + got, in.size() - got);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) throw std::invalid_argument("cannot read " + path.string() + ": " + std::generic_category().message(errno));
    if (r == 0) throw std::invalid_argument(path.string() + ": truncated checkpoint (it shrank while being read)");
    got += static_cast<std::size_t>(r);
  }
  if (have == size) return in;
  check_header(in, path.string(), dir);
  throw std::invalid_argument(path.string() + ": " + std::to_string(have) + " bytes, where a checkpoint of this scene has " +
                              std::to_string(size) + ": " + (have < size ? "truncated" : "oversized or damaged"));
}

}  // namespace

std::string checkpoint_key(const Plan& p) {
  Scene k = p.given;
  k.ensemble.threads = 0;
  k.ensemble.kernel = Kernel::simd;  // the kernel changes no bit: --resume DIR --kernel scalar continues it
  k.plots = true;
  k.plot_format = "png";  // figures change no result
  k.out = "DIR";  // the directory may be named differently (relative, absolute) when resumed
  // The resolved design too: a version that resolves "auto" differently must not continue it.
  const EnsembleConfig& e = p.scene.ensemble;
  return to_toml(k) + "# planned: spheres = " + std::to_string(e.spheres) + ", backend = " + std::string(to_string(e.backend)) +
         ", bins_log2 = " + std::to_string(e.bins_log2) + "\n";
}

std::string checkpoint_state_name(const StreamShare& share) {
  if (share.ranks <= 1) return kCheckpointState;
  return "checkpoint.rank-" + std::to_string(share.rank) + "-of-" + std::to_string(share.ranks) + ".bin";
}

void write_checkpoint(const fs::path& dir, const Plan& p, const StreamState& st) {
  const AtomicDirectory d(dir);
  std::optional<AtomicDirectory::Staged> scene;
  if (p.control.share.rank == 0) scene.emplace(d.stage(kCheckpointScene, to_toml(p.given)));
  auto state = d.stage(checkpoint_state_name(p.control.share), stream_state_bytes(p, st));
  // Both are complete on disk: only the renames are left. The scene first; if the state then
  // fails, a scene file this call created is removed again (a lone one would block both a new run
  // and --resume). A scene file that was there belongs to the previous state, which has the same
  // key: still a complete pair.
  const bool had_scene = d.holds(kCheckpointScene);
  try {
    if (scene) d.publish(*scene);
    d.publish(state);
  } catch (...) {
    if (scene && scene->published() && !had_scene && !state.published()) d.remove(kCheckpointScene);
    throw;
  }
}

std::string stream_state_bytes(const Plan& p, const StreamState& st) { return serialise(checkpoint_key(p), st); }

std::uint64_t checkpoint_checksum(std::string_view bytes) { return crc64(bytes.data(), bytes.size()); }

std::size_t checkpoint_state_size(const Plan& p) {
  const EnsembleConfig& e = p.scene.ensemble;
  const std::size_t G = std::min<std::uint64_t>(e.mode == Mode::sampled ? e.drops : e.spheres, kStreamBlocks);
  const std::size_t per_quantity = kStatHeader + 3 * sizeof(std::uint64_t) + (std::size_t{1} << e.bins_log2) * 8 +
                                   G * (std::size_t{1} << kStreamCoarseLog2) * 8 + G * sizeof(Moments);
  return kMagic.size() + sizeof kByteOrderMark + 8 + checkpoint_key(p).size() + 6 * 8 + kStreamQuantities.size() * per_quantity + 8;
}

StreamState read_checkpoint(const fs::path& dir, const Plan& p) {
  const auto path = dir / checkpoint_state_name(p.control.share);
  return stream_state_from_bytes(read_state_file(path, checkpoint_state_size(p), p.control.share, dir), p, path.string());
}

StreamState stream_state_from_bytes(const std::string& in, const Plan& p, const std::string& what) {
  const fs::path dir = fs::path(what).parent_path();
  check_header(in, what, dir);
  Reader r{in, kMagic.size() + sizeof kByteOrderMark, in.size(), what};
  r.need(8);
  r.end = in.size() - 8;  // the checksum's place
  std::uint64_t stored;
  std::memcpy(&stored, in.data() + r.end, 8);
  if (stored != crc64(in.data(), r.end))
    throw std::invalid_argument(what + ": damaged checkpoint (its checksum does not match its contents)" + start_afresh(dir));
  if (r.text() != checkpoint_key(p))
    throw std::invalid_argument(what + ": written for another scene than " + kCheckpointScene +
                                " with these options (only --threads, --quiet, --no-plots and --checkpoint-every may change)" +
                                start_afresh(dir));
  const EnsembleConfig& e = p.scene.ensemble;
  StreamState st = initial_stream_state(e);
  st.next_unit = r.get<std::uint64_t>(), st.core_contacts = r.get<std::uint64_t>();
  st.check_queries = r.get<std::uint64_t>(), st.check_agreed = r.get<std::uint64_t>();
  st.index_bytes = r.get<std::uint64_t>();
  read_stats(r, st);
  if (r.at != r.end) throw std::invalid_argument(what + ": damaged checkpoint (trailing bytes)");
  if (const std::string why = stream_state_problem(e, p.control.share, st); !why.empty())
    throw std::invalid_argument(what + ": inconsistent checkpoint (" + why + ")" + start_afresh(dir));
  return st;
}

void check_checkpoint_files(const Plan& p) {
  const Scene& s = p.given;
  if (!p.streams) return;
  if (p.control.resume) {
    read_checkpoint(s.out, p);
    return;
  }
  const auto present = checkpoint_files(s.out);
  if (present.empty()) return;
  const bool any_state = std::any_of(present.begin(), present.end(), [](const std::string& n) { return n != kCheckpointScene; });
  if (!any_state)
    throw std::invalid_argument("--out: " + (s.out / kCheckpointScene).string() +
                                " is a checkpoint without its state (cut off while being written, or by an older version): "
                                "there is nothing to continue; remove it to run here");
  const std::string state = present.front() == kCheckpointScene ? present.back() : present.front();
  throw std::invalid_argument("--out: " + (s.out / state).string() + " is the checkpoint of an interrupted run: continue it with --resume " +
                              s.out.string() + start_afresh(s.out));
}

void remove_checkpoint(const fs::path& dir, const StreamShare& share) {
  std::error_code ec;
  for (int r = 0; r < share.ranks; ++r) fs::remove(dir / checkpoint_state_name({r, share.ranks}), ec);
  fs::remove(dir / kCheckpointScene, ec);
}

}  // namespace asperity
