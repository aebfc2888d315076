// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Runs a shell command as a user would and captures what it prints (stdout + stderr when the
// command redirects 2>&1) and its exit status (-1 if it did not exit normally, e.g. a crash).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace asperity::testing {

struct CommandResult {
  int status;
  std::string out;
};

/// A file's bytes ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// An empty path in the temporary directory for one test: asperity-<what>-<name>-<pid>, removed if
/// a previous run left it.
inline std::filesystem::path fresh_dir(const std::string& what, const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("asperity-" + what + "-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  return d;
}

inline CommandResult run_command(const std::string& cmd) {
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return {-1, "popen failed: " + cmd};
  std::string out;
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

/// Starts `program` as a child the way a terminal would (tests that send it signals): default
/// signal dispositions and an empty mask (a shell's `&` or the test runner may have changed them),
/// stdout and stderr into `log`.
inline pid_t spawn_cli(const std::string& program, const std::vector<std::string>& args, const std::filesystem::path& log) {
  std::fflush(nullptr);  // the child must not repeat our buffered output
  const pid_t pid = ::fork();
  if (pid == 0) {
    for (int s : {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGQUIT, SIGALRM, SIGXCPU, SIGXFSZ}) ::signal(s, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    if (!std::freopen(log.c_str(), "w", stdout) || !std::freopen(log.c_str(), "a", stderr)) ::_exit(99);
    std::vector<char*> argv;
    std::string prog = program;
    argv.push_back(prog.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(98);
  }
  return pid;
}

/// The exit status, or 1000 + the signal that ended the child.
inline int wait_status(pid_t pid) {
  int st = 0;
  ::waitpid(pid, &st, 0);
  return WIFEXITED(st) ? WEXITSTATUS(st) : 1000 + WTERMSIG(st);
}

}  // namespace asperity::testing
