// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/io/output_staging.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <random>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "app/io/atomic_file.hpp"
#include "app/io/checkpoint_names.hpp"

namespace asperity {

namespace fs = std::filesystem;

namespace {

std::string reason(int err) { return std::generic_category().message(err); }

std::string random_suffix() {
  std::random_device rd;
  std::ostringstream s;
  s << ::getpid() << '-' << std::hex << rd();
  return s.str();
}

// The pid a staging directory's name starts with (".asperity-staging-<pid>-<hex>"), 0 if none.
pid_t staging_pid(std::string_view name) {
  if (name.substr(0, kStagingPrefix.size()) != kStagingPrefix) return 0;
  name.remove_prefix(kStagingPrefix.size());
  long long pid = 0;
  std::size_t i = 0;
  for (; i < name.size() && name[i] >= '0' && name[i] <= '9' && pid < (1LL << 31); ++i) pid = pid * 10 + (name[i] - '0');
  if (i == 0 || i >= name.size() || name[i] != '-' || pid <= 0 || pid >= (1LL << 31)) return 0;
  return static_cast<pid_t>(pid);
}

// Whether a process `pid` exists (EPERM: it exists, another user's).
bool process_alive(pid_t pid) { return ::kill(pid, 0) == 0 || errno == EPERM; }

// A live run's staging directory in `out`, named for the "in use" message ("" if none is seen).
std::string live_staging(const fs::path& out) {
  std::error_code ec;
  for (fs::directory_iterator it(out, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (const pid_t pid = staging_pid(name); pid != 0 && process_alive(pid)) return name;
  }
  return "";
}

}  // namespace

std::size_t remove_stale_staging(const fs::path& out) {
  std::size_t removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(out, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path p = it->path();
    const pid_t pid = staging_pid(p.filename().string());
    if (pid == 0 || pid == ::getpid() || process_alive(pid)) continue;  // ours, a live run's, or not a staging name
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != ::geteuid()) continue;
    std::error_code rm;
    fs::remove_all(p, rm);  // does not follow links inside it
    if (!rm) ++removed;
  }
  return removed;
}

std::string output_name_problem(std::string_view name) {
  if (name.empty()) return "is empty";
  if (name == "." || name == "..") return "is not a file name";
  if (name.size() > 255) return "is longer than 255 bytes";
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '/') return "must be a plain file name (no '/')";
    if (u < 0x20 || u == 0x7f) return "contains a control character (NUL, newline, ...)";
  }
  if (name.substr(0, kStagingPrefix.size()) == kStagingPrefix) return "starts with the staging prefix " + std::string(kStagingPrefix);
  if (name.substr(0, kTemporaryPrefix.size()) == kTemporaryPrefix)
    return "starts with the prefix of temporary files " + std::string(kTemporaryPrefix);
  // A streaming run writes, replaces and finally removes its checkpoint files in the output
  // directory: an output of that name would be deleted by its own run, or clobber a checkpoint.
  if (is_checkpoint_name(name))
    return "is the name of a streaming run's checkpoint file (checkpoint.toml, checkpoint.bin, checkpoint.rank-R-of-P.bin)";
  return "";
}

// A constructor that throws runs no destructor: the directories made before the failure (a deep
// --out whose last component cannot be created) are removed here, or they would stay behind.
OutputStaging::OutputStaging(const fs::path& out) : out_(out) {
  try {
    create(out);
  } catch (...) {
    remove_created_directories();
    if (lock_fd_ >= 0) ::close(lock_fd_);
    throw;
  }
}

void OutputStaging::remove_created_directories() noexcept {
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) ::rmdir(it->c_str());
}

void OutputStaging::create(const fs::path& out) {
  if (out.empty()) throw std::runtime_error("output directory: empty name");
  // The missing directories, outermost first: each is created (and remembered) in turn.
  std::vector<fs::path> missing;
  fs::path p = out.lexically_normal();
  if (!p.has_filename()) p = p.parent_path();  // "a/b/" -> "a/b"
  while (!p.empty()) {
    struct stat st {};
    if (::stat(p.c_str(), &st) == 0 || errno != ENOENT) break;  // exists, or let mkdir say why
    missing.push_back(p);
    const fs::path parent = p.parent_path();
    if (parent == p) break;
    p = parent;
  }
  std::reverse(missing.begin(), missing.end());
  for (const auto& d : missing) {
    guards_.push_back(std::make_unique<InterruptCleanup>(d, InterruptCleanup::Kind::empty_directory));
    const int rc = ::mkdir(d.c_str(), 0777);
    const int err = errno;
    guards_.back()->created();
    if (rc != 0 && err != EEXIST)
      throw std::runtime_error("cannot create directory '" + d.string() + "': " + reason(err));
    if (rc != 0) {  // someone else created it meanwhile: not ours to remove
      guards_.pop_back();
      continue;
    }
    created_.push_back(d);
  }
  struct stat st {};
  if (::stat(out.c_str(), &st) != 0) {
    const int err = errno;
    throw std::runtime_error("cannot create directory '" + out.string() + "': " + reason(err));
  }
  if (!S_ISDIR(st.st_mode)) throw std::runtime_error("'" + out.string() + "' is not a directory");
  lock(out);
  remove_stale_staging(out);
  dir_ = out / (std::string(kStagingPrefix) + random_suffix());
  guards_.push_back(std::make_unique<InterruptCleanup>(dir_));
  const int rc = ::mkdir(dir_.c_str(), 0700);
  const int err = errno;
  guards_.back()->created();
  if (rc != 0) {
    throw std::runtime_error("cannot write into directory '" + out.string() + "': " + reason(err));
  }
}

// One run at a time in a directory: a run finishing in it removes its checkpoint files, which
// would be another run's (issue 33 item 3). flock on the directory itself: nothing is created in
// it, and the lock goes with the process however it ends (kill -9 included). A file system that
// cannot lock (ENOLCK, EINVAL, EBADF: some network file systems) runs unlocked, as before.
void OutputStaging::lock(const fs::path& out) {
  lock_fd_ = ::open(out.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (lock_fd_ < 0) {
    const int err = errno;
    throw std::runtime_error("cannot open directory '" + out.string() + "': " + reason(err));
  }
  while (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    if (err == EINTR) continue;
    if (err != EWOULDBLOCK) return;
    ::close(lock_fd_);
    lock_fd_ = -1;
    const std::string who = live_staging(out);
    throw std::runtime_error("'" + out.string() + "' is in use by another run" +
                             (who.empty() ? std::string() : " (its staging directory " + who + ")") +
                             "; wait for it to end or choose another --out");
  }
}

OutputStaging::~OutputStaging() {
  std::error_code ec;
  fs::remove_all(dir_, ec);
  if (!committed_) remove_created_directories();
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock, after the staging directory is gone
}

void OutputStaging::add(const std::string& name) {
  if (const std::string why = output_name_problem(name); !why.empty())
    throw std::invalid_argument("output name \"" + name + "\" " + why);
  if (std::find(names_.begin(), names_.end(), name) != names_.end())
    throw std::invalid_argument("two outputs of this run are named \"" + name + "\"");
  struct stat st {};
  if (::lstat((dir_ / name).c_str(), &st) != 0 || !S_ISREG(st.st_mode))
    throw std::runtime_error("output \"" + name + "\" was not written into " + dir_.string());
  names_.push_back(name);
}

void OutputStaging::check_replaceable(const std::vector<std::string>& names) const {
  for (const auto& n : names) {
    const fs::path target = out_ / n;
    struct stat st {};
    if (::lstat(target.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
      throw std::runtime_error("cannot write " + target.string() + ": " + reason(S_ISDIR(st.st_mode) ? EISDIR : EEXIST) +
                               " (it is " + (S_ISLNK(st.st_mode) ? "a symbolic link" : S_ISDIR(st.st_mode) ? "a directory" : "not a regular file") +
                               ", never replaced; nothing was changed in " + out_.string() + ")");
  }
}

std::vector<fs::path> OutputStaging::commit() {
  // Nothing moves unless every target can be replaced: a regular file or nothing.
  check_replaceable(names_);
  struct Moved {
    fs::path target, backup;  // backup empty: the target did not exist before
  };
  std::vector<Moved> moved;
  auto roll_back = [&] {
    for (auto it = moved.rbegin(); it != moved.rend(); ++it) {
      if (it->backup.empty()) ::unlink(it->target.c_str());
      else ::rename(it->backup.c_str(), it->target.c_str());
    }
  };
  std::vector<fs::path> done;
  {
    const InterruptDeferral no_signals;  // all renames, or none (a signal waits for the end)
    for (std::size_t i = 0; i < names_.size(); ++i) {
      const fs::path from = dir_ / names_[i], target = out_ / names_[i];
      Moved m{target, {}};
      struct stat st {};
      if (::lstat(target.c_str(), &st) == 0) {
        // Keep the previous file until the whole commit succeeded (a hard link: the target stays).
        m.backup = dir_ / (".previous." + std::to_string(i));
        if (::link(target.c_str(), m.backup.c_str()) != 0) {
          const int err = errno;
          roll_back();
          throw std::runtime_error("cannot replace " + target.string() + ": " + reason(err) + " (nothing was changed in " +
                                   out_.string() + ")");
        }
      }
      if (::rename(from.c_str(), target.c_str()) != 0) {
        const int err = errno;
        if (!m.backup.empty()) ::unlink(m.backup.c_str());
        roll_back();
        throw std::runtime_error("cannot write " + target.string() + ": " + reason(err) + " (nothing was changed in " +
                                 out_.string() + ")");
      }
      moved.push_back(m);
      done.push_back(target);
    }
    committed_ = true;
    set_interrupt_output_committed();
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  return done;
}

}  // namespace asperity
