// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The processes of one run split across machines (validate-geometry under mpirun, issue 14): the
// app's only view of them, so that no library needs MPI. A run without a Collective is one process.
// Every process calls each function in the same order (they are collective operations).
#include <cstdint>
#include <string>
#include <vector>

namespace asperity {

class Collective {
 public:
  virtual ~Collective() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// The largest `v` of all processes, at every process.
  virtual int max(int v) = 0;
  /// Every process's `bytes` at rank 0, in rank order; other ranks get an empty vector.
  virtual std::vector<std::string> gather(const std::string& bytes) = 0;
  /// The element-wise sum of every process's `v` (same length everywhere) into rank 0's `v`; other
  /// ranks' `v` is left unspecified. Integers: the same sum in any order.
  virtual void sum(std::vector<std::uint64_t>& v) = 0;
};

}  // namespace asperity
