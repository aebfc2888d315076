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

#include "asperity/app/interrupt.hpp"

namespace asperity {

/// Why an output name is not a plain file name ("" when it is one): empty, ".", "..", a '/',
/// a control character (NUL, newline, ...), longer than 255 bytes, a name that starts with
/// the staging or temporary prefix, or a checkpoint file's name (is_checkpoint_name).
std::string output_name_problem(std::string_view name);

class OutputStaging {
 public:
  /// Creates `out` (and its missing parents, remembered) and the staging directory in it. Throws
  /// std::runtime_error naming the directory and the system's reason.
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
  /// Renames every added file into out(), in order (add the report last). A target that is a
  /// directory (or anything but a regular file) is refused before anything moves. Signals wait
  /// until it is done. Throws std::runtime_error with the system's reason; then out() is as it
  /// was. Returns the final paths.
  std::vector<std::filesystem::path> commit();

 private:
  void create(const std::filesystem::path& out);  ///< the constructor's work; throws
  void remove_created_directories() noexcept;      ///< deepest first, only if still empty
  std::filesystem::path out_, dir_;
  std::vector<std::filesystem::path> created_;  ///< directories this run created, parents first
  std::vector<std::unique_ptr<InterruptCleanup>> guards_;
  std::vector<std::string> names_;
  bool committed_ = false;
};

/// The prefix of staging directories (".asperity-staging-"): no output may be named like it.
inline constexpr std::string_view kStagingPrefix = ".asperity-staging-";

}  // namespace asperity
