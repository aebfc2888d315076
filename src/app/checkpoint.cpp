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

constexpr char kMagic[] = "asperity-stream-checkpoint-1\n";

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
  k.out = "DIR";  // the directory may be named differently (relative, absolute) when resumed
  return to_toml(k);
}

void write_checkpoint(const std::filesystem::path& dir, const Scene& s, const StreamState& st) {
  write_file_atomic(dir / kCheckpointScene, to_toml(s));
  write_file_atomic(dir / kCheckpointState, serialise(checkpoint_key(s), st));
}

StreamState read_checkpoint(const std::filesystem::path& dir, const Scene& s) {
  const auto path = dir / kCheckpointState;
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::invalid_argument("--resume: no checkpoint " + path.string());
  const std::string in((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  Reader r{in, 0, path.string()};
  r.need(sizeof kMagic - 1);
  if (in.compare(0, sizeof kMagic - 1, kMagic) != 0)
    throw std::invalid_argument(path.string() + ": not a checkpoint of this version");
  r.at = sizeof kMagic - 1;
  if (r.text() != checkpoint_key(s))
    throw std::invalid_argument(path.string() + ": written for another scene than " + (dir / kCheckpointScene).string() +
                                " with these options (only --threads, --quiet, --no-plots and --checkpoint-every may change)");
  StreamState st = initial_stream_state(s.ensemble);
  st.next_unit = r.get<std::uint64_t>(), st.core_contacts = r.get<std::uint64_t>();
  st.check_queries = r.get<std::uint64_t>(), st.check_agreed = r.get<std::uint64_t>();
  st.index_bytes = r.get<std::uint64_t>();
  if (r.get<std::uint64_t>() != st.stats.size()) throw std::invalid_argument(path.string() + ": damaged checkpoint");
  for (auto& b : st.stats) {
    const auto kind = r.get<Reference::Kind>();
    const auto sigma = r.get<double>();
    const auto fine = r.get<unsigned>(), coarse = r.get<unsigned>();
    const auto blocks = r.get<std::size_t>();
    if (kind != b.ref.kind || sigma != b.ref.sigma || fine != b.fine_log2 || coarse != b.coarse_log2 || blocks != b.blocks)
      throw std::invalid_argument(path.string() + ": its histograms do not match this scene");
    b.fine = r.vector<std::uint64_t>(b.fine.size());
    b.coarse = r.vector<std::uint64_t>(b.coarse.size());
    b.block_moments = r.vector<Moments>(b.block_moments.size());
  }
  if (r.at != in.size()) throw std::invalid_argument(path.string() + ": damaged checkpoint (trailing bytes)");
  return st;
}

void remove_checkpoint(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::remove(dir / kCheckpointState, ec);
  std::filesystem::remove(dir / kCheckpointScene, ec);
}

}  // namespace asperity
