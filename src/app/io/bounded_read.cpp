// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/io/bounded_read.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

namespace asperity {

namespace {

std::string reason(int err) { return std::generic_category().message(err); }

std::string bytes_text(std::uint64_t n) {
  if (n >= (std::uint64_t{1} << 30) && n % (std::uint64_t{1} << 30) == 0) return std::to_string(n >> 30) + " GiB";
  if (n >= (std::uint64_t{1} << 20) && n % (std::uint64_t{1} << 20) == 0) return std::to_string(n >> 20) + " MiB";
  return std::to_string(n) + " bytes";
}

/// Closes the descriptor on every path out.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

[[noreturn]] void refuse(const std::string& what, const std::filesystem::path& file, const std::string& why) {
  throw InputFileError(what + " '" + file.string() + "': " + why);
}

// Opens `file` for reading and checks the opened object: a regular file within the limit.
int open_checked(const std::filesystem::path& file, std::uint64_t max_bytes, const std::string& what,
                 std::uint64_t& size) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int err = errno;
    if (err == ELOOP) refuse(what, file, "a symbolic link that loops or nests too deeply");
    if (err == ENOENT) refuse(what, file, "does not exist");
    refuse(what, file, "cannot open: " + reason(err));
  }
  Fd guard{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) refuse(what, file, "cannot inspect: " + reason(errno));
  if (S_ISDIR(st.st_mode)) refuse(what, file, "is a directory, not a file");
  if (!S_ISREG(st.st_mode)) refuse(what, file, "is not a regular file (a device, FIFO or socket is never read)");
  size = static_cast<std::uint64_t>(st.st_size);
  if (size > max_bytes)
    refuse(what, file, "is " + std::to_string(size) + " bytes, more than the " + bytes_text(max_bytes) + " such a file may have");
  // Back to blocking reads: a regular file never blocks, and O_NONBLOCK only mattered for open().
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  guard.fd = -1;
  return fd;
}

}  // namespace

std::uint64_t checked_input_size(const std::filesystem::path& file, std::uint64_t max_bytes, const std::string& what) {
  std::uint64_t size = 0;
  Fd fd{open_checked(file, max_bytes, what, size)};
  return size;
}

std::string read_bounded_file(const std::filesystem::path& file, std::uint64_t max_bytes, const std::string& what) {
  std::uint64_t size = 0;
  Fd fd{open_checked(file, max_bytes, what, size)};
  std::string text(size, '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd.fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) refuse(what, file, "read error: " + reason(errno));
    if (n == 0) refuse(what, file, "shrank while being read");
    got += static_cast<std::size_t>(n);
  }
  char extra = 0;
  ssize_t n = 0;
  while ((n = ::read(fd.fd, &extra, 1)) < 0 && errno == EINTR) {
  }
  if (n != 0) refuse(what, file, "grew while being read");
  return text;
}

}  // namespace asperity
