// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <random>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "app/io/interrupt.hpp"

namespace asperity {

namespace {

AtomicFileSeams& seams() {
  static AtomicFileSeams s;
  return s;
}

// The injected failure of `step` (tests), or 0.
int injected(std::string_view step) { return seams().fault ? seams().fault(step) : 0; }

[[noreturn]] void fail(const std::filesystem::path& file, int err) {
  throw std::runtime_error("cannot write " + file.string() + ": " + std::generic_category().message(err));
}

// Unpredictable, so that nobody can plant a file under it in advance (O_EXCL refuses one anyway).
std::string temporary_name() {
  if (seams().temporary_name) return seams().temporary_name();
  std::random_device rd;
  std::ostringstream s;
  s << kTemporaryPrefix << ::getpid() << '-' << std::hex << rd() << rd();
  return s.str();
}

// Every byte, or the errno of the write that failed (EINTR retried).
int write_all(int fd, const std::string& text) {
  const char* p = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    if (const int err = injected("write")) return err;
    const ssize_t w = ::write(fd, p, left);
    if (w < 0 && errno == EINTR) continue;
    if (w < 0) return errno;
    p += w;
    left -= static_cast<std::size_t>(w);
  }
  return 0;
}

// fsync(fd), or the injected failure.
int sync(int fd, std::string_view step) {
  if (const int err = injected(step)) return err;
  return ::fsync(fd) == 0 ? 0 : errno;
}

}  // namespace

void set_atomic_file_seams(AtomicFileSeams s) { seams() = std::move(s); }

struct AtomicDirectory::Staged::Guard {
  InterruptCleanup cleanup;
  explicit Guard(const std::filesystem::path& p) : cleanup(p, InterruptCleanup::Kind::file) {}
};

AtomicDirectory::AtomicDirectory(const std::filesystem::path& dir) : path_(dir.empty() ? "." : dir) {
  fd_ = ::open(path_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0) {
    const int err = errno;
    throw std::runtime_error("cannot write into directory " + path_.string() + ": " +
                             std::generic_category().message(err));
  }
}

AtomicDirectory::~AtomicDirectory() { ::close(fd_); }

AtomicDirectory::Staged::Staged(const AtomicDirectory& d, std::string name, std::string temporary)
    : dir_(&d), name_(std::move(name)), temporary_(std::move(temporary)) {}

AtomicDirectory::Staged::Staged(Staged&& o) noexcept
    : dir_(o.dir_), name_(std::move(o.name_)), temporary_(std::move(o.temporary_)), guard_(std::move(o.guard_)) {
  o.temporary_.clear();
}

AtomicDirectory::Staged::~Staged() {
  if (!temporary_.empty()) dir_->remove(temporary_);
}

AtomicDirectory::Staged AtomicDirectory::stage(const std::string& name, const std::string& text) const {
  const auto file = path_ / name;
  for (int attempt = 0; attempt < 64; ++attempt) {
    Staged s(*this, name, temporary_name());
    s.guard_ = std::make_unique<Staged::Guard>(path_ / s.temporary_);
    int err = injected("open");
    const int fd = err ? -1 : ::openat(fd_, s.temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0 && !err) err = errno;
    s.guard_->cleanup.created();
    if (fd < 0) {
      s.temporary_.clear(), s.guard_.reset();  // not ours: never removed, not even on a signal
      if (err == EEXIST) continue;  // someone's file (or link) under that name: another name
      fail(file, err);
    }
    err = write_all(fd, text);
    if (!err) err = sync(fd, "fsync");
    const int closed = ::close(fd) == 0 ? 0 : errno;  // NFS and full disks report here
    if (!err) err = injected("close");
    if (!err) err = closed;
    if (err) fail(file, err);  // ~Staged removes the temporary
    return s;
  }
  fail(file, EEXIST);
}

void AtomicDirectory::publish(Staged& s) const {
  int err = injected("rename");
  if (!err && ::renameat(fd_, s.temporary_.c_str(), fd_, s.name_.c_str()) != 0) err = errno;
  if (err) fail(path_ / s.name_, err);
  s.temporary_.clear();
  // The rename itself reaches the disk only with the directory.
  if (const int e = sync(fd_, "sync-directory")) fail(path_ / s.name_, e);
}

bool AtomicDirectory::holds(const std::string& name) const {
  struct stat st {};
  return ::fstatat(fd_, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0;
}

void AtomicDirectory::remove(const std::string& name) const noexcept { ::unlinkat(fd_, name.c_str(), 0); }

void write_file_atomic(const std::filesystem::path& file, const std::string& text) {
  const AtomicDirectory dir(file.parent_path());
  auto s = dir.stage(file.filename().string(), text);
  dir.publish(s);
}

}  // namespace asperity
