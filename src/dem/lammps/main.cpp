/* SPDX-License-Identifier: MIT */
/* Copyright (c) 2026 the asperity developers. MIT (LICENSE's text); see asperity_draw.h. */
// asperity-lammps: Debian's LAMMPS (liblammps) with the asperity styles registered. Takes LAMMPS's
// own command line (-in FILE, -var NAME VALUE, -log FILE, -screen none, ...) and runs it; with
// mpirun, every rank does the same.
#include <mpi.h>

#include <cstdio>
#include <exception>

#include "input.h"
#include "lammps.h"

#include "asperity_lammps.h"

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rc = 0;
  try {
    auto* lmp = new LAMMPS_NS::LAMMPS(argc, argv, MPI_COMM_WORLD);
    asperity_dem::register_styles(lmp);
    lmp->input->file();
    delete lmp;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "asperity-lammps: %s\n", e.what());
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
