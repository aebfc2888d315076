// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// An exception must never leave an OpenMP region: the runtime calls std::terminate and the process
// aborts (a Python kernel dies, the CLI exits 134 instead of 2). Every parallel loop whose body can
// throw runs the body through LowestIndexError::run and calls rethrow() after the region. Of the
// exceptions thrown, the one of the lowest loop index is kept, so the error a user sees is the same
// for any thread count and schedule.
#include <cstdint>
#include <exception>
#include <limits>

namespace asperity {

/// Collects the exceptions of a parallel loop and rethrows the one of the lowest index after it,
/// so the error is the same for any thread count and schedule. Thread-safe; one per loop.
class LowestIndexError {
 public:
  /// Runs f(); an exception it throws is recorded against index i instead of propagating.
  template <class F>
  void run(std::int64_t i, F&& f) noexcept {
    try {
      f();
    } catch (...) {
      record(i, std::current_exception());
    }
  }
  /// True once any index failed: later iterations may skip their work (the run fails anyway).
  bool failed() const noexcept {
    bool f = false;
#pragma omp atomic read
    f = failed_;
    return f;
  }
  /// Rethrows the exception of the lowest failed index, if any. Call after the parallel region.
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  void record(std::int64_t i, std::exception_ptr e) noexcept {
#pragma omp critical(asperity_lowest_index_error)
    if (i < index_) index_ = i, error_ = std::move(e);
#pragma omp atomic write
    failed_ = true;
  }
  std::int64_t index_ = std::numeric_limits<std::int64_t>::max();
  std::exception_ptr error_;
  bool failed_ = false;
};

}  // namespace asperity
