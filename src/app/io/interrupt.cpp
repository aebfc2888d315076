// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/io/interrupt.hpp"

#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cerrno>
#include <cstdint>
#include <cstring>

namespace asperity {

namespace {

constexpr int kSlots = 64;

// Slot states. A registered path or child may still be being created by its thread ("creating"):
// the handler waits for that to end, since a path created after the handler looked would stay.
constexpr int kFree = 0, kRegistered = 1, kWriting = 2, kCreating = 3;

struct Slot {
  std::atomic<int> state{kFree};
  std::atomic<long> creator{0};  // the thread creating it (the handler does not wait for itself)
  InterruptCleanup::Kind kind = InterruptCleanup::Kind::directory;
  char path[PATH_MAX] = {};
};

Slot g_slots[kSlots];
std::atomic<int> g_phase{0};    // 0 running, 1 deferred (renaming into place), 2 aborting
std::atomic<int> g_pending{0};  // a signal that arrived while deferred
std::atomic<bool> g_installed{false};
std::atomic<bool> g_committed{false};  // the run's files are in place: nothing of it to remove
const char* g_program = "asperity";

// Every signal whose default action ends the process and that a user, a shell or a resource limit
// sends to a running program: each ends the run the same way (issue 33: SIGQUIT, SIGALRM, SIGXCPU
// and SIGXFSZ left the staging directory behind). SIGKILL cannot be caught: the next run in the
// directory removes what it left (remove_stale_staging).
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGQUIT, SIGALRM, SIGXCPU, SIGXFSZ};

void put(const char* s) {
  std::size_t n = 0;
  while (s[n]) ++n;
  while (n > 0) {
    const ssize_t w = ::write(2, s, n);
    if (w <= 0) return;
    s += w;
    n -= static_cast<std::size_t>(w);
  }
}

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    case SIGPIPE: return "SIGPIPE";
    case SIGQUIT: return "SIGQUIT";
    case SIGALRM: return "SIGALRM";
    case SIGXCPU: return "SIGXCPU";
    case SIGXFSZ: return "SIGXFSZ";
  }
  return "a signal";
}

// Removes the entries of `path` (files; one level) and then the directory, with system calls only
// (getdents64, unlinkat, rmdir: async-signal-safe). A file created meanwhile by another thread is
// caught by the next pass.
void wipe_dir(const char* path) {
  for (int pass = 0; pass < 1000; ++pass) {  // ends once nothing is created inside any more
    const int fd = ::open(path, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) return;
    alignas(8) char buf[4096];
    for (;;) {
      const long n = ::syscall(SYS_getdents64, fd, buf, sizeof buf);
      if (n <= 0) break;
      for (long off = 0; off < n;) {
        // struct linux_dirent64: u64 ino, s64 off, u16 reclen, u8 type, char name[]
        std::uint16_t reclen = 0;
        std::memcpy(&reclen, buf + off + 16, sizeof reclen);
        const char* name = buf + off + 19;
        if (!(name[0] == '.' && (name[1] == 0 || (name[1] == '.' && name[2] == 0)))) ::unlinkat(fd, name, 0);
        if (reclen == 0) break;
        off += reclen;
      }
    }
    ::close(fd);
    if (::rmdir(path) == 0 || errno != ENOTEMPTY) return;
  }
}

long this_thread_id() { return ::syscall(SYS_gettid); }

// Waits (at most ~2 s in all, nanosleep is async-signal-safe) until no other thread is between
// registering a slot and having created its path or child. The thread running the handler is
// not waited for: it creates nothing more.
template <class Slots>
void wait_for_creations(Slots& slots, long self, int& budget_ms) {
  for (auto& s : slots)
    while (s.state.load() == kCreating && s.creator.load() != self && budget_ms > 0) {
      const timespec ms{0, 1000000};
      ::nanosleep(&ms, nullptr);
      --budget_ms;
    }
}

bool live(const Slot& s) { return s.state.load() == kRegistered || s.state.load() == kCreating; }

// Kills the registered children and removes the registered paths (async-signal-safe).
void remove_registered() {
  // Called from a handler, or in normal context (~InterruptDeferral, an unexpected exit): there a
  // second signal (SIGPIPE from a message on a closed pipe) would enter on_signal, find the phase
  // taken and pause this thread forever. Blocked here, it waits; other threads that take it pause.
  sigset_t all;
  sigemptyset(&all);
  for (int s : kSignals) sigaddset(&all, s);
  ::pthread_sigmask(SIG_BLOCK, &all, nullptr);
  const long self = this_thread_id();
  int budget_ms = 2000;
  wait_for_creations(g_slots, self, budget_ms);
  using Kind = InterruptCleanup::Kind;
  for (auto& s : g_slots)
    if (live(s) && s.kind == Kind::file) ::unlink(s.path);
  for (auto& s : g_slots)
    if (live(s) && s.kind == Kind::directory) wipe_dir(s.path);
  // Directories the run created for its output, deepest first: registered parent first, so
  // backwards; removed only when empty.
  for (int pass = 0; pass < 2; ++pass)
    for (int i = kSlots - 1; i >= 0; --i)
      if (live(g_slots[i]) && g_slots[i].kind == Kind::empty_directory) ::rmdir(g_slots[i].path);
}

[[noreturn]] void clean_up_and_exit(int sig) {
  remove_registered();
  put(g_program);
  put(": interrupted by ");
  put(signal_name(sig));
  put(g_committed.load() ? ": the run had completed; its files are in place\n"
                         : ": this run's temporary files were removed, the output directory is as it was\n");
  ::_exit(128 + sig);
}

[[noreturn]] void wait_for_exit() {
  for (;;) ::pause();
}

std::atomic<bool> g_normal_exit{false};

// atexit: a library that ends the process with exit() -- libgomp when it cannot create a thread
// exits 1, which is our "a law was rejected" -- must neither claim a verdict nor leave the staging
// directory: its temporaries go as on a signal, and the status is 2 (failure).
void on_unexpected_exit() {
  if (g_normal_exit.load()) return;
  int expected = 0;
  if (!g_phase.compare_exchange_strong(expected, 2)) return;  // a signal is being handled
  remove_registered();
  put(g_program);
  put(g_committed.load() ? ": error: ended by a library (see its message above) after the run had completed\n"
                         : ": error: ended by a library (see its message above); this run's temporary files were "
                           "removed, the output directory is as it was\n");
  ::_exit(2);
}

void on_signal(int sig) {
  int expected = 0;
  if (g_phase.compare_exchange_strong(expected, 2)) clean_up_and_exit(sig);
  if (expected == 1) {
    int none = 0;
    g_pending.compare_exchange_strong(none, sig);
    return;
  }
  wait_for_exit();  // another thread is handling a signal and ends the process
}

}  // namespace

void install_interrupt_cleanup(const char* program) {
  if (g_installed.exchange(true)) return;
  g_program = program;
  std::atexit(on_unexpected_exit);
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  for (int s : kSignals) sigaddset(&sa.sa_mask, s);
  sa.sa_flags = 0;
  for (int s : kSignals) {
    struct sigaction old {};
    ::sigaction(s, nullptr, &old);
    // A signal ignored by whoever started us (nohup, `trap '' INT`) stays ignored.
    if (old.sa_handler == SIG_IGN && s != SIGPIPE) continue;
    ::sigaction(s, &sa, nullptr);
  }
  // Unblock them in this thread; threads created later inherit the mask.
  sigset_t set;
  sigemptyset(&set);
  for (int s : kSignals) sigaddset(&set, s);
  ::pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
}

InterruptCleanup::InterruptCleanup(const std::filesystem::path& path, Kind kind) {
  const std::string& p = path.native();
  if (p.empty() || p.size() >= PATH_MAX) return;
  if (g_phase.load() == 2) wait_for_exit();
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (!g_slots[i].state.compare_exchange_strong(expected, kWriting)) continue;
    std::memcpy(g_slots[i].path, p.c_str(), p.size() + 1);
    g_slots[i].kind = kind;
    g_slots[i].creator.store(this_thread_id());
    g_slots[i].state.store(kCreating);
    slot_ = i;
    break;
  }
  // A handler that started before the slot was visible did not see it: do not create the
  // path, wait for the handler to end the process.
  if (g_phase.load() == 2) wait_for_exit();
}

void InterruptCleanup::created() {
  if (slot_ >= 0) g_slots[slot_].state.store(kRegistered);
}

InterruptCleanup::~InterruptCleanup() {
  if (slot_ >= 0) g_slots[slot_].state.store(kFree);
}

void set_interrupt_output_committed() { g_committed.store(true); }
void mark_normal_exit() { g_normal_exit.store(true); }

int interrupt_pending() { return g_pending.load(); }
bool interrupt_cleanup_installed() { return g_installed.load(); }

InterruptDeferral::InterruptDeferral() {
  int expected = 0;
  if (!g_phase.compare_exchange_strong(expected, 1)) wait_for_exit();
}

InterruptDeferral::~InterruptDeferral() {
  int deferred = 1;
  g_phase.compare_exchange_strong(deferred, 0);
  const int sig = g_pending.exchange(0);
  if (sig != 0) {
    int expected = 0;
    if (g_phase.compare_exchange_strong(expected, 2)) clean_up_and_exit(sig);
    wait_for_exit();
  }
}

}  // namespace asperity
