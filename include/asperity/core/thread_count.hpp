// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The thread count of one library call. OpenMP's nthreads-var belongs to the calling thread and
// outlives the call: a library that sets it (omp_set_num_threads) changes every later parallel
// region of the DEM code or Python interpreter that called it. ThreadCountScope sets it for the
// call's own regions and restores the caller's value when the call returns or throws.
#ifdef _OPENMP
#include <omp.h>
#endif

namespace asperity {

/// Sets OpenMP's thread count for one library call and restores the caller's on the way out.
class ThreadCountScope {
 public:
  /// threads > 0: the call's parallel regions use that many threads; 0: the caller's setting.
  explicit ThreadCountScope(int threads) {
#ifdef _OPENMP
    if (threads > 0) saved_ = omp_get_max_threads(), omp_set_num_threads(threads);
#else
    (void)threads;
#endif
  }
  /// Restores the caller's thread count.
  ~ThreadCountScope() {
#ifdef _OPENMP
    if (saved_ > 0) omp_set_num_threads(saved_);
#endif
  }
  ThreadCountScope(const ThreadCountScope&) = delete;
  ThreadCountScope& operator=(const ThreadCountScope&) = delete;

 private:
  int saved_ = 0;  ///< the caller's nthreads-var, restored; 0: nothing was changed
};

}  // namespace asperity
