// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/cli/processes.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#if ASPERITY_WITH_MPI
#include <mpi.h>
#endif

namespace asperity::cli {

namespace {

// What MPI launchers put into the environment: the world size, or this process's rank (PMIx).
long env_number(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::strtol(v, nullptr, 10) : -1;
}
[[maybe_unused]] bool launched_as_one_of_many() {
  return env_number("OMPI_COMM_WORLD_SIZE") > 1 || env_number("PMI_SIZE") > 1 || env_number("PMIX_RANK") > 0 ||
         env_number("PMI_RANK") > 0;
}
bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "PMI_RANK"})
    if (std::getenv(v)) return true;
  return false;
}

#if ASPERITY_WITH_MPI
// Waits for a non-blocking collective by polling with short sleeps: a blocking MPI call spins on a
// core, and in `max` the processes may wait for each other for long (ranks > 0 for rank 0's whole
// analysis, or a run that does not split). The data-heavy gather and sums run when every process
// has arrived (after the max on the stream's outcome) and are blocking: a non-blocking collective
// only progresses inside MPI calls, and sleeping between them made the 8 MB reduction of the
// default histograms take ~1 s instead of milliseconds.
void wait(MPI_Request& req) {
  for (int done = 0;;) {
    MPI_Test(&req, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

class MpiCollective final : public Collective {
 public:
  MpiCollective() {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  ~MpiCollective() override { MPI_Finalize(); }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  int max(int v) override {
    int out = v;
    MPI_Request req;
    MPI_Iallreduce(&v, &out, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD, &req);
    wait(req);
    return out;
  }
  // Sizes first, then the bytes (small: block moments and counters, not the histograms).
  std::vector<std::string> gather(const std::string& bytes) override {
    if (bytes.size() > std::size_t(1) << 31) throw std::runtime_error("a share of more than 2 GiB cannot be sent");
    const int n = static_cast<int>(bytes.size());
    std::vector<int> sizes(rank_ == 0 ? std::size_t(size_) : 0);
    MPI_Gather(&n, 1, MPI_INT, sizes.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<int> at(sizes.size(), 0);
    long total = 0;
    for (std::size_t r = 0; r < sizes.size(); ++r) {
      at[r] = static_cast<int>(total);
      total += sizes[r];
    }
    if (total > (1L << 31) - 1) throw std::runtime_error("the shares of all processes exceed 2 GiB");
    std::string all(std::size_t(total), '\0');
    MPI_Gatherv(bytes.data(), n, MPI_CHAR, all.data(), sizes.data(), at.data(), MPI_CHAR, 0, MPI_COMM_WORLD);
    std::vector<std::string> parts;
    for (std::size_t r = 0; r < sizes.size(); ++r) parts.push_back(all.substr(std::size_t(at[r]), std::size_t(sizes[r])));
    return parts;
  }
  // In pieces of at most 2^24 counts (MPI counts are int; 2^24 keeps the temporary buffers small).
  void sum(std::vector<std::uint64_t>& v) override {
    constexpr std::size_t kPiece = std::size_t{1} << 24;
    for (std::size_t at = 0; at < v.size(); at += kPiece) {
      const int n = static_cast<int>(std::min(kPiece, v.size() - at));
      if (rank_ == 0)
        MPI_Reduce(MPI_IN_PLACE, v.data() + at, n, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
      else
        MPI_Reduce(v.data() + at, nullptr, n, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
    }
  }

 private:
  int rank_ = 0, size_ = 1;
};
#endif

}  // namespace

std::unique_ptr<Collective> join_processes(int* argc, char*** argv) {
  if (!launched_by_mpi()) return nullptr;
#if ASPERITY_WITH_MPI
  int provided = 0;
  // FUNNELED: only the main thread calls MPI (OpenMP threads never do).
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  auto group = std::make_unique<MpiCollective>();
  if (group->size() == 1) return nullptr;  // mpirun -np 1: one process (MPI_Finalize by the destructor)
  return group;
#else
  (void)argc, (void)argv;
  if (launched_as_one_of_many())
    throw std::runtime_error(
        "started by an MPI launcher as one of several processes, but this validate-geometry was built without MPI "
        "(install libopenmpi-dev and rebuild; README \"Beyond one machine\"): each process would run the whole scene "
        "into the same directory");
  return nullptr;
#endif
}

}  // namespace asperity::cli
