// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/app/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>
#include <system_error>

#include "asperity/app/interrupt.hpp"

namespace asperity {

namespace {

// The system's reason, captured before any clean-up can overwrite errno.
[[noreturn]] void fail(const std::filesystem::path& file, int err, const std::filesystem::path& tmp) {
  ::unlink(tmp.c_str());
  throw std::runtime_error("cannot write " + file.string() + ": " + std::generic_category().message(err));
}

}  // namespace

void write_file_atomic(const std::filesystem::path& file, const std::string& text) {
  auto tmp = file;
  tmp += ".tmp." + std::to_string(::getpid());
  InterruptCleanup on_signal(tmp, InterruptCleanup::Kind::file);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  on_signal.created();
  if (fd < 0) fail(file, errno, tmp);
  const char* p = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    const ssize_t w = ::write(fd, p, left);
    if (w < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      fail(file, err, tmp);
    }
    p += w;
    left -= static_cast<std::size_t>(w);
  }
  if (::close(fd) != 0) fail(file, errno, tmp);  // NFS and full disks report here
  if (::rename(tmp.c_str(), file.c_str()) != 0) fail(file, errno, tmp);
}

}  // namespace asperity
