// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// File writes that never leave a partial file and never leave their directory: every file of a
// run goes through here. A file is first written to a temporary of a fresh, unpredictable name in
// its directory, created through the directory's descriptor with O_CREAT|O_EXCL|O_NOFOLLOW (a
// symbolic link or any file planted under that name is never opened, let alone followed); every
// write, the fsync and the close are checked; then it is renamed over its final name (rename
// replaces a symbolic link there, it never writes through it) and the directory is fsynced.
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

namespace asperity {

/// The prefix of every temporary (".asperity-tmp-"): no output may be named like it
/// (output_name_problem).
inline constexpr std::string_view kTemporaryPrefix = ".asperity-tmp-";

/// A directory opened once; files are staged into it and published under their final names.
/// Messages name the final file. Throws std::runtime_error with the system's reason.
class AtomicDirectory {
 public:
  explicit AtomicDirectory(const std::filesystem::path& dir);
  ~AtomicDirectory();
  AtomicDirectory(const AtomicDirectory&) = delete;
  AtomicDirectory& operator=(const AtomicDirectory&) = delete;

  /// A complete, fsynced temporary waiting to become `name`; removed if never published.
  class Staged {
   public:
    Staged(Staged&&) noexcept;
    ~Staged();
    const std::string& name() const { return name_; }
    /// Renamed into place (publish got that far, even if the directory's fsync then failed).
    bool published() const { return temporary_.empty(); }

   private:
    friend class AtomicDirectory;
    struct Guard;
    Staged(const AtomicDirectory& d, std::string name, std::string temporary);
    const AtomicDirectory* dir_;
    std::string name_, temporary_;
    std::unique_ptr<Guard> guard_;  ///< removes the temporary on a signal
  };

  /// Writes `text` to a new temporary of this directory (see the top of this file).
  Staged stage(const std::string& name, const std::string& text) const;
  /// Renames the temporary over its name, then fsyncs the directory.
  void publish(Staged& s) const;
  /// Whether `name` exists here (as anything, a dangling symbolic link included).
  bool holds(const std::string& name) const;
  /// Removes `name` (a file this run created); errors ignored.
  void remove(const std::string& name) const noexcept;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

/// Writes `text` to `file` atomically (AtomicDirectory of its parent: stage, publish).
void write_file_atomic(const std::filesystem::path& file, const std::string& text);

/// Tests only (empty in a run): `fault(step)` returns an errno that the step ("open", "write",
/// "fsync", "close", "rename", "sync-directory") is made to fail with, 0 to let it run;
/// `temporary_name()` names the next temporary to try (a test plants files under those names).
struct AtomicFileSeams {
  std::function<int(std::string_view step)> fault;
  std::function<std::string()> temporary_name;
};
void set_atomic_file_seams(AtomicFileSeams seams);

}  // namespace asperity
