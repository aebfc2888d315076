// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What a run leaves behind when it is interrupted: nothing. install_interrupt_cleanup() makes
// SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGQUIT, SIGALRM, SIGXCPU and SIGXFSZ remove the registered temporary files and directories
// (their files, then themselves) and the registered output directories the run created (only if
// empty), and exit with status 128 + signal number. The
// handler uses async-signal-safe system calls only; registration is lock-free. Without
// install_interrupt_cleanup() (a library user) registrations cost a few stores and do nothing.
#include <filesystem>

namespace asperity {

/// Installs the handlers (once; later calls change nothing). `program` prefixes the one line
/// written to stderr on a signal ("<program>: interrupted by SIGINT; ...").
void install_interrupt_cleanup(const char* program);

/// A path removed on a signal while the guard lives. Register it BEFORE creating it and call
/// created() once the attempt to create it returned (success or not): a handler that starts in
/// between waits for created() (up to 2 s), so nothing is created after it cleaned up.
class InterruptCleanup {
 public:
  enum class Kind {
    directory,        ///< its files, then itself (a staging directory)
    empty_directory,  ///< only if empty (a directory the run created for its output)
    file              ///< a temporary file
  };
  explicit InterruptCleanup(const std::filesystem::path& path, Kind kind = Kind::directory);
  ~InterruptCleanup();
  void created();
  InterruptCleanup(const InterruptCleanup&) = delete;
  InterruptCleanup& operator=(const InterruptCleanup&) = delete;

 private:
  int slot_ = -1;  ///< -1: no free slot (too many at once): not cleaned on a signal
};

/// From install_interrupt_cleanup on, an exit() that main did not choose (a library ending the
/// process: libgomp exits 1 when it cannot create threads) removes the registered temporaries as a
/// signal would and ends with status 2. main calls this just before it returns its own status.
void mark_normal_exit();

/// The run's files are in place (OutputStaging::commit): a later signal says so.
void set_interrupt_output_committed();

/// A critical section that a signal must not interrupt (renaming a run's files into place):
/// while it lives, a signal is only recorded; when it ends, a recorded signal is handled (clean-up
/// of what is still registered, exit 128 + signal). If a signal is already being handled when it
/// is constructed, the constructor never returns (the handler is about to end the process).
class InterruptDeferral {
 public:
  InterruptDeferral();
  ~InterruptDeferral();
  InterruptDeferral(const InterruptDeferral&) = delete;
  InterruptDeferral& operator=(const InterruptDeferral&) = delete;
};

/// The signal recorded while an InterruptDeferral lives (0: none). A long run holds a deferral,
/// polls this between units of work, writes a checkpoint and ends; the deferral's end then
/// handles the signal as usual (clean-up, exit 128 + signal).
int interrupt_pending();
/// Whether install_interrupt_cleanup ran (a program, not a library user).
bool interrupt_cleanup_installed();

}  // namespace asperity
