// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The processes of a validate-geometry run started by an MPI launcher (mpirun, srun): issue 14's
// "beyond one machine". Only the executable knows MPI; the libraries see a Collective.
#include <memory>

#include "app/collective.hpp"

namespace asperity::cli {

/// A Collective of the MPI world when this process was started by an MPI launcher with more than
/// one process and validate-geometry was built with MPI; nullptr for a single process. Its
/// destructor ends MPI. Throws std::runtime_error when started as one of several processes by a
/// build without MPI (each would run the whole scene into the same directory).
std::unique_ptr<Collective> join_processes(int* argc, char*** argv);

}  // namespace asperity::cli
