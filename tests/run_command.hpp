#pragma once
// Runs a shell command as a user would and captures what it prints (stdout + stderr when the
// command redirects 2>&1) and its exit status (-1 if it did not exit normally, e.g. a crash).
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace asperity::testing {

struct CommandResult {
  int status;
  std::string out;
};

inline CommandResult run_command(const std::string& cmd) {
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return {-1, "popen failed: " + cmd};
  std::string out;
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

}  // namespace asperity::testing
