// The distributed job: rank 0 reads, partitions and closes; pieces are meshed on all ranks;
// rank 0 gathers, merges and writes. The driver only decides where pieces go and moves their
// bytes; every step ends with an agreement of all ranks.
#pragma once
#include <string>

#include "partet/job.hpp"

namespace partet::mpi {

struct JobStatus {
  int exit_code = 0;            // the same on every rank
  std::string error;            // on rank 0, when exit_code != 0
  bool meshing_failed = false;  // the error is a meshing failure another partition may help with
  bool usage_error = false;     // the command line asks for something impossible (exit code 2)
  RunFigures figures;           // rank 0, with MeshJob::compare_tetgen
  int ranks = 1;
};

// Call between MPI_Init and MPI_Finalize on every rank of MPI_COMM_WORLD.
JobStatus run_mesh_job(const MeshJob& job);

// The MPI library's name and version ("Open MPI v4.1.4"); callable before MPI_Init.
std::string library_version();

}  // namespace partet::mpi
