// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// All or nothing in the output directory. A run writes every file (figures, PLY, report) into a
// private staging directory inside the output directory; commit() renames them into place only
// when the whole run succeeded, with the report last. A run that fails, throws or is interrupted
// (interrupt.hpp) removes its staging directory and the directories it created (if empty), and
// leaves every file that was there before untouched; a commit that fails half-way puts the
// previous files back.
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "app/io/interrupt.hpp"

namespace asperity {

/// Why an output name is not a plain file name ("" when it is one): empty, ".", "..", a '/',
/// a control character (NUL, newline, ...), longer than 255 bytes, a name that starts with
/// the staging or temporary prefix, or a checkpoint file's name (is_checkpoint_name).
std::string output_name_problem(std::string_view name);

class OutputStaging {
 public:
  /// Creates `out` (and its missing parents, remembered), takes the directory's lock (one run at
  /// a time: flock on `out` itself, held until destruction; another run's is a std::runtime_error
  /// saying the directory is in use), removes the staging directories of dead runs
  /// (remove_stale_staging) and creates the staging directory in it. Throws std::runtime_error
  /// naming the directory and the system's reason.
  explicit OutputStaging(const std::filesystem::path& out);
  /// Not committed: removes the staging directory and the directories it created if empty.
  ~OutputStaging();
  OutputStaging(const OutputStaging&) = delete;
  OutputStaging& operator=(const OutputStaging&) = delete;

  const std::filesystem::path& out() const { return out_; }
  /// Where the run writes its files, each under its final name.
  const std::filesystem::path& dir() const { return dir_; }
  /// A file the run wrote into dir() (checked: a plain file name, not given before, present).
  void add(const std::string& name);
  const std::vector<std::string>& names() const { return names_; }
  /// Throws std::runtime_error unless every name can be replaced in out(): absent or a regular
  /// file (not a link, a directory, a FIFO). commit() checks its files so; a caller that knows
  /// names before the run (the report) checks them up front, not after the whole computation.
  void check_replaceable(const std::vector<std::string>& names) const;
  /// Renames every added file into out(), in order (add the report last). A target that is a
  /// directory (or anything but a regular file) is refused before anything moves. Signals wait
  /// until it is done. Throws std::runtime_error with the system's reason; then out() is as it
  /// was. Returns the final paths.
  std::vector<std::filesystem::path> commit();

 private:
  void create(const std::filesystem::path& out);  ///< the constructor's work; throws
  void remove_created_directories() noexcept;      ///< deepest first, only if still empty
  void lock(const std::filesystem::path& out);     ///< flock on `out`; throws if another run holds it
  std::filesystem::path out_, dir_;
  std::vector<std::filesystem::path> created_;  ///< directories this run created, parents first
  std::vector<std::unique_ptr<InterruptCleanup>> guards_;
  std::vector<std::string> names_;
  bool committed_ = false;
  int lock_fd_ = -1;  ///< `out` opened and flock'ed: no other run stages in it meanwhile
};

/// Removes the staging directories (kStagingPrefix + "<pid>-<hex>") in `out` left by runs that
/// died (kill -9, a power cut): only real directories (not links) owned by this user whose pid is
/// not a live process. Call it only while holding `out`'s lock (OutputStaging does): a live run
/// holds the lock while its staging directory exists. Returns how many it removed.
std::size_t remove_stale_staging(const std::filesystem::path& out);

/// The prefix of staging directories (".asperity-staging-"): no output may be named like it.
inline constexpr std::string_view kStagingPrefix = ".asperity-staging-";

}  // namespace asperity
